//! `tactile run`: a scenario's loop as three node programs (or in this process), and
//! its report.

use crate::cmd::node_options::NodeOptions;
use clap::Args;
use std::path::PathBuf;
use tactile_launch::error::Error;
use tactile_launch::{self as launch, load_scenario, parse_sets, Links, Supervision};
use tactile_report::text::render;
use tactile_runtime::args::LinkKind;

/// Arguments of `tactile run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file (TOML); without one, the built-in paper scenario
    /// (deploy/scenarios/paper.toml).
    pub scenario: Option<PathBuf>,
    /// Folder for summary.json, trace.csv, run.mcap, histograms and plots.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Change the scenario: KEY is a dotted path (network.forward.delay,
    /// environment.objects[0].stiffness), VALUE a TOML value ([5, 5, 5], 1000.0; a bare
    /// word is a string). Repeatable; checked like the file.
    #[arg(long, value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// How the node programs wait and are scheduled.
    #[command(flatten)]
    pub nodes: NodeOptions,
    /// Run master, emulator and slave in this process, without shared memory (the
    /// options about processes, links, waiting and scheduling do not apply and are
    /// refused with it).
    #[arg(long, conflicts_with_all = [
        "prefix", "spin_us", "wake_early_us", "max_restarts", "link", "udp", "no_pin",
        "sched", "idle", "stall_s",
    ])]
    pub in_process: bool,
    /// No progress line.
    #[arg(long, short)]
    pub quiet: bool,
    /// Times the emulator or the slave is restarted if it dies mid-run.
    #[arg(long, default_value_t = 3)]
    pub max_restarts: u32,
    /// Seconds a node's process may stay stopped (SIGSTOP, a debugger) before the node
    /// counts as frozen: it is killed, restarted if allowed, and the run is failed.
    /// 0: never.
    #[arg(long, default_value_t = 5.0, value_parser = stall_parser)]
    pub stall_s: f64,
    /// What carries the samples between the nodes on this host: iceoryx2 (shared
    /// memory), udp (loopback datagrams, the reference) or zenoh (loopback TCP; across
    /// hosts, start the nodes by hand, see docs/03-across-hosts.md).
    #[arg(long, value_enum, default_value_t = tactile_runtime::args::LinkKind::Iceoryx2)]
    pub link: tactile_runtime::args::LinkKind,
    /// Shorthand for --link udp.
    #[arg(long, conflicts_with = "link")]
    pub udp: bool,
    /// Write no trace.csv and no run.mcap (a long run's trace is about 1 kB per
    /// sample, its recording about 0.75 kB); everything
    /// else is reported.
    #[arg(long)]
    pub no_trace: bool,
    /// The trace's and the recording's formats.
    #[command(flatten)]
    pub formats: super::formats::FormatArgs,
}

/// A stall limit: 0 (never) or 1.5 to 3600 seconds (a job-control stop and continue
/// at a terminal takes a moment).
fn stall_parser(text: &str) -> Result<f64, String> {
    let s: f64 = text.parse().map_err(|e| format!("{e}"))?;
    if s == 0.0 || (1.5..=3600.0).contains(&s) {
        Ok(s)
    } else {
        Err("takes 0 (never) or 1.5 to 3600 seconds".into())
    }
}

/// `tactile run`.
pub fn main(args: &RunArgs) -> Result<(), Error> {
    args.formats
        .refuse_unless(!args.no_trace, "with --no-trace")?;
    let sets = parse_sets(&args.set)?;
    let loaded = load_scenario(args.scenario.as_deref(), &sets)?;
    for w in &loaded.warnings {
        tactile_launch::noteln!("tactile: warning: {w}");
    }
    let summary = if args.in_process {
        launch::sim::run_in_process(
            &loaded,
            &args.out,
            &args.formats.outputs(args.no_trace),
            Default::default(),
        )?
    } else {
        launch::clean_stale_runs();
        let link = Links::on_this_host(if args.udp { LinkKind::Udp } else { args.link })?;
        let sup = Supervision {
            progress: !args.quiet,
            max_restarts: args.max_restarts,
            outputs: args.formats.outputs(args.no_trace),
            stall: (args.stall_s > 0.0).then(|| std::time::Duration::from_secs_f64(args.stall_s)),
            ..args.nodes.supervision(link, "")
        };
        launch::run_processes(&loaded, &args.out, &sup)?
    };
    tactile_launch::out!("{}", render(&summary, &args.out));
    if summary.interrupted {
        return Err(Error::Interrupted);
    }
    if summary.failed {
        return Err(Error::Failed(format!(
            "the run failed: {}",
            // The launcher's first event: what died, and its last words (at most the
            // five last lines of its log), so the reason is on stderr.
            summary.events.first().map_or("", String::as_str)
        )));
    }
    Ok(())
}
