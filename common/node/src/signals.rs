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

/// True once SIGINT or SIGTERM arrived (false if no flag was ever installed).
pub fn stop_requested() -> bool {
    STOP.get().is_some_and(|f| f.load(Ordering::SeqCst))
}
