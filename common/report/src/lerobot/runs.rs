//! The runs an export takes, each checked before anything is written: a run's folder
//! (its records), or a sweep's folder (`sweep.json`), whose runs come in their
//! folders' order with the values the sweep gave them (`sweep.csv`'s row of the run).

use super::features::Layout;
use crate::arm_scene::ArmScene;
use crate::Error;
use std::path::{Path, PathBuf};
use tactile_scenario::Scenario;

/// One run to become an episode.
#[derive(Debug, Clone)]
pub struct Run {
    /// Its folder.
    pub dir: PathBuf,
    /// The scenario its records hold.
    pub scenario: Scenario,
    /// Its features' layout (the slave's joints).
    pub layout: Layout,
    /// The swept keys and the values this run had (empty for a lone run).
    pub swept: Swept,
    /// What the run was made under.
    pub meta: Meta,
}

/// The conditions a run was made under, and its task's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Meta {
    /// `control.kind`.
    pub control: String,
    /// `codec.forward.kind`.
    pub codec_forward: String,
    /// `codec.backward.kind`.
    pub codec_backward: String,
    /// The forward channel's constant delay (its largest axis), ms.
    pub delay_forward_ms: f64,
    /// The backward channel's, ms.
    pub delay_backward_ms: f64,
    /// `network.forward.loss`, 0 to 1.
    pub loss_forward: f64,
    /// `network.backward.loss`.
    pub loss_backward: f64,
    /// The task's success, where the run had a task (its `summary.json`).
    pub task_success: Option<bool>,
    /// The task's completion time, s, where it was completed.
    pub completion_s: Option<f64>,
}

/// The text at `path` of a TOML table (`control.kind`), or "".
fn text_at(v: &toml::Value, path: &str) -> String {
    let mut at = Some(v);
    for key in path.split('.') {
        at = at.and_then(|v| v.get(key));
    }
    at.and_then(toml::Value::as_str)
        .unwrap_or_default()
        .to_string()
}

impl Meta {
    fn of(scenario: &Scenario, dir: &Path) -> Meta {
        let v: toml::Value =
            toml::from_str(&scenario.to_toml()).unwrap_or(toml::Value::Boolean(false));
        let ms = |d: &[i64; 3]| d.iter().copied().max().unwrap_or(0) as f64 * scenario.t_s() * 1e3;
        let task = read_capped(&dir.join("summary.json"), MAX_JSON)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|s| s.get("task").cloned())
            .filter(|t| !t.is_null());
        let net = &scenario.network;
        Meta {
            control: text_at(&v, "control.kind"),
            codec_forward: text_at(&v, "codec.forward.kind"),
            codec_backward: text_at(&v, "codec.backward.kind"),
            delay_forward_ms: ms(&net.forward.delay),
            delay_backward_ms: ms(&net.backward.delay),
            loss_forward: net.forward.loss,
            loss_backward: net.backward.loss,
            task_success: task.as_ref().and_then(|t| t["success"].as_bool()),
            completion_s: task.as_ref().and_then(|t| t["completion_s"].as_f64()),
        }
    }
}

/// The slave's joint names: a URDF arm's, read where the scenario says or, a run
/// folder having moved, from the copy in its `inputs/`; None for the paper's arm.
fn joint_names(scenario: &Scenario, dir: &Path) -> Result<Option<Vec<String>>, Error> {
    let Some(arm) = &scenario.slave.arm else {
        return Ok(None);
    };
    let first = match ArmScene::of_scenario(scenario) {
        Ok(a) => return Ok(a.map(|a| a.names)),
        Err(e) => e,
    };
    let file = Path::new(&arm.urdf)
        .file_name()
        .map(|f| dir.join("inputs").join(f));
    if let Some(copy) = file.filter(|f| f.is_file()) {
        let mut moved = scenario.clone();
        if let Some(a) = moved.slave.arm.as_mut() {
            a.urdf = copy.display().to_string();
        }
        if let Ok(Some(a)) = ArmScene::of_scenario(&moved) {
            return Ok(Some(a.names));
        }
    }
    Err(Error::BadInput(format!(
        "{}: the slave arm's joint names are not known: {first}",
        dir.display()
    )))
}

/// A run's folder, checked: its records' scenario and its arm.
fn run(dir: &Path, swept: Swept) -> Result<Run, Error> {
    let (_, scenario) = crate::write::recorded(&[dir.to_path_buf()], &|| false)?;
    let layout = Layout::new(joint_names(&scenario, dir)?);
    let meta = Meta::of(&scenario, dir);
    Ok(Run {
        dir: dir.to_path_buf(),
        scenario,
        layout,
        swept,
        meta,
    })
}

/// Swept keys and their values, as text.
type Swept = Vec<(String, String)>;

/// A CSV line's fields (a quoted field may hold commas and doubled quotes).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// The largest `summary.json` or `sweep.json` read, bytes (a run's is a few kB).
const MAX_JSON: u64 = 16 << 20;

/// The largest `sweep.csv` read, bytes (100,000 runs of a kilobyte's row fit).
const MAX_SWEEP_CSV: u64 = 256 << 20;

/// `path` as text, refused past `max` bytes: a folder's files are read whole, and a
/// stray huge file must not take the memory.
fn read_capped(path: &Path, max: u64) -> std::io::Result<String> {
    use std::io::Read;
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(max + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > max {
        return Err(std::io::Error::other(format!("larger than {max} bytes")));
    }
    Ok(text)
}

/// A sweep's runs as its `sweep.csv` lists them, in order: each run's folder name with
/// the swept keys' values its row gives (and its seed).
fn sweep_table(dir: &Path) -> Result<Vec<(String, Swept)>, Error> {
    let bad = |what: String| Error::BadInput(format!("{}: {what}", dir.display()));
    let spec: serde_json::Value = read_capped(&dir.join("sweep.json"), MAX_JSON)
        .map_err(|e| bad(format!("sweep.json: {e}")))
        .and_then(|t| serde_json::from_str(&t).map_err(|e| bad(format!("sweep.json: {e}"))))?;
    let mut keys: Vec<String> = spec["sets"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|s| s.as_str()?.split('=').next())
        .map(|k| k.trim().trim_start_matches('+').to_string())
        .collect();
    keys.push("seed".into());
    let table = read_capped(&dir.join("sweep.csv"), MAX_SWEEP_CSV).map_err(|e| {
        bad(format!(
            "sweep.csv: {e} (a sweep's table is written when it ends)"
        ))
    })?;
    let mut lines = table.lines();
    let header = fields(lines.next().unwrap_or_default());
    let at = |k: &str| header.iter().position(|h| h == k);
    let run_col = at("run").ok_or_else(|| bad("sweep.csv has no run column".into()))?;
    let mut runs = Vec::new();
    for row in lines.map(fields) {
        let name = row.get(run_col).cloned().unwrap_or_default();
        if name.is_empty() || name.contains('/') || name.starts_with('.') {
            return Err(bad(format!("sweep.csv names a run {name:?}")));
        }
        let swept = keys
            .iter()
            .filter_map(|k| Some((k.clone(), row.get(at(k)?)?.clone())))
            .collect();
        runs.push((name, swept));
    }
    if runs.is_empty() {
        return Err(bad("sweep.csv lists no run".into()));
    }
    Ok(runs)
}

/// A sweep's runs, in its table's order, each with its swept values.
fn sweep(dir: &Path) -> Result<Vec<Run>, Error> {
    sweep_table(dir)?
        .into_iter()
        .map(|(name, swept)| run(&dir.join(name), swept))
        .collect()
}

/// A run's folder given alone: a sweep's run (its parent a sweep's folder whose table
/// lists it) keeps the values the sweep gave it.
fn lone(dir: &Path) -> Result<Run, Error> {
    let parent = dir.parent().filter(|p| p.join("sweep.json").is_file());
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned());
    let swept = match (parent, name) {
        (Some(p), Some(name)) => sweep_table(p)
            .ok()
            .and_then(|t| t.into_iter().find(|(n, _)| *n == name))
            .map(|(_, s)| s)
            .unwrap_or_default(),
        _ => Vec::new(),
    };
    run(dir, swept)
}

/// The runs of `inputs` (run folders and sweep folders), all checked, all of one arm.
pub fn gather(inputs: &[PathBuf]) -> Result<Vec<Run>, Error> {
    let mut runs = Vec::new();
    for dir in inputs {
        if dir.join("sweep.json").is_file() {
            runs.extend(sweep(dir)?);
        } else {
            runs.push(lone(dir)?);
        }
    }
    if let Some(first) = runs.first() {
        if let Some(other) = runs.iter().find(|r| r.layout != first.layout) {
            return Err(Error::BadInput(format!(
                "{} and {}: slaves of different joints ({:?} and {:?}): one dataset has one arm",
                first.dir.display(),
                other.dir.display(),
                first.layout.joints,
                other.layout.joints
            )));
        }
    }
    Ok(runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quoted_field_keeps_its_commas() {
        assert_eq!(
            fields(r#"run-0000,"[0,0,0]","a""b",1"#),
            ["run-0000", "[0,0,0]", "a\"b", "1"]
        );
    }
}
