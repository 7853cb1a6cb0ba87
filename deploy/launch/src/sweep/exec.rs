//! Running a sweep's runs: `--jobs` at once on a shared counter, each in its own
//! folder, progress with an estimate of the time left, and `--resume` keeping the
//! runs that already ended.

use super::{run_dir, sets_of, Base, SweepOptions};
use crate::error::Error;
use crate::{load_source, parse_sets, Loaded};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tactile_report::summary::of_these_records;
use tactile_report::sweep::{describe, value_cell, values, Axis};
use tactile_report::write::{TraceFormat, PARQUET_FILE};

/// One run of the sweep.
#[derive(Debug)]
pub struct Work {
    /// Its combination's index in the whole grid.
    pub k: usize,
    /// Its seed's index (0 without `--seeds`).
    pub seed: usize,
    /// Its folder.
    pub dir: PathBuf,
    /// `KEY=VALUE ...` for the progress line.
    pub what: String,
    /// The combination as `trace.parquet`'s text columns: each key and its value as
    /// `sweep.csv` writes it (a word as itself, else JSON: the same whichever front
    /// end wrote the `--set`), the seed with `--seeds`, and the run's name.
    pub columns: Vec<(String, String)>,
    /// Its scenario, checked.
    pub loaded: Loaded,
}

impl Work {
    /// Its folder's name, `run-0007`.
    fn name(&self) -> String {
        self.dir
            .file_name()
            .map_or_else(String::new, |f| f.to_string_lossy().into_owned())
    }
}

/// Every run of combinations `mine`, its scenario loaded and checked.
pub fn plan(
    base: &Base,
    axes: &[Axis],
    combos: &[Vec<usize>],
    mine: &[usize],
    args: &SweepOptions,
) -> Result<Vec<Work>, Error> {
    let base_sets = parse_sets(&base.sets)?;
    let first = load_source(&base.source, &base_sets)?.scenario.seed;
    let mut work = Vec::with_capacity(mine.len() * args.seeds);
    for &k in mine {
        for s in 0..args.seeds {
            let seed = (args.seeds > 1).then(|| first.wrapping_add(s as u64));
            let sets = sets_of(&base_sets, axes, &combos[k], seed)?;
            let loaded = load_source(&base.source, &sets)?;
            let mut what = describe(axes, &combos[k]);
            let dir = run_dir(&args.out, k, s, args.seeds);
            let mut columns: Vec<(String, String)> = axes
                .iter()
                .zip(&combos[k])
                .map(|(a, &i)| (a.key.clone(), value_cell(&a.sets[i])))
                .collect();
            if let Some(x) = seed {
                what += &format!(" seed={x}");
                columns.push(("seed".into(), x.to_string()));
            }
            let name = dir.file_name().map(|f| f.to_string_lossy().into_owned());
            columns.push(("run".into(), name.unwrap_or_default()));
            work.push(Work {
                k,
                seed: s,
                dir,
                what,
                columns,
                loaded,
            });
        }
    }
    refuse_same_runs(&work)?;
    Ok(work)
}

/// No two runs of one scenario: values that differ as written but not in the
/// scenario they give (10 and 10.0000001 ms are both 10 samples at 1 kHz, since a
/// delay is whole samples) would run the same run twice.
/// (Scenarios are looked up by a hash of their text, then compared whole: a sweep's
/// ten thousand texts are not kept.)
fn refuse_same_runs(work: &[Work]) -> Result<(), Error> {
    use std::hash::{Hash, Hasher};
    let mut seen: std::collections::HashMap<u64, Vec<&Work>> = std::collections::HashMap::new();
    for w in work {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        w.loaded.scenario.to_toml().hash(&mut h);
        let like = seen.entry(h.finish()).or_default();
        if let Some(first) = like.iter().find(|f| f.loaded.scenario == w.loaded.scenario) {
            return Err(Error::BadInput(format!(
                "{} ({}) and {} ({}) would run the same scenario: values that differ only beyond what the scenario keeps (a delay is whole samples) are one value; give each once",
                first.name(),
                first.what,
                w.name(),
                w.what
            )));
        }
        like.push(w);
    }
    Ok(())
}

/// A run's metrics read back from its folder's `summary.json`; `None` unless the
/// run ended (a stop request did not cut it short; a run whose node died did end, and
/// its summary says so).
pub fn finished(dir: &Path) -> Option<Vec<Option<f64>>> {
    let json = summary(dir)?;
    let whole = json["interrupted"] == false;
    whole.then(|| values(&json))
}

/// Why a run's folder holds no whole run (`--merge` names the folder before it).
#[derive(Debug, thiserror::Error)]
pub enum RunFolderError {
    /// Its `scenario.toml` cannot be read.
    #[error("its scenario.toml cannot be read ({0})")]
    ScenarioUnread(#[source] std::io::Error),
    /// Its `scenario.toml` is not a scenario.
    #[error("its scenario.toml is unreadable ({0})")]
    ScenarioBad(#[source] tactile_scenario::ScenarioError),
    /// Its `summary.json` cannot be read.
    #[error("its summary.json cannot be read ({0})")]
    SummaryUnread(#[source] std::io::Error),
    /// Its `summary.json` is not JSON.
    #[error("its summary.json is unreadable ({0})")]
    SummaryBad(#[source] serde_json::Error),
    /// The run was cut short.
    #[error("it was stopped before it ended (its summary.json says interrupted)")]
    Interrupted,
}

/// The seed the run in `dir` used, from its `scenario.toml`, or why it cannot be read.
pub fn seed_of(dir: &Path) -> Result<u64, RunFolderError> {
    let text = std::fs::read_to_string(dir.join("scenario.toml"))
        .map_err(RunFolderError::ScenarioUnread)?;
    tactile_scenario::Scenario::from_recorded_toml(&text)
        .map(|s| s.seed)
        .map_err(RunFolderError::ScenarioBad)
}

/// The run's `summary.json` in `dir`, or why it cannot be read.
pub fn read_summary(dir: &Path) -> Result<serde_json::Value, RunFolderError> {
    let text =
        std::fs::read_to_string(dir.join("summary.json")).map_err(RunFolderError::SummaryUnread)?;
    serde_json::from_str(&text).map_err(RunFolderError::SummaryBad)
}

fn summary(dir: &Path) -> Option<serde_json::Value> {
    read_summary(dir).ok()
}

/// True if the run in `dir` failed (a node died or a wait ran out).
pub fn failed(dir: &Path) -> bool {
    summary(dir).is_some_and(|j| j["failed"] == true)
}

/// What `--resume` keeps of a folder: a run that ended, did not fail, and ran this
/// very combination (its `scenario.toml`, input paths aside, is `w`'s scenario), its
/// summary the report of the folder's own record, never another scenario's or
/// another run's summary left in the folder; with `--trace`, one that wrote the
/// trace files asked for.
fn kept(w: &Work, args: &SweepOptions) -> Option<Vec<Option<f64>>> {
    // With --trace, a run kept has the trace files asked for (else it runs again).
    if args.trace {
        let f = args.trace_format;
        let csv = f != TraceFormat::Parquet;
        let parquet = f != TraceFormat::Csv;
        let has = |name: &str| w.dir.join(name).is_file();
        if (csv && !has("trace.csv")) || (parquet && !has(PARQUET_FILE)) {
            return None;
        }
    }
    let text = std::fs::read_to_string(w.dir.join("scenario.toml")).ok()?;
    let mut theirs = tactile_scenario::Scenario::from_recorded_toml(&text).ok()?;
    let mut ours = w.loaded.scenario.clone();
    for s in [&mut theirs, &mut ours] {
        for p in s.input_paths_mut() {
            p.clear();
        }
    }
    // The summary must be these records' report, not one copied in from another run.
    let own = summary(&w.dir).is_some_and(|j| of_these_records(&w.dir, &j));
    (theirs == ours && own && !failed(&w.dir))
        .then(|| finished(&w.dir))
        .flatten()
}

/// Runs `work` on `jobs` threads; each entry of the result is the run's metrics, or
/// `None` for a run a stop request kept from ending.
pub fn run_all(
    work: &[Work],
    jobs: usize,
    args: &SweepOptions,
    progress: &(dyn Fn(&Progress) + Sync),
) -> Result<Vec<Option<Vec<Option<f64>>>>, Error> {
    let stop =
        tactile_runtime::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    let results: Mutex<Vec<Option<Vec<Option<f64>>>>> = Mutex::new(vec![None; work.len()]);
    let mut todo = Vec::new();
    for (i, w) in work.iter().enumerate() {
        match args.resume.then(|| kept(w, args)).flatten() {
            Some(v) => lock(&results)[i] = Some(v),
            None => todo.push(i),
        }
    }
    if todo.len() < work.len() {
        crate::noteln!(
            "tactile sweep: {} runs kept from before (--resume)",
            work.len() - todo.len()
        );
    }
    let next = AtomicUsize::new(0);
    let ended = Mutex::new(0usize);
    let failed: Mutex<Option<Error>> = Mutex::new(None);
    let abort = AtomicBool::new(false);
    let start = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..jobs.min(todo.len()).max(1) {
            scope.spawn(|| loop {
                let j = next.fetch_add(1, Ordering::SeqCst);
                if j >= todo.len() || stop.load(Ordering::SeqCst) || abort.load(Ordering::SeqCst) {
                    break;
                }
                let w = &work[todo[j]];
                match run_one(w, args) {
                    Ok(Some(v)) => lock(&results)[todo[j]] = Some(v),
                    Ok(None) => {
                        // Cut short by the stop: not one of the runs that ended.
                        stopped(w);
                        continue;
                    }
                    Err(e) => {
                        abort.store(true, Ordering::SeqCst);
                        lock(&failed).get_or_insert(e);
                        break;
                    }
                }
                // Counted and told under one lock, so the counts are told in order.
                let mut n = lock(&ended);
                *n += 1;
                progress(&Progress {
                    ended: *n,
                    total: todo.len(),
                    elapsed: start.elapsed(),
                    run: w.name(),
                    what: w.what.clone(),
                });
            });
        }
    });
    if let Some(e) = lock(&failed).take() {
        return Err(e);
    }
    Ok(results.into_inner().unwrap_or_else(|p| p.into_inner()))
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// A run of the sweep ended: what a progress bar or line shows.
#[derive(Debug, Clone)]
pub struct Progress {
    /// Runs ended so far, this one included (not counting those `--resume` kept).
    pub ended: usize,
    /// Runs this sweep runs (not counting those `--resume` kept).
    pub total: usize,
    /// Since the first run started.
    pub elapsed: Duration,
    /// The run's folder's name, `run-0011`.
    pub run: String,
    /// Its combination, `KEY=VALUE ...`.
    pub what: String,
}

impl Progress {
    /// `tactile sweep: 12/40 runs, 0:31 elapsed, about 1:12 left (run-0011: ...)`.
    pub fn say(&self) {
        let elapsed = self.elapsed.as_secs_f64();
        let left = elapsed / self.ended as f64 * (self.total - self.ended) as f64;
        let mmss = |s: f64| format!("{}:{:02}", (s / 60.0) as u64, (s % 60.0) as u64);
        crate::noteln!(
            "tactile sweep: {}/{} runs, {} elapsed, about {} left ({}: {})",
            self.ended,
            self.total,
            mmss(elapsed),
            mmss(left),
            self.run,
            self.what
        );
    }
}

/// `tactile sweep: run-0003 stopped before it ended (KEY=VALUE ...)`.
fn stopped(w: &Work) {
    crate::noteln!(
        "tactile sweep: {} stopped before it ended ({})",
        w.name(),
        w.what
    );
}

/// One run and its report; its metrics as its `summary.json` holds them, or `None` if
/// a stop request cut it short.
fn run_one(w: &Work, args: &SweepOptions) -> Result<Option<Vec<Option<f64>>>, Error> {
    let l = &w.loaded;
    let outputs = crate::Outputs {
        trace_columns: w.columns.clone(),
        ..args.outputs()
    };
    let summary = if args.processes {
        crate::clean_stale_runs();
        let sup = crate::sweep_supervision(outputs);
        crate::run_processes(l, &w.dir, &sup)?
    } else {
        crate::sim::run_in_process(l, &w.dir, &outputs, Default::default())?
    };
    if summary.interrupted {
        return Ok(None);
    }
    finished(&w.dir).map(Some).ok_or_else(|| {
        Error::Failed(format!(
            "{}: no whole summary.json after the run",
            w.dir.display()
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// A run folder with a garbled summary says which file and keeps the parser's
    /// reason; one with no scenario keeps the system's.
    #[test]
    fn a_run_folders_error_keeps_its_cause() {
        let dir = tempfile::tempdir().expect("tmp");
        std::fs::write(dir.path().join("summary.json"), "{ nope").expect("write");
        let e = read_summary(dir.path()).expect_err("not JSON");
        assert!(
            e.to_string()
                .starts_with("its summary.json is unreadable ("),
            "{e}"
        );
        assert!(e.source().is_some_and(|c| c.is::<serde_json::Error>()));
        let e = seed_of(dir.path()).expect_err("no scenario.toml");
        assert!(e.source().is_some_and(|c| c.is::<std::io::Error>()));
    }
}
