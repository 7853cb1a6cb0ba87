//! Loading the recorded networks a scenario replays (the edge: files are read here,
//! checked, and handed to the pure channel).

use std::path::{Path, PathBuf};
use tactile_netem::{Replay, ReplayError};
use tactile_scenario::{ChannelConfig, Scenario};
use tactile_scenario::{ReplayConfig, ReplayFormat};

/// Largest replay file accepted, bytes (a line per packet: hours at 1 kHz).
pub const MAX_REPLAY_BYTES: u64 = 256 << 20;

/// A replay the scenario names that cannot be used; each message names the field and
/// the file.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file cannot be read.
    #[error("{field}: {source}")]
    Read {
        /// The scenario's field (`network.forward.replay`).
        field: &'static str,
        /// Why.
        source: tactile_runtime::files::FileError,
    },
    /// The file is read, but it is no replay.
    #[error("{field}: {}: {source}", path.display())]
    Parse {
        /// The scenario's field.
        field: &'static str,
        /// The file.
        path: PathBuf,
        /// What is wrong in it.
        source: ReplayError,
    },
}

/// The forward and backward replays of `scenario`, paths relative to `base_dir`; the
/// error names the field and the file.
pub fn load(scenario: &Scenario, base_dir: &Path) -> Result<[Option<Replay>; 2], LoadError> {
    let one = |field: &'static str, c: &ChannelConfig| -> Result<Option<Replay>, LoadError> {
        c.replay
            .as_ref()
            .map(|r| read(field, r, base_dir))
            .transpose()
    };
    Ok([
        one("network.forward.replay", &scenario.network.forward)?,
        one("network.backward.replay", &scenario.network.backward)?,
    ])
}

fn read(field: &'static str, cfg: &ReplayConfig, base_dir: &Path) -> Result<Replay, LoadError> {
    let path = base_dir.join(&cfg.path);
    let text = tactile_runtime::files::read_text(&path, "replay", MAX_REPLAY_BYTES)
        .map_err(|source| LoadError::Read { field, source })?;
    let parsed = match cfg.format {
        ReplayFormat::Csv => Replay::parse_csv(&text),
        ReplayFormat::Mahimahi => Replay::parse_mahimahi(&text, cfg),
    };
    parsed.map_err(|source| LoadError::Parse {
        field,
        path,
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    fn with_replay(path: &str) -> Scenario {
        let text = format!("[network.forward.replay]\npath = \"{path}\"\nformat = \"csv\"\n");
        Scenario::from_toml_str(&text).expect("a scenario with a replay")
    }

    /// A missing file and a bad one each keep their cause under the field's name.
    #[test]
    fn a_replay_error_keeps_its_cause() {
        let dir = tempfile::tempdir().expect("tmp");
        let e = load(&with_replay("gone.csv"), dir.path()).expect_err("missing");
        assert!(
            e.to_string()
                .starts_with("network.forward.replay: cannot read replay"),
            "{e}"
        );
        let file = e.source().expect("the file's error");
        assert!(file.source().is_some_and(|c| c.is::<std::io::Error>()));
        std::fs::write(dir.path().join("bad.csv"), "delay,lost\n1,2\n").expect("write");
        let e = load(&with_replay("bad.csv"), dir.path()).expect_err("bad");
        assert!(
            e.to_string()
                .ends_with("bad.csv: line 2: lost 2 is not 0 or 1"),
            "{e}"
        );
        assert_eq!(
            e.source().and_then(|c| c.downcast_ref::<ReplayError>()),
            Some(&ReplayError::Lost {
                line: 2,
                lost: "2".into()
            })
        );
    }
}
