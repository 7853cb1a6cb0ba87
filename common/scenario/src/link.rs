//! `link = { ... }` in `[network.forward]` / `[network.backward]`: a link with a rate
//! and a queue, `mm-link`'s (Mahimahi) meanings and names. Its behaviour is
//! `tactile-netem`'s `link`; its settings and ranges are here.

use crate::aqm::{
    validate_classes, CodelConfig, FqCodelConfig, PieConfig, PriorityConfig, WeightedConfig,
};
use crate::shown::Num;
use crate::{invalid, ScenarioError};
use serde::{Deserialize, Serialize};

/// The Mahimahi traces shipped in `deploy/networks/` (`ravinet/mahimahi`'s
/// `traces/`, unmodified): a scenario names one by its file name in lower case, the
/// dot a dash (`Verizon-LTE-short.up` is `verizon-lte-short-up`).
pub const SHIPPED_TRACES: [&str; 8] = [
    "Verizon-LTE-short.up",
    "Verizon-LTE-short.down",
    "TMobile-LTE-short.up",
    "TMobile-LTE-short.down",
    "TMobile-UMTS-driving.up",
    "TMobile-UMTS-driving.down",
    "ATT-LTE-driving-2016.up",
    "ATT-LTE-driving-2016.down",
];

/// Where a scenario finds the shipped traces, relative to its own folder (the
/// repository's `deploy/scenarios/` beside `deploy/networks/`, the Python package's
/// `tactile/scenarios/` beside `tactile/networks/`), as it finds `../robots/`.
pub const NETWORKS_DIR: &str = "../networks";

/// Largest packet on a Mahimahi link, bytes: mm-link's `PACKET_SIZE` (it refuses a
/// larger one).
pub const MAX_TRACE_PACKET_BYTES: u32 = 1504;
/// Largest packet on a fixed-rate link, bytes (an IPv4 datagram's limit).
pub const MAX_PACKET_BYTES: u32 = 65_535;
/// Most packets a queue bound may name: the link's memory cap, which holds whatever
/// the discipline (`tactile-netem`'s `MAX_QUEUE_PACKETS`).
pub const MAX_QUEUE_PACKETS: u32 = 100_000;
/// Highest fixed rate, bit/s (1 Tbit/s).
pub const MAX_RATE: f64 = 1e12;

/// The queue discipline: mm-link's `--uplink-queue`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum QueueKind {
    /// Takes every packet (mm-link's default); bounded only by the memory cap.
    #[default]
    Infinite,
    /// Refuses an arrival that would break the bound.
    Droptail,
    /// Takes every arrival, then drops from the head until the bound holds.
    Drophead,
    /// CoDel (RFC 8289), `codel = { ... }`; `packets`/`bytes` bound it if given.
    Codel,
    /// FQ-CoDel (RFC 8290), `fq_codel = { ... }` (its own `limit`).
    #[serde(rename = "fq_codel")]
    FqCodel,
    /// PIE (RFC 8033), `pie = { ... }`; `packets`/`bytes` bound it if given.
    Pie,
    /// Strict priority between classes, `priority = { classes = [...] }`.
    Priority,
    /// Weighted classes (deficit round robin), `weighted = { quantum, classes }`.
    Weighted,
}

impl QueueKind {
    /// Its name in a scenario.
    pub fn name(self) -> &'static str {
        match self {
            QueueKind::Infinite => "infinite",
            QueueKind::Droptail => "droptail",
            QueueKind::Drophead => "drophead",
            QueueKind::Codel => "codel",
            QueueKind::FqCodel => "fq_codel",
            QueueKind::Pie => "pie",
            QueueKind::Priority => "priority",
            QueueKind::Weighted => "weighted",
        }
    }
}

/// `link = { trace | path | rate | rate_trace, queue, packets, bytes, header_bytes, payload_bytes }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkConfig {
    /// A shipped Mahimahi trace by name ([`SHIPPED_TRACES`]); read from
    /// [`NETWORKS_DIR`] (the scenario as read holds it as `path`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trace: Option<String>,
    /// A Mahimahi trace file, relative to the scenario's folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    /// A fixed rate instead of a trace, bit/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
    /// A rate over time instead: a CSV `time_ms,rate_bps` (each rate from its time to
    /// the next row's, the last on for good), relative to the scenario's folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_trace: Option<String>,
    /// `infinite`, `droptail` or `drophead` [infinite], mm-link's `--uplink-queue`.
    #[serde(default)]
    pub queue: QueueKind,
    /// A bound in packets, mm-link's `--uplink-queue-args=packets=N`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub packets: Option<u32>,
    /// A bound in bytes, mm-link's `bytes=N`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<u64>,
    /// Headers each packet carries on the wire beside its payload, bytes [28: IPv4's
    /// 20 and UDP's 8; 48 for UDP/IPv6, 0 for the payload alone].
    #[serde(default = "default_header")]
    pub header_bytes: u32,
    /// Each sample's payload, bytes [250: about a Tactile frame].
    #[serde(default = "default_payload")]
    pub payload_bytes: u32,
    /// CoDel's parameters (`queue = "codel"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub codel: Option<CodelConfig>,
    /// FQ-CoDel's (`queue = "fq_codel"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fq_codel: Option<FqCodelConfig>,
    /// PIE's (`queue = "pie"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pie: Option<PieConfig>,
    /// Strict priority's classes (`queue = "priority"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub priority: Option<PriorityConfig>,
    /// Weighted classes (`queue = "weighted"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weighted: Option<WeightedConfig>,
}

fn default_header() -> u32 {
    28
}
fn default_payload() -> u32 {
    250
}

impl LinkConfig {
    /// A link over the Mahimahi trace at `path`, its other settings mm-link's defaults
    /// (what `replay = { path, format = "mahimahi" }` means).
    pub fn mahimahi(path: &str) -> LinkConfig {
        LinkConfig {
            trace: None,
            path: Some(path.to_string()),
            rate: None,
            rate_trace: None,
            queue: QueueKind::Infinite,
            packets: None,
            bytes: None,
            header_bytes: default_header(),
            payload_bytes: default_payload(),
            codel: None,
            fq_codel: None,
            pie: None,
            priority: None,
            weighted: None,
        }
    }

    /// A packet's size on the wire, bytes.
    pub fn packet_bytes(&self) -> u64 {
        u64::from(self.payload_bytes) + u64::from(self.header_bytes)
    }

    /// The file of a shipped trace's name, if it is one.
    pub fn shipped(name: &str) -> Option<&'static str> {
        SHIPPED_TRACES
            .iter()
            .find(|f| f.to_lowercase().replace('.', "-") == name)
            .copied()
    }

    /// A named trace as the path it is read from ([`NETWORKS_DIR`]), so the run
    /// copies the file into its inputs as it does every file a scenario reads.
    pub(crate) fn name_to_path(&mut self) {
        if let Some(file) = self.trace.as_deref().and_then(LinkConfig::shipped) {
            self.path = Some(format!("{NETWORKS_DIR}/{file}"));
            self.trace = None;
        }
    }

    /// Checks the fields; errors name `FIELD.link.*`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        let f = |k: &str| format!("{field}.link.{k}");
        self.validate_server(field)?;
        let most = if self.rate.is_some() || self.rate_trace.is_some() {
            MAX_PACKET_BYTES
        } else {
            MAX_TRACE_PACKET_BYTES
        };
        if self.payload_bytes == 0 {
            return Err(invalid(
                f("payload_bytes"),
                "0: a packet carries its sample",
            ));
        }
        if self.packet_bytes() > u64::from(most) {
            return Err(invalid(
                f("payload_bytes"),
                format!(
                    "{} + header_bytes {} = {} bytes on the wire exceeds {most} (the largest packet this link carries)",
                    self.payload_bytes,
                    self.header_bytes,
                    self.packet_bytes()
                ),
            ));
        }
        self.validate_bound(field)?;
        self.validate_discipline(field)
    }

    /// A discipline's table only beside its `queue`, each in range; `priority` and
    /// `weighted` need theirs (their classes).
    fn validate_discipline(&self, field: &str) -> Result<(), ScenarioError> {
        let f = |k: &str| format!("{field}.link.{k}");
        let given = [
            (QueueKind::Codel, self.codel.is_some()),
            (QueueKind::FqCodel, self.fq_codel.is_some()),
            (QueueKind::Pie, self.pie.is_some()),
            (QueueKind::Priority, self.priority.is_some()),
            (QueueKind::Weighted, self.weighted.is_some()),
        ];
        for (kind, is) in given {
            if is && kind != self.queue {
                return Err(invalid(
                    f(kind.name()),
                    format!(
                        "sets queue \"{}\"; queue is \"{}\"",
                        kind.name(),
                        self.queue.name()
                    ),
                ));
            }
        }
        if let Some(c) = &self.codel {
            c.validate(&f("codel"))?;
        }
        if let Some(c) = &self.fq_codel {
            c.validate(&f("fq_codel"), MAX_QUEUE_PACKETS)?;
        }
        if let Some(c) = &self.pie {
            c.validate(&f("pie"))?;
        }
        match (self.queue, &self.priority, &self.weighted) {
            (QueueKind::Priority, None, _) | (QueueKind::Weighted, _, None) => Err(invalid(
                f(self.queue.name()),
                "is missing: give its classes, e.g. { classes = [{ flows = [0] }, { flows = [] }] }",
            )),
            (QueueKind::Priority, Some(p), _) => {
                validate_classes(
                    &f("priority"),
                    &p.classes,
                    false,
                    MAX_QUEUE_PACKETS,
                    self.packet_bytes(),
                )
            }
            (QueueKind::Weighted, _, Some(w)) => {
                if w.quantum == 0 || w.quantum > 65_535 {
                    return Err(invalid(
                        f("weighted.quantum"),
                        format!("{} is outside 1..=65535", w.quantum),
                    ));
                }
                validate_classes(
                    &f("weighted"),
                    &w.classes,
                    true,
                    MAX_QUEUE_PACKETS,
                    self.packet_bytes(),
                )
            }
            _ => Ok(()),
        }
    }

    /// Exactly one of `trace`, `path` and `rate`, each in range.
    fn validate_server(&self, field: &str) -> Result<(), ScenarioError> {
        let given = [
            self.trace.is_some(),
            self.path.is_some(),
            self.rate.is_some(),
            self.rate_trace.is_some(),
        ];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(invalid(
                format!("{field}.link"),
                "give exactly one of trace (a shipped trace's name), path (a Mahimahi trace file), rate (bit/s) or rate_trace (a file of time_ms,rate_bps)",
            ));
        }
        if let Some(name) = &self.trace {
            if LinkConfig::shipped(name).is_none() {
                let names: Vec<String> = SHIPPED_TRACES
                    .iter()
                    .map(|f| f.to_lowercase().replace('.', "-"))
                    .collect();
                return Err(invalid(
                    format!("{field}.link.trace"),
                    format!(
                        "{name:?} is no shipped trace; they are {}",
                        names.join(", ")
                    ),
                ));
            }
        }
        for (key, file) in [("path", &self.path), ("rate_trace", &self.rate_trace)] {
            if file.as_ref().is_some_and(String::is_empty) {
                return Err(invalid(format!("{field}.link.{key}"), "is empty"));
            }
        }
        if let Some(r) = self.rate {
            if !r.is_finite() || !(1.0..=MAX_RATE).contains(&r) {
                return Err(invalid(
                    format!("{field}.link.rate"),
                    format!("{} bit/s is outside 1..={}", Num(r), Num(MAX_RATE)),
                ));
            }
        }
        Ok(())
    }

    /// mm-link's queue arguments: none for `infinite`, `packets` and/or `bytes` for
    /// the others, each positive (mm-link reads 0 as no bound; here it is refused).
    fn validate_bound(&self, field: &str) -> Result<(), ScenarioError> {
        let f = |k: &str| format!("{field}.link.{k}");
        if let Some(p) = self.packets {
            if p == 0 || p > MAX_QUEUE_PACKETS {
                return Err(invalid(
                    f("packets"),
                    format!("{p} is outside 1..={MAX_QUEUE_PACKETS} (the link's memory cap)"),
                ));
            }
        }
        if let Some(b) = self.bytes {
            if b < self.packet_bytes() {
                return Err(invalid(
                    f("bytes"),
                    format!(
                        "{b} holds no packet of {} bytes (payload_bytes + header_bytes)",
                        self.packet_bytes()
                    ),
                ));
            }
        }
        let bounded = self.packets.is_some() || self.bytes.is_some();
        let which = if self.packets.is_some() {
            "packets"
        } else {
            "bytes"
        };
        match self.queue {
            QueueKind::FqCodel | QueueKind::Priority | QueueKind::Weighted if bounded => {
                Err(invalid(
                    f(which),
                    format!(
                        "bounds a single queue; queue \"{}\" bounds its own (fq_codel.limit, or each class's packets and bytes)",
                        self.queue.name()
                    ),
                ))
            }
            QueueKind::Infinite if bounded => Err(invalid(
                f(which),
                "bounds a queue \"droptail\", \"drophead\", \"codel\" or \"pie\"; queue is \"infinite\"",
            )),
            QueueKind::Droptail | QueueKind::Drophead if !bounded => Err(invalid(
                f("queue"),
                "a dropping queue needs a bound: packets, bytes or both",
            )),
            _ => Ok(()),
        }
    }
}
