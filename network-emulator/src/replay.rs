//! Loading the recorded networks a scenario replays (the edge: files are read here,
//! checked, and handed to the pure channel).

use std::path::Path;
use tactile_netem::Replay;
use tactile_scenario::{ChannelConfig, Scenario};
use tactile_scenario::{ReplayConfig, ReplayFormat};

/// Largest replay file accepted, bytes (a line per packet: hours at 1 kHz).
pub const MAX_REPLAY_BYTES: u64 = 256 << 20;

/// The forward and backward replays of `scenario`, paths relative to `base_dir`; the
/// error names the field and the file.
pub fn load(scenario: &Scenario, base_dir: &Path) -> Result<[Option<Replay>; 2], String> {
    let one = |field: &str, c: &ChannelConfig| -> Result<Option<Replay>, String> {
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

fn read(field: &str, cfg: &ReplayConfig, base_dir: &Path) -> Result<Replay, String> {
    let path = base_dir.join(&cfg.path);
    let shown = path.display().to_string();
    let text = tactile_runtime::files::read_text(&path, "replay", MAX_REPLAY_BYTES)
        .map_err(|e| format!("{field}: {e}"))?;
    let parsed = match cfg.format {
        ReplayFormat::Csv => Replay::parse_csv(&text),
        ReplayFormat::Mahimahi => Replay::parse_mahimahi(&text, cfg),
    };
    parsed.map_err(|e| format!("{field}: {shown}: {e}"))
}
