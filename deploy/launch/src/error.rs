//! The launcher's errors and the exit status each one maps to.

use tactile_runtime::exit::{EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_INTERRUPTED};
use thiserror::Error;

/// What makes a scenario one that cannot run, each fault kept whole.
#[derive(Debug, Error)]
pub enum InputError {
    /// The `--set`s cannot be applied to its text.
    #[error(transparent)]
    Set(#[from] tactile_scenario::overrides::SetError),
    /// A file it names cannot be read, or is not there.
    #[error(transparent)]
    File(#[from] tactile_runtime::files::FileError),
    /// A recorded network it replays cannot be used.
    #[error(transparent)]
    Replay(#[from] tactile_network_emulator::replay::LoadError),
    /// A delay histogram it draws from cannot be used.
    #[error(transparent)]
    Histogram(#[from] tactile_network_emulator::histogram::LoadError),
    /// The device's gimbal cannot be used.
    #[error(transparent)]
    Gimbal(#[from] tactile_master::peripherals::GimbalError),
}

/// Everything the launcher can fail with.
#[derive(Debug, Error)]
pub enum Error {
    /// Bad input named by file, line, column or field.
    #[error("{0}")]
    BadInput(String),
    /// Reading input or writing output failed.
    #[error("{context}: {source}")]
    Io {
        /// What was being read or written.
        context: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A malformed `--set KEY=VALUE`, or sets that cannot be applied.
    #[error(transparent)]
    Set(#[from] tactile_scenario::overrides::SetError),
    /// A file named cannot be read (a scenario, a device file).
    #[error(transparent)]
    File(#[from] tactile_runtime::files::FileError),
    /// The run's prefix is malformed or held by another process.
    #[error(transparent)]
    Lock(#[from] tactile_runtime::lock::LockError),
    /// A recorded network the scenario replays cannot be used.
    #[error(transparent)]
    Replay(#[from] tactile_network_emulator::replay::LoadError),
    /// A delay histogram the scenario draws from cannot be used.
    #[error(transparent)]
    Histogram(#[from] tactile_network_emulator::histogram::LoadError),
    /// A malformed sweep axis `--set KEY=V1,V2,...`.
    #[error(transparent)]
    Axis(#[from] tactile_report::sweep::AxisError),
    /// The scenario named cannot run: its sets, its values, or a file it names.
    #[error("{name}: {source}")]
    Input {
        /// The scenario's name (its file, or the caller's name for its text).
        name: String,
        /// Why not (boxed: the launcher's error stays small).
        source: Box<InputError>,
    },
    /// A failure while running.
    #[error("{0}")]
    Failed(String),
    /// Reading records or writing the report failed.
    #[error(transparent)]
    Report(#[from] tactile_report::Error),
    /// SIGINT or SIGTERM stopped the run; its report was written.
    #[error("stopped by a signal; the report of what ran was written")]
    Interrupted,
    /// SIGINT or SIGTERM stopped a command that writes no report; what it left.
    #[error("stopped by a signal: {0}")]
    Stopped(String),
}

impl Error {
    /// The process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::BadInput(_)
            | Error::Set(_)
            | Error::File(_)
            | Error::Lock(_)
            | Error::Replay(_)
            | Error::Histogram(_)
            | Error::Axis(_)
            | Error::Input { .. }
            | Error::Report(tactile_report::Error::BadInput(_)) => EXIT_BAD_INPUT,
            Error::Interrupted
            | Error::Stopped(_)
            | Error::Report(tactile_report::Error::Stopped(_)) => EXIT_INTERRUPTED,
            Error::Report(_) => EXIT_FAILURE,
            Error::Io { .. } | Error::Failed(_) => EXIT_FAILURE,
        }
    }

    /// Wraps an I/O error with what was being done.
    pub fn io(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> Error {
        let context = context.into();
        move |source| Error::Io { context, source }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// A scenario's bad input keeps its cause under the scenario's name, and is exit 2.
    #[test]
    fn an_input_error_keeps_its_cause() {
        let set = tactile_scenario::overrides::Set::parse("rate_hz.x=1").expect("a set");
        let cause = tactile_scenario::overrides::apply("rate_hz = 1.0\n", &[set])
            .expect_err("rate_hz is no table");
        let e = Error::Input {
            name: "s.toml".into(),
            source: Box::new(cause.into()),
        };
        assert_eq!(e.exit_code(), EXIT_BAD_INPUT);
        assert!(
            e.to_string().starts_with("s.toml: --set rate_hz.x=1: "),
            "{e}"
        );
        let input = e.source().expect("the input's error");
        assert!(
            input.to_string().starts_with("--set rate_hz.x=1: "),
            "{input}"
        );
        // InputError::Set is transparent: the set's own cause is next.
        let problem = input.source().expect("the set's problem");
        assert!(
            problem.is::<tactile_scenario::overrides::Problem>(),
            "{problem:?}"
        );
    }
}
