//! `tactile sweep`: one scenario run for every combination of the values given to
//! `--set KEY=V1,V2,...`, a table of their metrics (`sweep.csv`) and a plot per metric
//! against the first swept key, one line per value of the second.
//!
//! Each run is an ordinary run with its own folder and full report (without its
//! trace); its row in `sweep.csv` is a view of its `summary.json`, picked by the paths
//! in [`METRICS`], so the table never says anything the summaries do not. Runs go
//! in-process by default (the same library code as the node programs, bit-for-bit
//! the lockstep trio: the delays are counted in samples), which is what makes a sweep
//! of many runs quick; `--processes` starts the three programs for every run instead.

use crate::error::Error;
use crate::launch::{self, load_scenario, prepare_out};
use clap::Args;
use std::path::Path;
use std::path::PathBuf;
use tactile_report::sweep::{self, axis, combinations, describe, header, row, Axis};
use tactile_report::write::{write_report, Launch};
use tactile_scenario::overrides::Set;

/// Most runs one sweep may ask for: beyond this a typo in a list is likelier than a
/// plan, and the folder would hold more reports than anyone reads.
pub const MAX_RUNS: usize = 10_000;

/// Arguments of `tactile sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Scenario file (TOML) every run starts from.
    pub scenario: PathBuf,
    /// A swept key and its values, KEY=V1,V2,... (commas inside brackets or quotes
    /// belong to the value: network.forward.delay=[0,0,0],[5,5,5]). Repeatable: every
    /// combination runs. The first key is the plots' x axis, the second their lines.
    #[arg(long, value_name = "KEY=V1,V2,...", required = true)]
    pub set: Vec<String>,
    /// Folder for sweep.csv, the plots, and one folder per run (run-0000, ...).
    #[arg(long, default_value = "sweep-out")]
    pub out: PathBuf,
    /// Start the three node programs for every run (in realtime, each run then takes
    /// its real time) instead of running them in-process.
    #[arg(long)]
    pub processes: bool,
    /// Write each run's trace.csv and run.mcap too (about 1 kB and 0.75 kB per
    /// sample).
    #[arg(long)]
    pub trace: bool,
}

/// `tactile sweep`.
pub fn main(args: &SweepArgs) -> Result<(), Error> {
    let axes = args
        .set
        .iter()
        .map(|a| axis(a).map_err(Error::BadInput))
        .collect::<Result<Vec<_>, _>>()?;
    for (k, a) in axes.iter().enumerate() {
        if axes[..k].iter().any(|b| b.key == a.key) {
            return Err(Error::BadInput(format!(
                "--set {}: the key is swept twice; give all its values in one --set KEY=V1,V2,...",
                a.key
            )));
        }
    }
    let count = axes
        .iter()
        .try_fold(1usize, |n, a| n.checked_mul(a.values.len()))
        .filter(|&n| n <= MAX_RUNS);
    if count.is_none() {
        let sizes: Vec<String> = axes.iter().map(|a| a.values.len().to_string()).collect();
        return Err(Error::BadInput(format!(
            "{} combinations: more than the {MAX_RUNS} a sweep may run",
            sizes.join(" x ")
        )));
    }
    let combos = combinations(&axes);
    // Every combination is checked before the first run starts, so a bad value is
    // bad input (exit 2) with nothing run.
    let loaded = combos
        .iter()
        .map(|c| load_scenario(Some(&args.scenario), &sets_of(&axes, c)))
        .collect::<Result<Vec<_>, _>>()?;
    tactile_report::write::make_out_dir(&args.out)?;
    // The table grows a row as each run ends, so a sweep cut short keeps what ran.
    let table = args.out.join("sweep.csv");
    let mut csv = std::fs::File::create(&table)
        .map_err(Error::io(format!("creating {}", table.display())))?;
    let written =
        |r: std::io::Result<()>| r.map_err(Error::io(format!("writing {}", table.display())));
    written(std::io::Write::write_all(
        &mut csv,
        header(&axes).as_bytes(),
    ))?;
    let stop =
        tactile_node::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    let mut rows = Vec::new();
    for (k, (c, l)) in combos.iter().zip(&loaded).enumerate() {
        if stop.load(std::sync::atomic::Ordering::SeqCst) {
            break;
        }
        let dir = args.out.join(format!("run-{k:04}"));
        crate::noteln!(
            "tactile sweep: run {}/{}: {}",
            k + 1,
            combos.len(),
            describe(&axes, c)
        );
        let summary = run_one(l, &dir, args)?;
        if summary.interrupted {
            // Cut short: its folder holds the report of what ran; the table keeps
            // only whole runs.
            break;
        }
        let json = serde_json::to_value(&summary)
            .map_err(|e| Error::Failed(format!("summary of {}: {e}", dir.display())))?;
        let values = sweep::values(&json);
        written(std::io::Write::write_all(
            &mut csv,
            row(k, &axes, c, &values).as_bytes(),
        ))?;
        rows.push((c.clone(), values));
    }
    tactile_report::plots::sweep_plots(&args.out, &axes, &rows)
        .map_err(|e| Error::Failed(format!("plotting the sweep: {e}")))?;
    if rows.len() < combos.len() {
        crate::noteln!(
            "tactile sweep: stopped by a signal after {} of {} runs; sweep.csv and the plots hold those",
            rows.len(),
            combos.len()
        );
        return Err(Error::Interrupted);
    }
    crate::outln!(
        "tactile sweep: {} runs; sweep.csv and one plot per metric in {}",
        combos.len(),
        args.out.display()
    );
    Ok(())
}

fn sets_of(axes: &[Axis], combo: &[usize]) -> Vec<Set> {
    axes.iter()
        .zip(combo)
        .map(|(a, &i)| a.sets[i].clone())
        .collect()
}

fn run_one(
    l: &launch::Loaded,
    dir: &Path,
    args: &SweepArgs,
) -> Result<tactile_report::summary::Summary, Error> {
    let launch = Launch {
        no_trace: !args.trace,
        stop: tactile_node::signals::stop_flag().ok(),
        ..Launch::default()
    };
    if args.processes {
        launch::clean_stale_runs();
        let sup = launch::sweep_supervision(!args.trace);
        return launch::run_processes(l, dir, &sup);
    }
    prepare_out(dir, &l.inputs)?;
    let completed = launch::sim::simulate(&l.scenario, &l.base_dir, dir)?;
    let launch = if completed {
        launch
    } else {
        launch.interrupted()
    };
    Ok(write_report(&[dir.to_path_buf()], dir, &launch)?)
}
