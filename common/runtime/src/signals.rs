//! Stop requests: SIGINT and SIGTERM set a flag that the loops look at between
//! samples, so a node, a launcher, a sweep or a report ends cleanly and writes what it
//! has instead of dying mid-frame.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

static STOP: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The process's stop flag, which SIGINT and SIGTERM set from the first call on. One
/// flag for the whole process (registered once, never reset), so every part of it
/// (a sweep and each of its runs) sees the same request.
pub fn stop_flag() -> std::io::Result<Arc<AtomicBool>> {
    if let Some(f) = STOP.get() {
        return Ok(Arc::clone(f));
    }
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop))?;
    }
    Ok(Arc::clone(STOP.get_or_init(|| stop)))
}

/// For a library inside another program that handles the signals itself (the Python
/// package: Python's SIGINT handler raises KeyboardInterrupt, and SIGTERM must still
/// end the interpreter): the process's stop flag, made without handlers of its own if
/// none were installed yet, so [`stop_flag`] hands out this flag and installs nothing.
/// The caller sets it with [`request_stop`] when its own handling says so.
pub fn handled_by_caller() -> Arc<AtomicBool> {
    Arc::clone(STOP.get_or_init(|| Arc::new(AtomicBool::new(false))))
}

/// Asks every loop of the process to stop after the sample in hand, as SIGINT does
/// (for a caller that handles the signals itself: [`handled_by_caller`]).
pub fn request_stop() {
    handled_by_caller().store(true, Ordering::SeqCst);
}

/// Forgets a stop request that was answered: for a library whose caller goes on after
/// one (the Python package, where a Ctrl-C ends one run and the notebook goes on), so
/// the next run does not stop at once. The command never calls it: there a request
/// ends the process.
pub fn clear_stop() {
    if let Some(f) = STOP.get() {
        f.store(false, Ordering::SeqCst);
    }
}

/// True once SIGINT or SIGTERM arrived (false if no flag was ever installed), whether
/// the node's handler caught it or iceoryx2's (which takes the signals over once the
/// process maps its shared memory: see `tactile_transport::ipc`); the latter is
/// latched into the flag, so every part of the process sees it from then on.
pub fn stop_requested() -> bool {
    let Some(f) = STOP.get() else {
        return false;
    };
    if f.load(Ordering::SeqCst) {
        return true;
    }
    if tactile_transport::ipc::termination_requested() {
        f.store(true, Ordering::SeqCst);
        return true;
    }
    false
}
