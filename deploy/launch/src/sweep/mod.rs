//! A sweep (`tactile sweep`): one scenario run for every combination of the values given to
//! `--set KEY=V1,V2,...` (each repeated over `--seeds` seeds), a table of their metrics
//! (`sweep.csv`, one row per run), their mean and interval per combination
//! (`sweep-summary.csv`) and a plot per metric against the first swept key, one line
//! per value of the second. Both tables have the same columns whatever `--seeds`, so
//! a script reads any sweep's.
//!
//! Each run is an ordinary run with its own folder and full report (without its
//! trace); its row in `sweep.csv` is read back from its `summary.json`, picked by the
//! paths in [`sweep::METRICS`], so the table never says anything the summaries do not,
//! and a table made from the folders (`--resume`, `--merge`) equals one made as the
//! runs ended. Runs go in-process by default (the same library code as the node
//! programs, bit-for-bit the lockstep trio), `--jobs` of them at once, each on its own
//! scenario and seed, so the results do not depend on the order they finish in;
//! `--processes` starts the three programs for every run instead, one run at a time.
//! `--shard K/N` runs one slice of the grid and `--merge` joins the slices' folders,
//! so a scheduler can spread a study over many machines (docs/01-the-loop.md).

mod exec;
mod table;
mod traces;

pub use table::merge;

use crate::error::Error;
use crate::Source;
pub use exec::Progress;
use std::path::{Path, PathBuf};
use tactile_report::mcap::Compression;
use tactile_report::sweep::{axis, combinations, Axis};
use tactile_report::sweep_grid::same_value;
use tactile_report::write::TraceFormat;
use tactile_scenario::overrides::Set;

/// Most runs one sweep may ask for: beyond this a typo in a list is likelier than a
/// plan, and the folder would hold more reports than anyone reads.
pub const MAX_RUNS: usize = 10_000;

/// What a sweep runs, as plain values (the command's `tactile sweep` arguments, a
/// Python `Scenario.sweep`'s): the swept keys and their values, the folder, how the
/// runs go and what each writes.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// The swept keys, `KEY=V1,V2,...` or `+KEY=V1,V2,...` (paired with the one before).
    pub set: Vec<String>,
    /// Folder for sweep.csv, the plots, and one folder per run.
    pub out: PathBuf,
    /// The three node programs for every run, one run at a time (else in-process).
    pub processes: bool,
    /// Each run's trace and recording too.
    pub trace: bool,
    /// With `trace`: the trace's format.
    pub trace_format: TraceFormat,
    /// With `trace`: run.mcap's compression.
    pub mcap_compression: Compression,
    /// Runs at once (None: the CPUs this process may use; 1 with `processes`).
    pub jobs: Option<usize>,
    /// Seeds per combination.
    pub seeds: usize,
    /// Keep the runs whose folders already hold a whole report.
    pub resume: bool,
    /// One slice of the grid, `K/N`.
    pub shard: Option<String>,
}

impl SweepOptions {
    /// The launcher's outputs for each run.
    fn outputs(&self) -> crate::Outputs {
        crate::Outputs {
            no_trace: !self.trace,
            trace_format: self.trace_format,
            mcap_compression: self.mcap_compression,
            trace_columns: Vec::new(),
        }
    }
}

/// What a sweep is, as its folder records it (`sweep.json`), so `--merge` and
/// `--resume` join only slices of the same sweep.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// The scenario file as given.
    pub scenario: String,
    /// FNV-1a hash of the scenario file's text: slices of another scenario are refused.
    pub scenario_hash: String,
    /// The `--set` arguments, in order.
    pub sets: Vec<String>,
    /// Seeds per combination.
    pub seeds: usize,
    /// Combinations in the whole grid.
    pub combinations: usize,
    /// This folder's slice, `[K, N]`, or null for the whole grid.
    pub shard: Option<[usize; 2]>,
}

/// `--seeds` within its range and not beside a seed axis; the grid within
/// [`MAX_RUNS`].
fn check_size(args: &SweepOptions, axes: &[Axis], combinations: usize) -> Result<(), Error> {
    if args.seeds == 0 || args.seeds > 1000 {
        return Err(Error::BadInput(format!(
            "--seeds {}: give 1 to 1000",
            args.seeds
        )));
    }
    if args.seeds > 1 && axes.iter().any(|a| a.key == "seed") {
        return Err(Error::BadInput(
            "--set seed=... and --seeds: sweep the seed one way or the other".into(),
        ));
    }
    if combinations.saturating_mul(args.seeds) > MAX_RUNS {
        return Err(Error::BadInput(format!(
            "{combinations} combinations x {} seeds: more than the {MAX_RUNS} runs a sweep may run",
            args.seeds
        )));
    }
    Ok(())
}

/// Runs at once per CPU at most: an in-process run keeps a CPU busy, so more only
/// hold more runs' memory at once (`--jobs 100000` over 400 runs took 1.34 GB).
pub const JOBS_PER_CPU: usize = 4;

/// Runs at a time: as given, up to [`JOBS_PER_CPU`] x the CPUs this process may use
/// (and never more than the runs to do, see `exec::run_all`); one with `--processes`
/// (they take the machine's CPUs), else the CPUs.
fn jobs(args: &SweepOptions) -> Result<usize, Error> {
    let cpus = tactile_runtime::sched::allowed_cpus().map_or(1, |c| c.len().max(1));
    let cap = cpus.saturating_mul(JOBS_PER_CPU);
    match (args.jobs, args.processes) {
        (Some(0), _) => Err(Error::BadInput("--jobs 0: give at least 1".into())),
        (Some(n), true) if n > 1 => Err(Error::BadInput(
            "--processes runs take the machine's CPUs one run at a time: --jobs 1".into(),
        )),
        (Some(n), _) if n > cap => {
            crate::noteln!(
                "tactile sweep: --jobs {n}: capped at {cap} ({JOBS_PER_CPU} x the {cpus} CPUs this process may use; more would only hold more runs in memory)"
            );
            Ok(cap)
        }
        (Some(n), _) => Ok(n),
        (None, true) => Ok(1),
        (None, false) => Ok(cpus),
    }
}

/// Says each warning of the runs' scenarios once, however many runs share it.
fn warn_once(work: &[exec::Work]) {
    let mut said = std::collections::BTreeSet::new();
    for w in work.iter().flat_map(|w| &w.loaded.warnings) {
        if said.insert(w) {
            crate::noteln!("tactile: warning: {w}");
        }
    }
}

/// What a sweep starts every run from: a scenario's source and the `--set`s applied
/// to it before the swept ones (none from the command; a Python `Scenario`'s
/// `with_set`s). A swept key given here too (or its twin in the other unit) takes the
/// swept value.
#[derive(Debug, Clone)]
pub struct Base {
    /// The scenario's text and where it came from.
    pub source: Source,
    /// `KEY=VALUE` sets applied before each run's swept values.
    pub sets: Vec<String>,
}

impl Base {
    /// The scenario file `path`, read as `tactile run` reads it, with no sets.
    pub fn file(path: &Path) -> Result<Self, Error> {
        Ok(Base {
            source: Source::file(path)?,
            sets: Vec::new(),
        })
    }

    /// FNV-1a of the text (then of each set, a NUL before each), hex: what
    /// `--resume` and `--merge` compare. With no sets, the file's bytes' hash alone,
    /// as `sweep.json` has always recorded it.
    fn hash(&self) -> String {
        let mut bytes = self.source.text.as_bytes().to_vec();
        for s in &self.sets {
            bytes.push(0);
            bytes.extend_from_slice(s.as_bytes());
        }
        format!("{:016x}", crate::sim::fnv1a64(&bytes))
    }
}

/// Runs the sweep `args` asks for (its scenario file aside: `base` is what every
/// run starts from) into `args.out`, telling `progress` as each run ends; the runs
/// it ran. Every run's scenario is checked before the first starts, so a bad value
/// is bad input with nothing run. The tables are written even when a run's summary
/// says it failed or a stop request cuts the sweep short (then the error says so); a
/// run that could not be run at all ends the sweep with its error.
pub fn sweep(
    base: &Base,
    args: &SweepOptions,
    progress: &(dyn Fn(&Progress) + Sync),
) -> Result<usize, Error> {
    let axes = parse_axes(&args.set)?;
    refuse_repeats(&axes)?;
    let combos = combinations(&axes);
    check_size(args, &axes, combos.len())?;
    let shard = args.shard.as_deref().map(parse_shard).transpose()?;
    let jobs = jobs(args)?;
    let spec = Spec {
        scenario: base.source.name.clone(),
        scenario_hash: base.hash(),
        sets: args.set.clone(),
        seeds: args.seeds,
        combinations: combos.len(),
        shard: shard.map(|(k, n)| [k, n]),
    };
    let mine: Vec<usize> = (0..combos.len())
        .filter(|k| shard.is_none_or(|(s, n)| k % n == s - 1))
        .collect();
    let work = exec::plan(base, &axes, &combos, &mine, args)?;
    // Every folder the sweep writes, before any is touched: a run's refused half-way
    // would leave the sweep cut short.
    tactile_report::ours::refuse_foreign(&args.out)?;
    for w in &work {
        tactile_report::ours::refuse_foreign(&w.dir)?;
    }
    warn_once(&work);
    let holder = format!("tactile sweep (pid {})", std::process::id());
    let _held = tactile_report::out::take(&args.out, &holder)?;
    table::check_resume(&args.out, &spec, args.resume)?;
    table::write_spec(&args.out, &spec)?;
    let done = exec::run_all(&work, jobs, args, progress);
    // Even after a failure: the dataset then holds the runs that ended, no stale ones.
    traces::gather(&args.out, work.iter().map(|w| w.dir.as_path()))?;
    let done = done?;
    let complete = done.iter().all(Option::is_some);
    let results: Vec<table::Ran> = work
        .iter()
        .zip(done)
        .filter_map(|(w, d)| {
            d.map(|values| table::Ran {
                k: w.k,
                s: w.seed,
                seed: w.loaded.scenario.seed,
                values,
            })
        })
        .collect();
    table::write_tables(&args.out, &axes, args.seeds, &results)?;
    if !complete {
        crate::noteln!(
            "tactile sweep: stopped by a signal after {} of {} runs; sweep.csv holds the runs that ended, sweep-summary.csv and the plots the combinations whose runs all ended; --resume runs the rest",
            results.len(),
            work.len()
        );
        return Err(Error::Interrupted);
    }
    let failed: Vec<String> = work
        .iter()
        .filter(|w| exec::failed(&w.dir))
        .map(|w| format!("{} ({})", w.dir.display(), w.what))
        .collect();
    if !failed.is_empty() {
        // A run whose node died still has its row (its summary says what ran), but
        // the sweep is not a success: --resume runs the failed ones again.
        return Err(Error::Failed(format!(
            "{} of {} runs failed: {}; their rows in sweep.csv are from what ran; --resume runs them again",
            failed.len(),
            work.len(),
            failed.join(", ")
        )));
    }
    Ok(work.len())
}

/// The axes of `--set`s, each key once.
pub fn parse_axes(sets: &[String]) -> Result<Vec<Axis>, Error> {
    let axes = sets
        .iter()
        .map(|a| axis(a).map_err(Error::from))
        .collect::<Result<Vec<_>, _>>()?;
    for (k, a) in axes.iter().enumerate() {
        if axes[..k].iter().any(|b| b.key == a.key) {
            return Err(Error::BadInput(format!(
                "--set {}: the key is swept twice; give all its values in one --set KEY=V1,V2,...",
                a.key
            )));
        }
    }
    let keys: Vec<String> = axes.iter().map(|a| a.key.clone()).collect();
    if let Some((a, b)) = tactile_scenario::overrides::twins(&keys) {
        return Err(Error::BadInput(tactile_scenario::overrides::twice(
            &sets[a], &sets[b],
        )));
    }
    check_pairs(&axes, sets)?;
    let count = axes
        .iter()
        .filter(|a| !a.paired)
        .try_fold(1usize, |n, a| n.checked_mul(a.values.len()))
        .filter(|&n| n <= MAX_RUNS);
    if count.is_none() {
        let sizes: Vec<String> = axes
            .iter()
            .filter(|a| !a.paired)
            .map(|a| a.values.len().to_string())
            .collect();
        return Err(Error::BadInput(format!(
            "{} combinations: more than the {MAX_RUNS} a sweep may run",
            sizes.join(" x ")
        )));
    }
    Ok(axes)
}

/// A paired key (`+KEY=...`) has a key before it to pair with, and as many values.
fn check_pairs(axes: &[Axis], sets: &[String]) -> Result<(), Error> {
    for (k, a) in axes.iter().enumerate().filter(|(_, a)| a.paired) {
        let Some(before) = k.checked_sub(1).map(|j| &axes[j]) else {
            return Err(Error::BadInput(format!(
                "--set {}: a key written +KEY pairs with the --set before it, and there is none",
                sets[k]
            )));
        };
        if before.values.len() != a.values.len() {
            return Err(Error::BadInput(format!(
                "--set {}: {} values, but {} before it has {}: a paired key takes one value for each of its partner's",
                sets[k],
                a.values.len(),
                before.key,
                before.values.len()
            )));
        }
    }
    Ok(())
}

/// No value of a key given twice (nor a pair of values, for paired keys), however
/// it is written (`10` and `10.0`, `tdpa` and `"tdpa"`): every combination with it
/// would run twice.
fn refuse_repeats(axes: &[Axis]) -> Result<(), Error> {
    let mut start = 0;
    while start < axes.len() {
        let end = (start + 1..axes.len())
            .find(|&j| !axes[j].paired)
            .unwrap_or(axes.len());
        let group = &axes[start..end];
        let same = |i: usize, j: usize| {
            group
                .iter()
                .all(|a| same_value(&a.sets[i].value, &a.sets[j].value))
        };
        let n = group[0].values.len();
        if let Some((i, j)) = (0..n).find_map(|j| (0..j).find(|&i| same(i, j)).map(|i| (i, j))) {
            let said = |i: usize| -> String {
                let v: Vec<&str> = group.iter().map(|a| a.values[i].as_str()).collect();
                v.join(" and ")
            };
            let keys: Vec<&str> = group.iter().map(|a| a.key.as_str()).collect();
            return Err(Error::BadInput(format!(
                "--set {}: value {} and value {} are one value ({} and {}): every combination with it would run twice; give each value once",
                keys.join(" with +"),
                i + 1,
                j + 1,
                said(i),
                said(j)
            )));
        }
        start = end;
    }
    Ok(())
}

/// `K/N` with `1 <= K <= N`.
fn parse_shard(s: &str) -> Result<(usize, usize), Error> {
    let bad = || Error::BadInput(format!("--shard {s}: expected K/N with 1 <= K <= N"));
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let (k, n): (usize, usize) = (
        k.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if k == 0 || k > n {
        return Err(bad());
    }
    Ok((k, n))
}

/// The `--set`s of one run: the base's but those of a swept key (or of its twin in
/// the other unit: `delay_ms` for `delay`), then the combination's values, then its
/// seed when seeds vary.
fn sets_of(
    base: &[Set],
    axes: &[Axis],
    combo: &[usize],
    seed: Option<u64>,
) -> Result<Vec<Set>, Error> {
    let swept = |b: &Set| {
        axes.iter().any(|a| {
            let keys = [b.key(), a.key.clone()];
            keys[0] == keys[1] || tactile_scenario::overrides::twins(&keys).is_some()
        })
    };
    let mut sets: Vec<Set> = base.iter().filter(|b| !swept(b)).cloned().collect();
    sets.extend(axes.iter().zip(combo).map(|(a, &i)| a.sets[i].clone()));
    if let Some(s) = seed {
        sets.push(Set::parse(&format!("seed={s}"))?);
    }
    Ok(sets)
}

/// A run's folder: `run-0007`, or `run-0007-s2` for the third seed.
pub fn run_dir(out: &Path, k: usize, seed: usize, seeds: usize) -> PathBuf {
    if seeds == 1 {
        out.join(format!("run-{k:04}"))
    } else {
        out.join(format!("run-{k:04}-s{seed}"))
    }
}
