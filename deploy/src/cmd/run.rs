//! `tactile run`: a scenario's loop as three node programs (or in this process), and
//! its report.

use crate::error::Error;
use crate::launch::{self, load_scenario, parse_sets, Links, Supervision};
use clap::Args;
use std::path::PathBuf;
use std::time::Duration;
use tactile_report::summary::render;
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
    /// iceoryx2 prefix isolating this run's shared memory (default: one per launcher).
    #[arg(long)]
    pub prefix: Option<String>,
    /// Microseconds each process polls (yielding the core between polls) before it
    /// blocks on its wake-up event. Default: twice the wake-up margin (each node
    /// sleeps until 200 us before a sample is due, at most 40 % of a period), two
    /// periods in lockstep (chosen by measurement, see docs/07-latency.md).
    #[arg(long)]
    pub spin_us: Option<u64>,
    /// Realtime: microseconds before a sample is due that each node stops sleeping
    /// and polls (default 200, at most 40 % of a period).
    #[arg(long)]
    pub wake_early_us: Option<u64>,
    /// Run master, emulator and slave in this process, without shared memory (the
    /// options about processes, links, waiting and scheduling do not apply and are
    /// refused with it).
    #[arg(long, conflicts_with_all = [
        "prefix", "spin_us", "wake_early_us", "max_restarts", "link", "udp", "no_pin",
        "sched", "idle",
    ])]
    pub in_process: bool,
    /// No progress line.
    #[arg(long, short)]
    pub quiet: bool,
    /// Times the emulator or the slave is restarted if it dies mid-run.
    #[arg(long, default_value_t = 3)]
    pub max_restarts: u32,
    /// What carries the samples between the nodes on this host: iceoryx2 (shared
    /// memory), udp (loopback datagrams, the reference) or zenoh (loopback TCP; across
    /// hosts, start the nodes by hand, see docs/03-across-hosts.md).
    #[arg(long, value_enum, default_value_t = tactile_runtime::args::LinkKind::Iceoryx2)]
    pub link: tactile_runtime::args::LinkKind,
    /// Shorthand for --link udp.
    #[arg(long, conflicts_with = "link")]
    pub udp: bool,
    /// Do not pin the processes (by default the master runs on CPU 0 and the emulator
    /// and slave on CPU 1, where the machine has two CPUs).
    #[arg(long)]
    pub no_pin: bool,
    /// Scheduling the nodes set on themselves: fifo (SCHED_FIFO at priority 70 with
    /// memory locked, where permitted; otherwise SCHED_OTHER, said in the report) or
    /// other.
    #[arg(long, value_enum, default_value_t = tactile_runtime::sched::Policy::Fifo)]
    pub sched: tactile_runtime::sched::Policy,
    /// What each node's CPU does while the node sleeps, under SCHED_FIFO: halt (the
    /// kernel's idle; the default) or poll (a SCHED_IDLE thread keeps it busy, so a
    /// halted CPU is not woken late; on these virtual machines a CPU kept busy is
    /// taken away for about 7.5 ms every 10 s instead: docs/07-latency.md).
    #[arg(long, value_enum, default_value_t = tactile_runtime::sched::IdleMode::Halt)]
    pub idle: tactile_runtime::sched::IdleMode,
    /// Write no trace.csv and no run.mcap (a long run's trace is about 1 kB per
    /// sample, its recording about 0.75 kB); everything
    /// else is reported.
    #[arg(long)]
    pub no_trace: bool,
}

/// `tactile run`.
pub fn main(args: &RunArgs) -> Result<(), Error> {
    let sets = parse_sets(&args.set)?;
    let loaded = load_scenario(args.scenario.as_deref(), &sets)?;
    for w in &loaded.warnings {
        crate::noteln!("tactile: warning: {w}");
    }
    let summary = if args.in_process {
        launch::sim::run_in_process(&loaded, &args.out, args.no_trace)?
    } else {
        launch::clean_stale_runs();
        let sup = Supervision {
            prefix: args
                .prefix
                .clone()
                .unwrap_or_else(|| format!("tactile{}", std::process::id())),
            spin: args.spin_us.map(Duration::from_micros),
            wake_early: args.wake_early_us.map(Duration::from_micros),
            progress: !args.quiet,
            max_restarts: args.max_restarts,
            link: Links::on_this_host(if args.udp { LinkKind::Udp } else { args.link })?,
            pin: !args.no_pin,
            sched: args.sched,
            idle: args.idle,
            no_trace: args.no_trace,
            wrap: Default::default(),
        };
        launch::run_processes(&loaded, &args.out, &sup)?
    };
    crate::out!("{}", render(&summary, &args.out));
    if summary.interrupted {
        return Err(Error::Interrupted);
    }
    if summary.failed {
        return Err(Error::Failed(format!(
            "the run failed: {}",
            summary
                .events
                .first()
                .map_or("", |e| e.lines().next().unwrap_or(""))
        )));
    }
    Ok(())
}
