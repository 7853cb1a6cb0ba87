//! `tactile sweep`: the arguments, parsed, handed to the launcher's sweep
//! ([`tactile_launch::sweep`], which runs the grid and writes the tables), and its
//! closing line.

use clap::Args;
use std::path::PathBuf;
use tactile_launch::error::Error;
use tactile_launch::sweep::{sweep, Base, Progress, SweepOptions};

/// Arguments of `tactile sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Scenario file (TOML) every run starts from.
    #[arg(required_unless_present = "merge")]
    pub scenario: Option<PathBuf>,
    /// A swept key and its values, KEY=V1,V2,... (commas inside brackets or quotes
    /// belong to the value: network.forward.delay=[0,0,0],[5,5,5]). Repeatable: every
    /// combination runs. +KEY=V1,V2,... pairs KEY with the key before it, value for
    /// value, instead of combining them (a round trip split evenly both ways:
    /// --set network.forward.delay_ms=0,5,25 --set +network.backward.delay_ms=0,5,25).
    /// The first key is the plots' x axis, the second their lines (a paired key is
    /// shown by its partner).
    #[arg(long, value_name = "KEY=V1,V2,...", required_unless_present = "merge")]
    pub set: Vec<String>,
    /// Folder for sweep.csv, the plots, and one folder per run (run-0000, ...).
    #[arg(long, default_value = "sweep-out")]
    pub out: PathBuf,
    /// Start the three node programs for every run (in realtime, each run then takes
    /// its real time), one run at a time, instead of running them in-process.
    #[arg(long)]
    pub processes: bool,
    /// Write each run's trace.csv and run.mcap too (about 1 kB and 0.75 kB per
    /// sample).
    #[arg(long)]
    pub trace: bool,
    /// With --trace: the trace's and the recording's formats. With
    /// --trace-format parquet (or both), every run's trace.parquet carries its
    /// combination as text columns and is linked into traces/, one table for pandas
    /// (`pandas.read_parquet("OUT/traces")`).
    #[command(flatten)]
    pub formats: crate::cmd::formats::FormatArgs,
    /// Runs at once [default: the CPUs this process may use; 1 with --processes].
    /// The results equal --jobs 1's: every run has its own scenario and seed.
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Repeat every combination over N seeds (the scenario's seed, then +1, +2, ...):
    /// sweep.csv has every run with the seed it used, sweep-summary.csv each metric's
    /// mean and 95 % confidence half width over them, the plots error bars.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub seeds: usize,
    /// Keep the runs whose folders already hold a whole report (a sweep cut short, or
    /// run again with more seeds) and run only the others.
    #[arg(long)]
    pub resume: bool,
    /// Run one slice of the grid, K of N (1 <= K <= N): combinations K-1, K-1+N,
    /// K-1+2N, ... with all their seeds. `--merge` joins the slices' folders.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// No progress line per run (as `tactile run -q`); warnings, errors and the
    /// closing line still print.
    #[arg(long, short)]
    pub quiet: bool,
    /// Join the folders of a sharded sweep into --out: the same sweep.csv and plots as
    /// the sweep run whole.
    #[arg(long, value_name = "DIR", num_args = 1.., conflicts_with_all = ["scenario", "set", "shard", "resume", "processes", "trace", "jobs"])]
    pub merge: Vec<PathBuf>,
}

impl SweepArgs {
    /// The sweep these arguments ask for, as the launcher takes it.
    pub fn options(&self) -> SweepOptions {
        SweepOptions {
            set: self.set.clone(),
            out: self.out.clone(),
            processes: self.processes,
            trace: self.trace,
            trace_format: self.formats.trace_format,
            mcap_compression: self.formats.mcap_compression,
            jobs: self.jobs,
            seeds: self.seeds,
            resume: self.resume,
            shard: self.shard.clone(),
        }
    }
}

/// `tactile sweep`.
pub fn main(args: &SweepArgs) -> Result<(), Error> {
    args.formats.refuse_unless(
        args.trace && args.merge.is_empty(),
        "without --trace (or with --merge)",
    )?;
    if !args.merge.is_empty() {
        return tactile_launch::sweep::merge(&args.merge, &args.out);
    }
    let scenario = args
        .scenario
        .as_deref()
        .ok_or_else(|| Error::BadInput("a scenario file is needed".into()))?;
    let runs = sweep(&Base::file(scenario)?, &args.options(), &|p: &Progress| {
        if !args.quiet {
            p.say();
        }
    })?;
    tactile_launch::outln!(
        "tactile sweep: {runs} runs{}; sweep.csv and a plot per metric with values in {}",
        args.shard
            .as_deref()
            .map_or_else(String::new, |s| format!(" (shard {s})")),
        args.out.display()
    );
    Ok(())
}
