//! `tactile._native`: the Python package's compiled half. It calls the libraries the
//! `tactile` command calls (the scenario's reading, loading and checks, the
//! in-process run, the report), with no subprocess and no second copy of the loop;
//! the package's Python half (`python/tactile/__init__.py`) gives them their Python
//! shape (a `Scenario` value, a `Run` whose tables are pyarrow's).
//!
//! Every function takes a scenario as its source (text, the folder its relative
//! paths are resolved against, its name for errors, its file if any) and its `--set`s
//! as the command takes them, so a scenario is checked, resolved and run exactly as
//! `tactile check` and `tactile run --in-process` do.
//!
//! Signals stay Python's: the module installs no handler (a SIGTERM still ends the
//! interpreter, a Ctrl-C raises KeyboardInterrupt wherever Python is). A run's loop
//! computes on the caller's thread with the GIL released, taking it back for its
//! callables and, every [`SIGNAL_POLL`], to look at Python's signals (Python runs its
//! handlers on the main thread alone: there a Ctrl-C raises inside a callable that
//! blocks, and between samples); a KeyboardInterrupt asks the run to stop after the
//! sample in hand, as SIGINT asks the command, and is raised once the report of what
//! ran is written. A sweep's runs, and every report, compute on threads of their own
//! while the caller's thread waits with the GIL released, looking at the signals as
//! often.

mod hooks;

use hooks::Raised;
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tactile_launch::error::Error;
use tactile_launch::sweep::{Base, Progress, SweepOptions};
use tactile_launch::{load_source, parse_sets, Loaded, Outputs, Source};
use tactile_report::write::{write_report, Launch};
use tactile_runtime::files;
use tactile_runtime::signals;
use tactile_scenario::overrides::Set;

create_exception!(
    _native,
    ScenarioError,
    PyValueError,
    "A scenario, a --set or an input the command would refuse (exit status 2); the message is the command's, naming the field."
);
create_exception!(
    _native,
    RunError,
    PyRuntimeError,
    "A run or a report that failed (exit status 1); the message is the command's."
);

/// How often a run's loop, or a waiting call, looks at Python's signals: a Ctrl-C is
/// answered within this (plus the sample in hand).
const SIGNAL_POLL: Duration = Duration::from_millis(20);

/// The command's error as the Python exception of its exit status: 2 (bad input)
/// ScenarioError, 130 KeyboardInterrupt, else RunError.
fn to_py(e: Error) -> PyErr {
    match e.exit_code() {
        2 => ScenarioError::new_err(e.to_string()),
        130 => PyKeyboardInterrupt::new_err(e.to_string()),
        _ => RunError::new_err(e.to_string()),
    }
}

/// A scenario's source as the Python half holds it.
fn source(text: String, base_dir: &str, name: String, path: Option<&str>) -> Source {
    Source {
        text,
        base_dir: PathBuf::from(base_dir),
        name,
        path: path.map(PathBuf::from),
    }
}

/// A scenario and its sets as the command loads them, but what this build cannot
/// run is said as a Python user can act on it, where the command's refusal names a
/// `cargo build` flag: a scenario that uses ROS 2 needs the node programs (a run
/// from Python is in-process, so no rebuild could help), and `arithmetic = "rtl"`
/// a package built with the RTL (a pip option, not a cargo one).
fn load(src: &Source, sets: &[String]) -> Result<Loaded, Error> {
    let sets = parse_sets(sets)?;
    if let Some(s) = parsed(src, &sets) {
        if tactile_runtime::outside::ros_in_run(&s) {
            return Err(Error::BadInput(format!(
                "{}: this scenario uses ROS 2 (a ros2 backend or the live view), which needs the node programs: run it with the tactile command built with ROS 2 (`cargo build --release --features zenoh`, then `tactile run {}`); the Python package runs scenarios in-process, where no build reaches ROS 2",
                src.name, src.name
            )));
        }
        if s.arithmetic == tactile_math::arith::ArithKind::Rtl && !cfg!(feature = "rtl") {
            return Err(Error::BadInput(format!(
                "{}: arithmetic \"rtl\" needs the RTL simulated by Verilator, which this package was built without: install it with the RTL (Verilator, make and g++ present: `python3 -m pip install ./deploy/python --config-settings=build-args=\"--features rtl\"`)",
                src.name
            )));
        }
    }
    load_source(src, &sets)
}

/// The scenario with `sets` applied, parsed and its ranges checked as `load_source`
/// starts; None where that fails (`load_source` then says why).
fn parsed(src: &Source, sets: &[Set]) -> Option<tactile_scenario::Scenario> {
    let text = tactile_scenario::overrides::apply(&src.text, sets).ok()?;
    tactile_scenario::Scenario::from_toml_str(&text).ok()
}

/// What `Scenario.with_set` asks at once: the sets' keys are the scenario's and
/// their values of its types (a misspelt key raises where it was typed, not at the
/// run). A value out of range, which may hang on other keys still to be set, is left
/// to `check()` and the run. The error is the command's, as `check()` gives it.
#[pyfunction]
#[pyo3(signature = (text, base_dir, name, path, sets))]
fn check_sets(
    text: String,
    base_dir: &str,
    name: String,
    path: Option<&str>,
    sets: Vec<String>,
) -> PyResult<()> {
    use tactile_scenario::ScenarioError as Bad;
    let src = source(text, base_dir, name, path);
    let parsed = parse_sets(&sets)
        .and_then(|s| tactile_scenario::overrides::apply(&src.text, &s).map_err(Error::from));
    let typed = match parsed {
        Ok(text) => !matches!(
            tactile_scenario::Scenario::from_toml_str(&text),
            Err(Bad::Parse(_))
        ),
        Err(_) => false,
    };
    if typed {
        return Ok(());
    }
    // The command's own message for it: loading fails at the same step.
    load(&src, &sets).map(drop).map_err(to_py)
}

/// A sweep's axes and the value of each axis in each combination.
type Grid = (Vec<(String, bool, Vec<String>)>, Vec<Vec<usize>>);

/// A sweep's `--set`s (its `sweep.json`) as its grid: each key, whether it is paired
/// with the key before it, and its values as JSON, in order; and every combination
/// (the index of its value on each axis), in the grid's order.
#[pyfunction]
fn sweep_grid(sets: Vec<String>) -> PyResult<Grid> {
    let axes = tactile_launch::sweep::parse_axes(&sets).map_err(to_py)?;
    let combos = tactile_report::sweep::combinations(&axes);
    let axes = axes
        .into_iter()
        .map(|a| {
            let values = a
                .sets
                .iter()
                .map(|s| serde_json::to_string(&s.value).unwrap_or_else(|_| s.value.to_string()))
                .collect();
            (a.key, a.paired, values)
        })
        .collect();
    Ok((axes, combos))
}

/// What a computing thread tells the waiting one.
enum Told<E> {
    /// Something for the caller's Python code (a sweep's progress).
    Event(E),
    /// The work is done.
    Ended,
}

/// Runs `work` on a thread of its own while this thread waits, the GIL released,
/// looking at Python's signals: a KeyboardInterrupt (or whatever the caller's handler
/// raises) asks `work` to stop and is returned once `work` has ended. What `work`
/// tells (its first argument) is handed to `on_event` on this thread, with the GIL;
/// an exception there stops the work as a KeyboardInterrupt does.
fn interruptible<T: Send, E: Send>(
    py: Python<'_>,
    work: impl FnOnce(&(dyn Fn(E) + Sync)) -> Result<T, Error> + Send,
    mut on_event: impl FnMut(Python<'_>, E) -> PyResult<()>,
) -> PyResult<T> {
    use std::sync::mpsc::{channel, RecvTimeoutError};
    let (tell, mut told) = channel::<Told<E>>();
    std::thread::scope(|s| {
        let handle = s.spawn(move || {
            let event = |e| {
                let _ = tell.send(Told::Event(e));
            };
            // The thread is made known to Python once and then lets the GIL go: a
            // callable in the loop takes the GIL back in a fraction of the time it
            // would take with a fresh thread state each call.
            let done = Python::attach(|py| py.detach(|| work(&event)));
            let _ = tell.send(Told::Ended);
            done
        });
        let mut raised: Option<PyErr> = None;
        let stop = |e: PyErr, raised: &mut Option<PyErr>| {
            if raised.is_none() {
                signals::request_stop();
                *raised = Some(e);
            }
        };
        loop {
            // Woken at once when the work tells or ends (or panics: the sender is
            // dropped). The receiver goes along and back: it may be sent, not shared.
            let (got, back) = py.detach(move || (told.recv_timeout(SIGNAL_POLL), told));
            told = back;
            match got {
                Ok(Told::Event(e)) if raised.is_none() => {
                    if let Err(err) = on_event(py, e) {
                        stop(err, &mut raised);
                    }
                }
                Ok(Told::Event(_)) => {}
                Ok(Told::Ended) | Err(RecvTimeoutError::Disconnected) => break,
                Err(RecvTimeoutError::Timeout) => {}
            }
            if let Err(e) = py.check_signals() {
                stop(e, &mut raised);
            }
        }
        let done = handle
            .join()
            .map_err(|_| RunError::new_err("the run panicked; its records say how far it got"))?;
        match raised {
            Some(e) => Err(e),
            None => done.map_err(to_py),
        }
    })
}

/// [`interruptible`] for work that tells nothing.
fn waiting<T: Send>(py: Python<'_>, work: impl FnOnce() -> Result<T, Error> + Send) -> PyResult<T> {
    interruptible(py, |_: &(dyn Fn(()) + Sync)| work(), |_, ()| Ok(()))
}

/// A scenario file read as the command reads it (its size cap, UTF-8): its text, the
/// folder its relative paths are resolved against, its name.
#[pyfunction]
fn read_scenario(path: PathBuf) -> PyResult<(String, PathBuf, String)> {
    let text = files::read_text(&path, "scenario", files::MAX_SCENARIO_BYTES)
        .map_err(|e| to_py(e.into()))?;
    Ok((text, files::base_dir(&path), path.display().to_string()))
}

/// `tactile check`: the scenario as it would run (every default filled in, the sets
/// applied, paths resolved), and what `check` says about it (length, files, the
/// delays in both units, warnings).
#[pyfunction]
#[pyo3(signature = (text, base_dir, name, path, sets))]
fn check(
    text: String,
    base_dir: &str,
    name: String,
    path: Option<&str>,
    sets: Vec<String>,
) -> PyResult<(String, Vec<String>)> {
    let loaded = load(&source(text, base_dir, name, path), &sets).map_err(to_py)?;
    let notes = tactile_launch::estimate::report(&loaded);
    Ok((loaded.scenario.resolved(&loaded.base_dir).to_toml(), notes))
}

/// `tactile run --in-process` into `out`, the trace as `trace_format` (csv, parquet,
/// both; None: `--no-trace`), with the Python callables given in its loop (see [`hooks`]); whether it
/// completed is its summary's (`failed`). A KeyboardInterrupt while it runs (between
/// samples, or inside a callable, even one blocked in a system call, when called
/// from the main thread) ends it after the sample in hand and is raised once the
/// report of what ran is written (marked `interrupted`); so is the first exception a
/// callable raised. The next run starts afresh.
#[pyfunction]
#[pyo3(signature = (text, base_dir, name, path, sets, out, trace_format, operator, backward_predictor, forward_predictor))]
#[allow(clippy::too_many_arguments)] // the source's four parts, as everywhere here
fn run(
    py: Python<'_>,
    text: String,
    base_dir: &str,
    name: String,
    path: Option<&str>,
    sets: Vec<String>,
    out: PathBuf,
    trace_format: Option<&str>,
    operator: Option<Py<PyAny>>,
    backward_predictor: Option<Py<PyAny>>,
    forward_predictor: Option<Py<PyAny>>,
) -> PyResult<()> {
    let outputs = outputs(trace_format)?;
    let src = source(text, base_dir, name, path);
    let raised = Raised::default();
    let hooks = hooks::hooks([operator, backward_predictor, forward_predictor], &raised);
    signals::clear_stop();
    // The loop on this thread, the GIL released and taken back for each callable:
    // Python runs its signal handlers on the main thread alone, so a Ctrl-C reaches a
    // callable that blocks there (raising KeyboardInterrupt inside it), and the watch
    // looks at the signals between samples. The report on another thread, while this
    // one looks at the signals.
    let simulated = py.detach(|| {
        let loaded = load(&src, &sets)?;
        tactile_launch::sim::simulate_into(&loaded, &out, hooks)
    });
    let summary = simulated
        .map_err(to_py)
        .and_then(|s| waiting(py, move || s.report(&outputs)));
    if let Some(e) = hooks::take(&raised) {
        return Err(e);
    }
    if summary?.interrupted {
        return Err(to_py(Error::Interrupted));
    }
    Ok(())
}

/// `tactile sweep` of the source with `sets` applied (the swept keys' values win),
/// over the `swept` axes (`KEY=V1,V2,...` as `--set` takes them), `seeds` seeds each,
/// `jobs` runs at once (None: the CPUs), into `out`; with `trace`, every run's trace
/// as `trace_format`; with `resume`, the runs already in `out` are kept. After each
/// run, `progress(ended, total, run, what)` is called with the GIL (an exception
/// there stops the sweep). Returns the runs it ran; the tables are in `out`.
#[pyfunction]
#[pyo3(signature = (text, base_dir, name, path, sets, swept, seeds, jobs, out, trace, trace_format, resume, progress))]
#[allow(clippy::too_many_arguments)] // the source's four parts and the sweep's options
fn sweep(
    py: Python<'_>,
    text: String,
    base_dir: &str,
    name: String,
    path: Option<&str>,
    sets: Vec<String>,
    swept: Vec<String>,
    seeds: usize,
    jobs: Option<usize>,
    out: PathBuf,
    trace: bool,
    trace_format: &str,
    resume: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<usize> {
    let args = SweepOptions {
        set: swept,
        out,
        processes: false,
        trace,
        trace_format: outputs(Some(trace_format))?.trace_format,
        mcap_compression: Default::default(),
        jobs,
        seeds,
        resume,
        shard: None,
    };
    let base = Base {
        source: source(text, base_dir, name, path),
        sets,
    };
    signals::clear_stop();
    interruptible(
        py,
        |tell: &(dyn Fn(Progress) + Sync)| {
            tactile_launch::sweep::sweep(&base, &args, &|p: &Progress| tell(p.clone()))
        },
        |py, p: Progress| match &progress {
            Some(f) => f.call1(py, (p.ended, p.total, p.run, p.what)).map(drop),
            None => Ok(()),
        },
    )
}

/// `tactile report DIR... [--out OUT]`: the report of the records in `dirs` (a run's
/// folder, or one folder per node) written into `out` (None: beside the master's
/// record, as the command does), the trace as `trace_format`. Returns the folder.
#[pyfunction]
#[pyo3(signature = (dirs, out, trace_format))]
fn report(
    py: Python<'_>,
    dirs: Vec<PathBuf>,
    out: Option<PathBuf>,
    trace_format: &str,
) -> PyResult<PathBuf> {
    let outputs = outputs(Some(trace_format))?;
    signals::clear_stop();
    waiting(py, || {
        let out = match out {
            Some(o) => o,
            None => tactile_launch::report_out(&dirs)?,
        };
        write_into(&dirs, &out, outputs)?;
        Ok(out)
    })
}

fn write_into(dirs: &[PathBuf], out: &Path, outputs: Outputs) -> Result<(), Error> {
    let holder = format!("tactile report from Python (pid {})", std::process::id());
    let _held = tactile_report::out::take(out, &holder)?;
    let launch = Launch {
        outputs,
        stop: Some(signals::handled_by_caller()),
        ..Launch::default()
    };
    let summary = write_report(dirs, out, &launch)?;
    if summary.interrupted {
        return Err(Error::Interrupted);
    }
    Ok(())
}

/// An episode as `export_lerobot` hands it back: its run's folder, frames, task text,
/// and the sample a damaged record ended it at.
type EpisodeOut = (PathBuf, u64, String, Option<u64>);

/// `tactile export lerobot RUN... --out OUT --fps FPS [--task TASK]`: the runs (run
/// folders and sweep folders) as a LeRobot v3.0 dataset in the new folder `out`.
/// Returns each episode, in order, and the warnings the command prints.
#[pyfunction]
#[pyo3(signature = (runs, out, fps, task))]
fn export_lerobot(
    py: Python<'_>,
    runs: Vec<PathBuf>,
    out: PathBuf,
    fps: u32,
    task: Option<String>,
) -> PyResult<(Vec<EpisodeOut>, Vec<String>)> {
    let opts = tactile_report::lerobot::Options { fps, task };
    signals::clear_stop();
    let stop = signals::handled_by_caller();
    waiting(py, move || {
        let stopped = || stop.load(std::sync::atomic::Ordering::SeqCst);
        let done = tactile_report::lerobot::export(&runs, &out, &opts, &stopped)?;
        let episodes = done
            .episodes
            .into_iter()
            .map(|e| (e.run, e.length, e.task, e.damaged_at))
            .collect();
        Ok((episodes, done.warnings))
    })
}

/// The outputs of a run or report from Python: its trace as `trace_format`, or no
/// trace and no recording for None (the command's `--no-trace`).
fn outputs(trace_format: Option<&str>) -> PyResult<Outputs> {
    let Some(format) = trace_format else {
        return Ok(Outputs {
            no_trace: true,
            ..Outputs::default()
        });
    };
    let trace_format = format
        .parse()
        .map_err(|e: tactile_report::error::UnknownChoice| {
            ScenarioError::new_err(format!("trace_format: {e}"))
        })?;
    Ok(Outputs {
        trace_format,
        ..Outputs::default()
    })
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Before anything could install the command's handlers: signals stay Python's.
    signals::handled_by_caller();
    m.add_function(wrap_pyfunction!(read_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(check_sets, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_grid, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(report, m)?)?;
    m.add_function(wrap_pyfunction!(export_lerobot, m)?)?;
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add("RunError", m.py().get_type::<RunError>())?;
    m.add("PAPER_SCENARIO", tactile_launch::PAPER_SCENARIO)?;
    m.add("MAX_SCENARIO_BYTES", files::MAX_SCENARIO_BYTES)?;
    Ok(())
}
