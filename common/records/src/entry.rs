//! Each node's own record: what it received, computed and commanded, its events and its
//! counters, written as the run goes.
//!
//! One file per node (`master.rec`, `emulator.rec`, `slave.rec`) of checked frames
//! ([`crate::frames`]), one record each. A node restarted into the same run appends a
//! new segment (a new `Start`) to its file. The report reads the files back and joins
//! them by sample number.

use serde::{Deserialize, Serialize};

/// One entry of a node's record. `S` is the node's per-sample record, `C` its counters.
// A record lives for one write or one read; boxing `Start` would allocate for nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Record<S, C> {
    /// A node started (a file holds one segment per start).
    Start(Start),
    /// The run this node joined: the token the master chose.
    Run(u64),
    /// One sample received, computed and commanded.
    Sample(S),
    /// Something that happened (peers found, break, resume, clamps, stop).
    Event(Event),
    /// Counters so far: written every second and at the end.
    Counters(Totals<C>),
    /// The node ended normally; nothing follows in this segment.
    Stop(Stop),
    /// Samples stored together as columns ([`crate::block`]): how a writer stores
    /// them; a reader hands them out one by one as [`Record::Sample`].
    Samples(SampleBlock),
}

/// Consecutive samples of one record, packed ([`crate::block::pack`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleBlock {
    /// Samples in the block.
    pub samples: u32,
    /// Length of the planes before LZ4, bytes.
    pub raw_len: u32,
    /// The packed planes.
    pub packed: Packed,
}

/// Bytes stored as one string (serde's bytes), not as a sequence of numbers.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Packed(pub Vec<u8>);

impl Serialize for Packed {
    fn serialize<Z: serde::Serializer>(&self, s: Z) -> Result<Z::Ok, Z::Error> {
        s.serialize_bytes(&self.0)
    }
}

impl<'de> Deserialize<'de> for Packed {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Bytes;
        impl serde::de::Visitor<'_> for Bytes {
            type Value = Packed;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("bytes")
            }
            fn visit_bytes<E: serde::de::Error>(self, v: &[u8]) -> Result<Packed, E> {
                Ok(Packed(v.to_vec()))
            }
            fn visit_byte_buf<E: serde::de::Error>(self, v: Vec<u8>) -> Result<Packed, E> {
                Ok(Packed(v))
            }
        }
        d.deserialize_byte_buf(Bytes)
    }
}

/// A record of any role read for its role-independent entries (`Start`, `Run`): the
/// samples' and counters' bodies are not decoded, so such a frame counts as damage.
pub type AnyRecord = Record<serde::de::IgnoredAny, serde::de::IgnoredAny>;

/// How a node started.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Start {
    /// `master`, `emulator` or `slave`.
    pub role: String,
    /// Version of the program.
    pub version: String,
    /// Process id.
    pub pid: u32,
    /// Host name.
    pub host: String,
    /// The clock domain: nodes with the same one share CLOCK_MONOTONIC (the kernel's
    /// boot id; `TACTILE_CLOCK_DOMAIN` overrides it), so a stage between their stamps is
    /// a true time; between two domains only an estimate is possible.
    pub clock: String,
    /// iceoryx2 prefix (or the link's name of the run).
    pub prefix: String,
    /// The link in use.
    pub link: String,
    /// Scenario name.
    pub scenario: String,
    /// The scenario as run, TOML, relative paths made absolute: the report reads the
    /// run's settings from here, and writes it out as `scenario.toml`.
    pub scenario_toml: String,
    /// Samples the scenario asks for.
    pub samples: u64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Scheduling: policy, priority, CPU, wake-up margin and poll budget.
    pub sched: Sched,
    /// Wall-clock time of the start, ms since the Unix epoch.
    pub unix_ms: u64,
    /// CLOCK_MONOTONIC at the start, ns.
    pub mono_ns: u64,
}

/// Something that happened to a node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Sample number when it happened.
    pub sample: u64,
    /// CLOCK_MONOTONIC, ns.
    pub mono_ns: u64,
    /// What happened.
    pub what: String,
}

/// A node's counters with its memory use.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Totals<C> {
    /// The node's own counters.
    pub counters: C,
    /// Peak resident set size so far, kB (getrusage's `ru_maxrss`).
    pub peak_rss_kb: u64,
}

/// How a node ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stop {
    /// `completed`, `interrupted`, or the failure.
    pub reason: String,
    /// CLOCK_MONOTONIC at the end, ns.
    pub mono_ns: u64,
}

/// What a node runs with, recorded in its record's start and in the run's summary.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Sched {
    /// `SCHED_FIFO` or `SCHED_OTHER`.
    pub policy: String,
    /// SCHED_FIFO priority (0 under SCHED_OTHER).
    pub priority: u8,
    /// CPU the node is pinned to, if any.
    pub cpu: Option<usize>,
    /// How long before a sample is due the node stops sleeping, us (0: it never
    /// sleeps, as in lockstep).
    pub wake_early_us: u64,
    /// How long it polls before it blocks, us.
    pub poll_us: u64,
    /// Memory locked (mlockall, pages locked as they are touched).
    pub memory_locked: bool,
    /// The node's CPUs kept busy while it sleeps.
    pub idle_poll: bool,
    /// Why the node does not run as asked, if it does not.
    pub note: Option<String>,
}
