//! Stop requests: SIGINT and SIGTERM set a flag that the loops look at between
//! samples, so a node, a launcher or a bench ends cleanly and writes what it has
//! instead of dying mid-frame.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// A flag that SIGINT and SIGTERM set from now on. Each call registers its own flag,
/// so several parts of one process can each notice the request.
pub fn stop_flag() -> std::io::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop))?;
    }
    Ok(stop)
}
