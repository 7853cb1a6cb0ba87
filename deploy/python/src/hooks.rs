//! Python callables in the loop of an in-process run: the operator and the two
//! predictors, each called once a sample it is needed at, on the run's thread (the
//! caller's), with the GIL taken for the call; and the run's watch, which looks at
//! Python's signals between samples. The package's Python half wraps the user's
//! function so that what reaches here is already checked (three real, finite
//! numbers) and an exception names the sample; an exception, kept in [`Raised`],
//! asks this run alone to stop after the sample in hand (`Hooks::halt`, not the
//! process's stop request, which would stop every run of the process) and is raised
//! once the run has ended; no callable of the run is called after it. A
//! KeyboardInterrupt (a Ctrl-C, raised by Python's handler inside a callable or at
//! the watch) asks what SIGINT asks the command: every run of the process stops
//! after the sample in hand.

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use tactile_control::codec::{Guess, HISTORY};
use tactile_launch::sim::Hooks;
use tactile_master::operator::Operate;
use tactile_runtime::signals;

/// The first exception a run's callables raised, kept until the run has ended.
pub type Raised = Arc<Mutex<Option<PyErr>>>;

/// The exception kept, if any.
pub fn take(raised: &Raised) -> Option<PyErr> {
    lock(raised).take()
}

fn lock(raised: &Raised) -> std::sync::MutexGuard<'_, Option<PyErr>> {
    raised.lock().unwrap_or_else(|p| p.into_inner())
}

/// Keeps `e` (unless an exception is kept already); a KeyboardInterrupt asks every
/// loop of the process to stop, as SIGINT does; anything else this run alone.
fn keep(py: Python<'_>, raised: &Raised, halt: &AtomicBool, e: PyErr) {
    if e.is_instance_of::<PyKeyboardInterrupt>(py) {
        signals::request_stop();
    } else {
        halt.store(true, Ordering::SeqCst);
    }
    lock(raised).get_or_insert(e);
}

/// The run's watch (`Hooks::watch`), called between samples on the loop's thread:
/// every [`SIGNAL_POLL`](super::SIGNAL_POLL) it takes the GIL and runs Python's signal
/// handlers (Python runs them on the main thread only: from another thread this
/// finds nothing). What they raise is kept, as a callable's exception is, and stops
/// the run.
fn watch(raised: &Raised, halt: &Arc<AtomicBool>) -> Box<dyn FnMut() -> bool + Send> {
    let (raised, halt) = (Arc::clone(raised), Arc::clone(halt));
    let mut next = Instant::now() + super::SIGNAL_POLL;
    Box::new(move || {
        let now = Instant::now();
        if now < next {
            return false;
        }
        next = now + super::SIGNAL_POLL;
        Python::attach(|py| match py.check_signals() {
            Ok(()) => false,
            Err(e) => {
                keep(py, &raised, &halt, e);
                true
            }
        })
    })
}

/// One of the run's callables (the Python half's wrapper, which returns three
/// floats or raises).
struct Callable {
    f: Py<PyAny>,
    raised: Raised,
    /// The run's own stop request (`Hooks::halt`).
    halt: Arc<AtomicBool>,
}

impl Callable {
    /// `f(args)` as three numbers; `None` once any of the run's callables raised
    /// (this one now: its exception is kept and the run asked to stop).
    fn call<A>(&self, args: impl FnOnce(Python<'_>) -> A) -> Option<[f64; 3]>
    where
        A: for<'py> pyo3::call::PyCallArgs<'py>,
    {
        if lock(&self.raised).is_some() {
            return None;
        }
        // The lock is not held over the call: the GIL is taken there.
        Python::attach(|py| {
            let got = self
                .f
                .call1(py, args(py))
                .and_then(|r| r.extract::<(f64, f64, f64)>(py));
            match got {
                Ok((x, y, z)) => Some([x, y, z]),
                Err(e) => {
                    keep(py, &self.raised, &self.halt, e);
                    None
                }
            }
        })
    }
}

/// The operator: `f(n, t, fx, fy, fz)`, the force the hand felt as its last three.
struct Operator(Callable);

impl Operate for Operator {
    fn target(&mut self, n: u64, t: f64, felt: [f64; 3]) -> Option<[f64; 3]> {
        self.0.call(|_| (n, t, felt[0], felt[1], felt[2]))
    }
}

/// A predictor: `f(n, to, history)`, the history as the bytes of a (k, 4) float64
/// array, rows `[sample, x, y, z]`, oldest first.
struct Predictor {
    call: Callable,
    bytes: Vec<u8>,
}

impl Guess for Predictor {
    fn guess(&mut self, n: u64, to: u64, history: &[(u64, [f64; 3])]) -> Option<[f64; 3]> {
        self.bytes.clear();
        for (at, v) in history {
            for x in [*at as f64, v[0], v[1], v[2]] {
                self.bytes.extend_from_slice(&x.to_ne_bytes());
            }
        }
        let bytes = &self.bytes;
        self.call
            .call(|py| (n, to, PyBytes::new(py, bytes).unbind()))
    }
}

/// The hooks for `[operator, backward predictor, forward predictor]`, each the
/// Python half's wrapper or None, and the watch, sharing `raised`.
pub fn hooks(f: [Option<Py<PyAny>>; 3], raised: &Raised) -> Hooks {
    let [operator, backward, forward] = f;
    let halt = Arc::new(AtomicBool::new(false));
    let callable = |f: Py<PyAny>| Callable {
        f,
        raised: Arc::clone(raised),
        halt: Arc::clone(&halt),
    };
    let predictor = |f: Py<PyAny>| -> Box<dyn Guess> {
        Box::new(Predictor {
            call: callable(f),
            bytes: Vec::with_capacity(HISTORY * 4 * 8),
        })
    };
    Hooks {
        operator: operator.map(|f| Box::new(Operator(callable(f))) as Box<dyn Operate>),
        backward_predictor: backward.map(predictor),
        forward_predictor: forward.map(predictor),
        watch: Some(watch(raised, &halt)),
        halt: Arc::clone(&halt),
    }
}
