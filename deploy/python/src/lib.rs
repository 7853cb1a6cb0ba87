//! `tactile._native`: the Python package's compiled half. It calls the libraries the
//! `tactile` command calls (the scenario's loading and checks, the in-process run,
//! the report), with no subprocess and no second copy of the loop; the package's
//! Python half (`python/tactile/__init__.py`) gives them their Python shape (a
//! `Scenario` value, a `Run` whose tables are pyarrow's).
//!
//! Every function takes a scenario as its source (text, the folder its relative
//! paths are resolved against, its name for errors, its file if any) and its `--set`s
//! as the command takes them, so a scenario is checked, resolved and run exactly as
//! `tactile check` and `tactile run --in-process` do. A run releases the GIL while it
//! computes.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use tactile::error::Error;
use tactile::launch::{load_source, parse_sets, Loaded, Outputs, Source};
use tactile_report::write::{write_report, Launch};

create_exception!(
    _native,
    ScenarioError,
    PyValueError,
    "A scenario, a --set or an input file the command would refuse (exit status 2); the message is the command's, naming the field."
);
create_exception!(
    _native,
    RunError,
    PyRuntimeError,
    "A run or a report that failed (exit status 1); the message is the command's."
);

/// The command's error as the Python exception of its kind.
fn to_py(e: Error) -> PyErr {
    match e {
        Error::BadInput(m) => ScenarioError::new_err(m),
        Error::Interrupted => pyo3::exceptions::PyKeyboardInterrupt::new_err(e.to_string()),
        other => RunError::new_err(other.to_string()),
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

fn load(src: &Source, sets: &[String]) -> Result<Loaded, Error> {
    load_source(src, &parse_sets(sets)?)
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
    let s = &loaded.scenario;
    let mut notes = tactile::cmd::check::report(s);
    notes.extend(loaded.warnings.iter().map(|w| format!("warning: {w}")));
    Ok((s.resolved(&loaded.base_dir).to_toml(), notes))
}

/// `tactile run --in-process` into `out`, the trace as `trace_format` (csv, parquet,
/// both). Returns whether the run completed (False: failed). A stop request (SIGINT:
/// Ctrl-C in a terminal or a notebook's interrupt; SIGTERM) ends it after the sample
/// in hand, as it ends the command, and raises KeyboardInterrupt once the report of
/// what ran is written; the next run starts with no request.
#[pyfunction]
#[pyo3(signature = (text, base_dir, name, path, sets, out, trace_format))]
#[allow(clippy::too_many_arguments)] // the source's four parts, as everywhere here
fn run(
    py: Python<'_>,
    text: String,
    base_dir: &str,
    name: String,
    path: Option<&str>,
    sets: Vec<String>,
    out: PathBuf,
    trace_format: &str,
) -> PyResult<bool> {
    let outputs = outputs(trace_format)?;
    let src = source(text, base_dir, name, path);
    let summary = py
        .detach(|| {
            // A Ctrl-C answered by an earlier run (its KeyboardInterrupt) is over.
            tactile_runtime::signals::clear_stop();
            let loaded = load(&src, &sets)?;
            tactile::launch::sim::run_in_process(&loaded, &out, &outputs)
        })
        .map_err(to_py)?;
    if summary.interrupted {
        return Err(interrupted(py));
    }
    Ok(!summary.failed)
}

/// The error a stopped run raises. Python's own SIGINT handler saw the signal too
/// (the run's handler chains to it), so its KeyboardInterrupt is pending: it is taken
/// now, once, else it would interrupt the caller's `except` a second time. A handler
/// of the caller's that raises something else has its way.
fn interrupted(py: Python<'_>) -> PyErr {
    match py.check_signals() {
        Err(e) if !e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) => e,
        _ => to_py(Error::Interrupted),
    }
}

/// `tactile report DIR... --out OUT`: the report of the records in `dirs` (a run's
/// folder, or one folder per node) written into `out`, the trace as `trace_format`.
#[pyfunction]
fn report(py: Python<'_>, dirs: Vec<PathBuf>, out: PathBuf, trace_format: &str) -> PyResult<()> {
    let outputs = outputs(trace_format)?;
    py.detach(|| -> Result<(), Error> {
        tactile_runtime::signals::clear_stop();
        let holder = format!("tactile report from Python (pid {})", std::process::id());
        let _held = tactile_report::out::take(&out, &holder)?;
        let launch = Launch {
            outputs,
            ..Launch::default()
        };
        write_report(&dirs, &out, &launch)?;
        Ok(())
    })
    .map_err(to_py)
}

/// The outputs of a run or report from Python: its trace as `trace_format`.
fn outputs(trace_format: &str) -> PyResult<Outputs> {
    let trace_format = trace_format
        .parse()
        .map_err(|e: String| ScenarioError::new_err(format!("trace_format: {e}")))?;
    Ok(Outputs {
        trace_format,
        ..Outputs::default()
    })
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(report, m)?)?;
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add("RunError", m.py().get_type::<RunError>())?;
    m.add("PAPER_SCENARIO", tactile::launch::PAPER_SCENARIO)?;
    Ok(())
}
