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
    /// A plot or a map could not be drawn.
    #[error("{what}: {source}")]
    Plot {
        /// Which (`plotting latency`, `drawing the sweep's maps`).
        what: String,
        /// Why.
        source: crate::plots::PlotError,
    },
    /// Something else went wrong while writing (an encoding).
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

/// A word that is none of an option's choices (`--trace-format`, `--mcap-compression`).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{given:?}: give {choices}")]
pub struct UnknownChoice {
    /// The word given.
    pub given: String,
    /// The choices, as a sentence says them (`csv, parquet or both`).
    pub choices: &'static str,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// A plot that cannot be written keeps plotters' fault under the report's error,
    /// and the operating system's under that.
    #[test]
    fn a_plot_error_keeps_plotters_fault_and_its_cause() {
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join("no-such-folder").join("p.svg");
        let series = [("a".to_string(), vec![(50.0, 1.0), (99.0, 2.0)])];
        let e = crate::plots::whole_svg(&path, |p| crate::plots::percentile_plot(p, "t", &series))
            .expect_err("no folder");
        assert!(matches!(e, crate::plots::PlotError::Draw(_)), "{e:?}");
        let e = Error::Plot {
            what: "plotting percentiles".into(),
            source: e,
        };
        assert!(e.to_string().starts_with("plotting percentiles: "), "{e}");
        let mut chain = Vec::new();
        let mut cause = e.source();
        while let Some(c) = cause {
            chain.push(c.to_string());
            cause = c.source();
        }
        assert!(chain.len() >= 2, "{chain:?}");
        assert!(e
            .source()
            .is_some_and(|c| c.is::<crate::plots::PlotError>()));
    }
}
