//! What a report can fail with. The `tactile` command maps each to its exit status.

use thiserror::Error;

/// Everything reading records and writing a report can fail with.
#[derive(Debug, Error)]
pub enum Error {
    /// Bad input: a missing, foreign or malformed record, named by file and byte.
    #[error("{0}")]
    BadInput(String),
    /// Reading a record or writing a report file failed.
    #[error("{context}: {source}")]
    Io {
        /// What was being read or written.
        context: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// Something else went wrong while writing (a plot, an encoding).
    #[error("{0}")]
    Failed(String),
    /// A stop request (SIGINT, SIGTERM) came before a sample was joined: no report was
    /// written.
    #[error("{0}")]
    Stopped(String),
}

impl Error {
    /// Wraps an I/O error with what was being done.
    pub fn io(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> Error {
        let context = context.into();
        move |source| Error::Io { context, source }
    }
}
