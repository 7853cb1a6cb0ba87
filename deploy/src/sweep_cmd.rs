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

use crate::cli::SweepArgs;
use crate::error::Error;
use crate::report_cmd::{write_report, Launch};
use crate::run_cmd::{load_scenario, prepare_out};
use std::path::Path;
use tactile_scenario::overrides::{split_values, Set};

/// The columns of `sweep.csv` after the swept keys: a name, and where the value is in
/// a run's `summary.json` (a JSON pointer).
pub const METRICS: [(&str, &str); 22] = [
    ("samples_sent", "/samples_sent"),
    ("samples_lost", "/samples_lost"),
    ("deadline_misses", "/deadline_misses"),
    ("tracking_rms_m", "/tracking_rms_m"),
    ("tracking_max_m", "/master/motion/tracking_max_m"),
    ("force_max_n", "/master/motion/force_max_n"),
    ("felt_rms_n", "/master/motion/felt_rms_n"),
    ("felt_max_n", "/master/motion/felt_max_n"),
    ("round_trip_p50_ns", "/round_trip_ns/p50"),
    ("round_trip_p99_ns", "/round_trip_ns/p99"),
    ("overhead_p50_ns", "/overhead_ns/p50"),
    ("overhead_p99_ns", "/overhead_ns/p99"),
    ("position_rms_m", "/tracking/position_rms_m"),
    ("force_rms_n", "/tracking/force_rms_n"),
    ("max_penetration_m", "/contact/max_penetration_m"),
    ("force_swing_n", "/contact/force_swing_n"),
    ("observer_min_j", "/passivity/observer_min_j"),
    ("side_observer_min_j", "/passivity/side_observer_min_j"),
    ("dissipated_j", "/passivity/dissipated_j"),
    ("drift_max_m", "/passivity/drift_max_m"),
    ("packets_forward", "/packets/forward"),
    ("packets_backward", "/packets/backward"),
];

/// Most runs one sweep may ask for: beyond this a typo in a list is likelier than a
/// plan, and the folder would hold more reports than anyone reads.
pub const MAX_RUNS: usize = 10_000;

/// One swept key and its values, each already a `--set`.
#[derive(Debug, Clone)]
pub struct Axis {
    /// The key as written.
    pub key: String,
    /// The values as written, in order.
    pub values: Vec<String>,
    /// `KEY=VALUE` for each value.
    pub sets: Vec<Set>,
}

/// Parses `KEY=V1,V2,...` (a value with commas inside brackets or quotes stays one).
pub fn axis(arg: &str) -> Result<Axis, String> {
    let (key, list) = arg
        .split_once('=')
        .ok_or_else(|| format!("--set {arg:?}: expected KEY=V1,V2,..."))?;
    let values = split_values(list);
    let sets = values
        .iter()
        .map(|v| Set::parse(&format!("{}={v}", key.trim())))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Axis {
        key: key.trim().to_string(),
        values,
        sets,
    })
}

/// Every combination of the axes' values, the first axis varying slowest; each
/// combination is the index of the value on every axis.
pub fn combinations(axes: &[Axis]) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new()];
    for a in axes {
        out = out
            .into_iter()
            .flat_map(|c| {
                (0..a.values.len()).map(move |i| {
                    let mut c = c.clone();
                    c.push(i);
                    c
                })
            })
            .collect();
    }
    out
}

/// `tactile sweep`.
pub fn main(args: &SweepArgs) -> Result<(), Error> {
    let axes = args
        .set
        .iter()
        .map(|a| axis(a).map_err(Error::BadInput))
        .collect::<Result<Vec<_>, _>>()?;
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
    std::fs::create_dir_all(&args.out)
        .map_err(Error::io(format!("creating {}", args.out.display())))?;
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
    let mut rows = Vec::new();
    for (k, (c, l)) in combos.iter().zip(&loaded).enumerate() {
        let dir = args.out.join(format!("run-{k:04}"));
        eprintln!(
            "tactile sweep: run {}/{}: {}",
            k + 1,
            combos.len(),
            describe(&axes, c)
        );
        let summary = run_one(l, &dir, args)?;
        let json = serde_json::to_value(&summary)
            .map_err(|e| Error::Failed(format!("summary of {}: {e}", dir.display())))?;
        let values: Vec<Option<f64>> = METRICS
            .iter()
            .map(|(_, p)| json.pointer(p).and_then(serde_json::Value::as_f64))
            .collect();
        written(std::io::Write::write_all(
            &mut csv,
            row(k, &axes, c, &values).as_bytes(),
        ))?;
        rows.push((c.clone(), values));
        if summary.interrupted {
            return Err(Error::Interrupted);
        }
    }
    crate::plots::sweep_plots(&args.out, &axes, &rows)
        .map_err(|e| Error::Failed(format!("plotting the sweep: {e}")))?;
    println!(
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

fn describe(axes: &[Axis], combo: &[usize]) -> String {
    let parts: Vec<String> = axes
        .iter()
        .zip(combo)
        .map(|(a, &i)| format!("{}={}", a.key, a.values[i]))
        .collect();
    parts.join(" ")
}

fn run_one(
    l: &crate::run_cmd::Loaded,
    dir: &Path,
    args: &SweepArgs,
) -> Result<crate::summary::Summary, Error> {
    let launch = Launch {
        no_trace: !args.trace,
        ..Launch::default()
    };
    if args.processes {
        crate::run_cmd::clean_stale_runs();
        let sup = crate::run_cmd::sweep_supervision(!args.trace);
        return crate::run_cmd::run_processes(l, dir, &sup);
    }
    prepare_out(dir, &l.inputs)?;
    crate::sim::simulate(&l.scenario, &l.base_dir, dir)?;
    write_report(&[dir.to_path_buf()], dir, &launch)
}

fn header(axes: &[Axis]) -> String {
    let mut cols: Vec<String> = vec!["run".into()];
    cols.extend(axes.iter().map(|a| csv_field(&a.key)));
    cols.extend(METRICS.iter().map(|(n, _)| n.to_string()));
    cols.join(",") + "\n"
}

fn row(k: usize, axes: &[Axis], combo: &[usize], values: &[Option<f64>]) -> String {
    let mut cols: Vec<String> = vec![k.to_string()];
    cols.extend(
        axes.iter()
            .zip(combo)
            .map(|(a, &i)| csv_field(&a.values[i])),
    );
    cols.extend(
        values
            .iter()
            .map(|v| v.map_or_else(String::new, |x| format!("{x}"))),
    );
    cols.join(",") + "\n"
}

/// A CSV field, quoted when it holds a comma or a quote.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn combinations_cover_every_pair_once() {
        let axes = [
            axis("network.forward.delay=[0,0,0],[5,5,5],[10,10,10]").expect("a"),
            axis("mode=realtime,lockstep").expect("b"),
        ];
        assert_eq!(axes[0].values.len(), 3);
        let c = combinations(&axes);
        assert_eq!(c.len(), 6);
        let mut seen = c.clone();
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), 6);
        assert_eq!(c[0], [0, 0]);
        assert_eq!(c[1], [0, 1]);
        assert_eq!(
            describe(&axes, &c[5]),
            "network.forward.delay=[10,10,10] mode=lockstep"
        );
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(csv_field("[1,2]"), "\"[1,2]\"");
        assert_eq!(csv_field("tdpa"), "tdpa");
    }
}
