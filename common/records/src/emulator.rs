//! The emulator's record: one schema for what it did to each sample it passed, and
//! what it counted. The report joins it with the master's and the slave's records by
//! sample number.

use serde::{Deserialize, Serialize};
use tactile_messages::samples::Signal;
use tactile_messages::stream::{InboxStats, OutboxStats};

/// What the emulator counted over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EmulatorCounters {
    /// Forward samples passed.
    pub forward: u64,
    /// Backward samples passed.
    pub backward: u64,
    /// Forward samples with no new packet: the last value (or, before the first
    /// arrival, the first value sent) passed again, flagged.
    pub forward_substituted: u64,
    /// Backward samples with a value substituted.
    pub backward_substituted: u64,
    /// Forward samples dropped on purpose (loss model).
    pub forward_dropped: u64,
    /// Backward samples dropped on purpose.
    pub backward_dropped: u64,
    /// Forward samples corrupted to NaN on purpose (fault injection).
    pub forward_corrupted: u64,
    /// Backward samples corrupted to NaN on purpose.
    pub backward_corrupted: u64,
    /// Forward packets the network lost (a loss model or a replay): no packet
    /// arrived for them, and the receiver filled the sample from what it had.
    pub forward_packets_lost: u64,
    /// Backward packets the network lost.
    pub backward_packets_lost: u64,
    /// Forward packets sent twice (netem's duplicate).
    pub forward_duplicated: u64,
    /// Backward packets sent twice.
    pub backward_duplicated: u64,
}

/// What the fault model decided for one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Fate {
    /// Passed on.
    Deliver,
    /// Passed on with its values replaced by NaN (fault injection).
    Corrupt,
    /// Dropped on purpose (loss model).
    Drop,
}

/// Which channel a sample crossed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Direction {
    /// Master to slave: c(n) in, v(n) out.
    Forward,
    /// Slave to master: h(n) in, q(n) out.
    Backward,
}

/// The emulator's record of one sample it passed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Passage {
    /// Which channel.
    pub dir: Direction,
    /// Sample number.
    pub n: u64,
    /// The values that arrived.
    pub input: [f64; 3],
    /// What left (values, provenance, injected delay, flags); values as sent even when
    /// dropped.
    pub out: Signal,
    /// A 6-DoF sample's rotational half as it left (the orientation forward, the torque
    /// and a zero backward); `None` in a 3-DoF run.
    pub rotational: Option<[f64; 4]>,
    /// Noise added to each value.
    pub noise: [f64; 3],
    /// Jitter drawn for this packet, samples (zero without a jitter model).
    pub jitter: f64,
    /// True if the network lost this packet (a loss model or a replay).
    pub lost: bool,
    /// Delivered, corrupted or dropped.
    pub fate: Fate,
}

/// What the emulator's four stream ends counted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EmulatorStats {
    /// c(n) received.
    pub c_in: InboxStats,
    /// v(n) published.
    pub v_out: OutboxStats,
    /// h(n) received.
    pub h_in: InboxStats,
    /// q(n) published.
    pub q_out: OutboxStats,
}

/// The emulator's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EmulatorTotals {
    /// Channel counters (including drops and corruptions on purpose).
    pub counters: EmulatorCounters,
    /// What the four stream ends counted.
    pub links: EmulatorStats,
}

/// The emulator's record type.
pub type EmulatorRecord = crate::Record<Passage, EmulatorTotals>;
