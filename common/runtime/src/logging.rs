//! A node's log: `tracing` events into `<role>.log` in the node's output folder, and,
//! when the node runs by hand, also to stderr (in colour only on a terminal). Neither
//! file nor redirected stderr gets colour codes. `RUST_LOG` sets the level (default
//! [`DEFAULT_FILTER`]).

use std::io::IsTerminal;
use std::path::Path;
use tracing_subscriber::layer::SubscriberExt;
use tracing_subscriber::util::SubscriberInitExt;
use tracing_subscriber::{fmt, EnvFilter, Layer};

/// The log's level without `RUST_LOG`: info, and the attempts of Zenoh's connecting
/// side, which it says only at debug: a connection refused, a failed TLS handshake (the
/// listener says its side at warn), a retry, so a node that cannot reach its peer or
/// its router says why on its own side too.
pub const DEFAULT_FILTER: &str = "info,zenoh::net::runtime::orchestrator=debug";

/// The node's log file could not be opened.
#[derive(Debug, thiserror::Error)]
#[error("opening {}: {source}", path.display())]
pub struct LogError {
    /// The log file.
    pub path: std::path::PathBuf,
    /// The operating system's reason.
    pub source: std::io::Error,
}

/// Installs the node's logger; `to_stderr` adds a copy on stderr. Returns an error line
/// if the log file cannot be opened.
pub fn init(dir: &Path, role: tactile_messages::Role, to_stderr: bool) -> Result<(), LogError> {
    let path = dir.join(format!("{role}.log"));
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|source| LogError { path, source })?;
    let filter =
        || EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new(DEFAULT_FILTER));
    let file_layer = fmt::layer()
        .with_writer(std::sync::Mutex::new(file))
        .with_ansi(false)
        .with_target(false)
        .with_filter(filter());
    // Colours only for a terminal: a node started by hand with its stderr sent to a
    // file (`2> master.err`, a pipe, ssh, a service's journal) would write escape
    // codes into it, which tracing does by default. NO_COLOR is kept as tracing keeps it.
    let ansi = std::io::stderr().is_terminal()
        && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty());
    let stderr_layer = to_stderr.then(|| {
        fmt::layer()
            .with_writer(std::io::stderr)
            .with_ansi(ansi)
            .with_target(false)
            .with_filter(filter())
    });
    // A second init in one process (tests) keeps the first logger.
    let _ = tracing_subscriber::registry()
        .with(file_layer)
        .with(stderr_layer)
        .try_init();
    Ok(())
}
