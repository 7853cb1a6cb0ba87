//! The parameters of a link's queue disciplines beyond mm-link's FIFOs: `codel`,
//! `fq_codel`, `pie` (each with its RFC's defaults), and the classes of `priority` and
//! `weighted`. Their behaviour is `tactile-netem`'s `link`; their settings and ranges
//! are here.

use crate::{invalid, ScenarioError};
use serde::{Deserialize, Serialize};

/// Longest target, interval, update period or burst allowance, ms (a minute).
pub const MAX_AQM_MS: f64 = 60_000.0;
/// Highest flow id a class names (cross flows are numbered from 1).
pub const MAX_FLOW_ID: u32 = 65_535;
/// Most classes of a scheduler.
pub const MAX_CLASSES: usize = 16;

/// CoDel's arithmetic: RFC 8289's pseudo-code (ns, a square root), or Linux's and
/// ns-3's (1024 ns units, a Newton step a drop in fixed point): the same state
/// machine, drops a little apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum CodelArithmetic {
    /// RFC 8289's.
    #[default]
    Rfc,
    /// Linux's and ns-3's.
    Linux,
}

/// `codel = { target_ms, interval_ms, mtu_bytes, arithmetic }` (RFC 8289).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CodelConfig {
    /// Acceptable standing queueing delay, ms [5].
    #[serde(default = "codel_target")]
    pub target_ms: f64,
    /// Window the delay must stay above the target before a drop, ms [100].
    #[serde(default = "codel_interval")]
    pub interval_ms: f64,
    /// No drop while the queue holds at most this many bytes (the MTU) [1500].
    #[serde(default = "mtu")]
    pub mtu_bytes: u32,
    /// `rfc` or `linux` [rfc].
    #[serde(default)]
    pub arithmetic: CodelArithmetic,
}

/// `fq_codel = { target_ms, interval_ms, mtu_bytes, quantum, flows, limit, drop_batch }`
/// (RFC 8290).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FqCodelConfig {
    /// Each flow's CoDel target, ms [5].
    #[serde(default = "codel_target")]
    pub target_ms: f64,
    /// Each flow's CoDel interval, ms [100].
    #[serde(default = "codel_interval")]
    pub interval_ms: f64,
    /// Each flow's CoDel MTU, bytes [1500].
    #[serde(default = "mtu")]
    pub mtu_bytes: u32,
    /// Each flow's CoDel arithmetic, `rfc` or `linux` [rfc].
    #[serde(default)]
    pub arithmetic: CodelArithmetic,
    /// Bytes a flow sends each round [1514].
    #[serde(default = "quantum")]
    pub quantum: u32,
    /// Flow queues (a flow's is `flow % flows`) [1024].
    #[serde(default = "fq_flows")]
    pub flows: u32,
    /// Most packets held in all [10240].
    #[serde(default = "fq_limit")]
    pub limit: u32,
    /// Most packets dropped at once from the fattest flow at the limit [64].
    #[serde(default = "drop_batch")]
    pub drop_batch: u32,
}

/// `pie = { target_ms, tupdate_ms, alpha, beta, max_burst_ms, mean_packet_bytes }`
/// (RFC 8033).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PieConfig {
    /// Target queueing delay, ms [15].
    #[serde(default = "pie_ms")]
    pub target_ms: f64,
    /// Drop probability update period, ms [15].
    #[serde(default = "pie_ms")]
    pub tupdate_ms: f64,
    /// Weight of the delay's deviation from the target, 1/s [0.125].
    #[serde(default = "alpha")]
    pub alpha: f64,
    /// Weight of the delay's trend, 1/s [1.25].
    #[serde(default = "beta")]
    pub beta: f64,
    /// Burst allowance, ms [150].
    #[serde(default = "burst")]
    pub max_burst_ms: f64,
    /// No drop while the queue holds at most two of these, bytes [1000].
    #[serde(default = "mean_packet")]
    pub mean_packet_bytes: u32,
}

/// One class of `priority` or `weighted`: `{ flows = [0], packets, bytes, weight }`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassConfig {
    /// The flows it takes (0: the haptic flow); a flow no class names goes to the last.
    #[serde(default)]
    pub flows: Vec<u32>,
    /// Its bound in packets (drop-tail).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub packets: Option<u32>,
    /// Its bound in bytes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<u64>,
    /// Its share under `weighted` [1]; refused under `priority`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weight: Option<u32>,
}

/// `priority = { classes = [...] }`: the first class the highest.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PriorityConfig {
    /// The classes, highest first (1 to [`MAX_CLASSES`]).
    pub classes: Vec<ClassConfig>,
}

/// `weighted = { quantum, classes = [...] }`: deficit round robin by weight.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightedConfig {
    /// Bytes a class of weight 1 sends a round [1514].
    #[serde(default = "quantum")]
    pub quantum: u32,
    /// The classes (1 to [`MAX_CLASSES`]).
    pub classes: Vec<ClassConfig>,
}

fn codel_target() -> f64 {
    5.0
}
fn codel_interval() -> f64 {
    100.0
}
fn mtu() -> u32 {
    1500
}
fn quantum() -> u32 {
    1514
}
fn fq_flows() -> u32 {
    1024
}
fn fq_limit() -> u32 {
    10_240
}
fn drop_batch() -> u32 {
    64
}
fn pie_ms() -> f64 {
    15.0
}
fn alpha() -> f64 {
    0.125
}
fn beta() -> f64 {
    1.25
}
fn burst() -> f64 {
    150.0
}
fn mean_packet() -> u32 {
    1000
}

impl Default for CodelConfig {
    fn default() -> CodelConfig {
        CodelConfig {
            target_ms: codel_target(),
            interval_ms: codel_interval(),
            mtu_bytes: mtu(),
            arithmetic: CodelArithmetic::Rfc,
        }
    }
}

impl Default for FqCodelConfig {
    fn default() -> FqCodelConfig {
        FqCodelConfig {
            target_ms: codel_target(),
            interval_ms: codel_interval(),
            mtu_bytes: mtu(),
            arithmetic: CodelArithmetic::Rfc,
            quantum: quantum(),
            flows: fq_flows(),
            limit: fq_limit(),
            drop_batch: drop_batch(),
        }
    }
}

impl Default for PieConfig {
    fn default() -> PieConfig {
        PieConfig {
            target_ms: pie_ms(),
            tupdate_ms: pie_ms(),
            alpha: alpha(),
            beta: beta(),
            max_burst_ms: burst(),
            mean_packet_bytes: mean_packet(),
        }
    }
}

/// The shortest duration a discipline takes, ms (1 us): a shorter one rounds to
/// nothing in the link's nanoseconds.
const MIN_AQM_MS: f64 = 0.001;

/// PIE's shortest update period, ms: the link runs every update due, so a period of
/// nanoseconds would cost billions of them a simulated minute (the RFC's is 15 ms).
const MIN_TUPDATE_MS: f64 = 0.1;

/// A duration in ms: finite, at least [`MIN_AQM_MS`] (or 0 if `zero` may be), at most
/// a minute.
fn ms(field: String, v: f64, zero: bool) -> Result<(), ScenarioError> {
    let low_ok = v >= MIN_AQM_MS || (zero && v == 0.0);
    if !v.is_finite() || !low_ok || v > MAX_AQM_MS {
        let low = if zero { "0 or 0.001" } else { "0.001" };
        return Err(invalid(
            field,
            format!("{v} ms is outside {low}..={MAX_AQM_MS}"),
        ));
    }
    Ok(())
}

/// A count: 1 up to `max`.
fn count(field: String, v: u64, max: u64) -> Result<(), ScenarioError> {
    if v == 0 || v > max {
        return Err(invalid(field, format!("{v} is outside 1..={max}")));
    }
    Ok(())
}

impl CodelConfig {
    /// Checks the fields; errors name `FIELD.*` (`FIELD` is `…link.codel`).
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        ms(format!("{field}.target_ms"), self.target_ms, false)?;
        ms(format!("{field}.interval_ms"), self.interval_ms, false)?;
        count(format!("{field}.mtu_bytes"), self.mtu_bytes.into(), 65_535)
    }
}

impl FqCodelConfig {
    /// Checks the fields; errors name `FIELD.*`.
    pub fn validate(&self, field: &str, cap: u32) -> Result<(), ScenarioError> {
        ms(format!("{field}.target_ms"), self.target_ms, false)?;
        ms(format!("{field}.interval_ms"), self.interval_ms, false)?;
        count(format!("{field}.mtu_bytes"), self.mtu_bytes.into(), 65_535)?;
        count(format!("{field}.quantum"), self.quantum.into(), 65_535)?;
        count(format!("{field}.flows"), self.flows.into(), 65_536)?;
        count(format!("{field}.limit"), self.limit.into(), cap.into())?;
        count(
            format!("{field}.drop_batch"),
            self.drop_batch.into(),
            cap.into(),
        )
    }
}

impl PieConfig {
    /// Checks the fields; errors name `FIELD.*`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        ms(format!("{field}.target_ms"), self.target_ms, false)?;
        ms(format!("{field}.tupdate_ms"), self.tupdate_ms, false)?;
        if self.tupdate_ms < MIN_TUPDATE_MS {
            return Err(invalid(
                format!("{field}.tupdate_ms"),
                format!(
                    "{} ms is under {MIN_TUPDATE_MS} ms (every update is run: the RFC's is 15 ms)",
                    self.tupdate_ms
                ),
            ));
        }
        ms(format!("{field}.max_burst_ms"), self.max_burst_ms, true)?;
        for (k, v) in [("alpha", self.alpha), ("beta", self.beta)] {
            if !v.is_finite() || !(0.0..=100.0).contains(&v) {
                return Err(invalid(
                    format!("{field}.{k}"),
                    format!("{v} is outside 0..=100 (1/s)"),
                ));
            }
        }
        count(
            format!("{field}.mean_packet_bytes"),
            self.mean_packet_bytes.into(),
            65_535,
        )
    }
}

/// Checks a scheduler's classes; `weighted` says whether weights belong.
pub(crate) fn validate_classes(
    field: &str,
    classes: &[ClassConfig],
    weighted: bool,
    cap: u32,
    packet_bytes: u64,
) -> Result<(), ScenarioError> {
    if classes.is_empty() || classes.len() > MAX_CLASSES {
        return Err(invalid(
            format!("{field}.classes"),
            format!("{} classes; give 1 to {MAX_CLASSES}", classes.len()),
        ));
    }
    let mut seen = std::collections::BTreeSet::new();
    for (k, c) in classes.iter().enumerate() {
        let f = |key: &str| format!("{field}.classes[{k}].{key}");
        for &flow in &c.flows {
            if flow > MAX_FLOW_ID {
                return Err(invalid(
                    f("flows"),
                    format!("flow {flow} is outside 0..={MAX_FLOW_ID}"),
                ));
            }
            if !seen.insert(flow) {
                return Err(invalid(
                    f("flows"),
                    format!("flow {flow} is in two classes"),
                ));
            }
        }
        if let Some(p) = c.packets {
            count(f("packets"), p.into(), cap.into())?;
        }
        if let Some(b) = c.bytes.filter(|b| *b < packet_bytes) {
            return Err(invalid(
                f("bytes"),
                format!("{b} holds no packet of this link's {packet_bytes} bytes"),
            ));
        }
        match (weighted, c.weight) {
            (false, Some(_)) => {
                return Err(invalid(
                    f("weight"),
                    "strict priority has no weights (queue = \"weighted\" has)",
                ))
            }
            (true, Some(w)) => count(f("weight"), w.into(), 1_000)?,
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::Scenario;

    fn refused(link: &str) -> String {
        let toml = format!("[network.forward]\nlink = {link}\n");
        match Scenario::from_toml_str(&toml) {
            Ok(_) => panic!("accepted: {link}"),
            Err(e) => e.to_string(),
        }
    }

    /// Times that round to nothing, a PIE update period that would cost billions of
    /// updates, and a class that holds no packet are refused, naming the field.
    #[test]
    fn degenerate_times_and_bounds_are_refused() {
        for (link, field) in [
            (
                "{ rate = 1e7, queue = \"pie\", pie = { tupdate_ms = 0.01 } }",
                "pie.tupdate_ms",
            ),
            (
                "{ rate = 1e7, queue = \"codel\", codel = { target_ms = 1e-9 } }",
                "codel.target_ms",
            ),
            (
                "{ rate = 1e7, queue = \"priority\", priority = { classes = [{ flows = [0], bytes = 100 }] } }",
                "priority.classes[0].bytes",
            ),
        ] {
            let e = refused(link);
            assert!(e.contains(field), "{link}: {e}");
        }
        let ok = "[network.forward]\nlink = { rate = 1e7, queue = \"priority\", priority = { classes = [{ flows = [0], bytes = 278 }] } }\n";
        Scenario::from_toml_str(ok).expect("a class holding one packet");
    }
}
