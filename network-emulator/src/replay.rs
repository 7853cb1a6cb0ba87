//! Loading the recorded networks a scenario replays (the edge: files are read here,
//! checked, and handed to the pure channel).

use std::path::{Path, PathBuf};
use tactile_netem::{LinkSpec, Replay, ReplayError};
use tactile_scenario::{ChannelConfig, LinkConfig, Scenario};
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

/// The forward and backward replays and links of `scenario`, paths relative to
/// `base_dir`; the error names the field and the file.
pub fn load(scenario: &Scenario, base_dir: &Path) -> Result<[Option<Replay>; 2], LoadError> {
    let one = |dir: usize, c: &ChannelConfig| -> Result<Option<Replay>, LoadError> {
        if let Some(l) = &c.link {
            return link(FIELDS[dir][1], l, base_dir).map(Some);
        }
        c.replay
            .as_ref()
            .map(|r| read(FIELDS[dir][0], r, base_dir))
            .transpose()
    };
    Ok([
        one(0, &scenario.network.forward)?,
        one(1, &scenario.network.backward)?,
    ])
}

/// The fields a loading error names, per direction: the replay's and the link's.
const FIELDS: [[&str; 2]; 2] = [
    ["network.forward.replay", "network.forward.link"],
    ["network.backward.replay", "network.backward.link"],
];

/// A link: its trace read (a shipped one is a path by now, the scenario's reading
/// made it one), or its rate.
fn link(field: &'static str, cfg: &LinkConfig, base_dir: &Path) -> Result<Replay, LoadError> {
    if let Some(spec) = LinkSpec::of_rate(cfg) {
        return Ok(Replay::Link(spec));
    }
    if let Some(file) = &cfg.rate_trace {
        let path = base_dir.join(file);
        let text = tactile_runtime::files::read_text(&path, "rate trace", MAX_TRACE_BYTES)
            .map_err(|source| LoadError::Read { field, source })?;
        return LinkSpec::parse_rates(&text, cfg)
            .map(Replay::Link)
            .map_err(|source| LoadError::Parse {
                field,
                path,
                source,
            });
    }
    let file = match (&cfg.path, &cfg.trace) {
        (Some(p), _) => p.clone(),
        (None, Some(name)) => LinkConfig::shipped(name)
            .map(|f| format!("{}/{f}", tactile_scenario::NETWORKS_DIR))
            .unwrap_or_else(|| name.clone()),
        (None, None) => String::new(),
    };
    let path = base_dir.join(file);
    let text = tactile_runtime::files::read_text(&path, "trace", MAX_TRACE_BYTES)
        .map_err(|source| LoadError::Read { field, source })?;
    Replay::parse_mahimahi(&text, cfg).map_err(|source| LoadError::Parse {
        field,
        path,
        source,
    })
}

/// Largest Mahimahi trace accepted, bytes: [`tactile_netem::link::MAX_OPPORTUNITIES`]
/// lines of up to 9 digits (the largest shipped is 1.2 MB, Mahimahi's largest 3.4
/// MB). A trace of 10^8 lines, at least 2 bytes each, is refused by its size before
/// it is read.
pub const MAX_TRACE_BYTES: u64 = 100 << 20;

fn read(field: &'static str, cfg: &ReplayConfig, base_dir: &Path) -> Result<Replay, LoadError> {
    let path = base_dir.join(&cfg.path);
    let most = match cfg.format {
        ReplayFormat::Csv => MAX_REPLAY_BYTES,
        ReplayFormat::Mahimahi => MAX_TRACE_BYTES,
    };
    let text = tactile_runtime::files::read_text(&path, "replay", most)
        .map_err(|source| LoadError::Read { field, source })?;
    let parsed = match cfg.format {
        ReplayFormat::Csv => Replay::parse_csv(&text),
        // mm-link with its defaults: an infinite queue, packets of 250 + 28 bytes.
        ReplayFormat::Mahimahi => Replay::parse_mahimahi(&text, &LinkConfig::mahimahi(&cfg.path)),
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
