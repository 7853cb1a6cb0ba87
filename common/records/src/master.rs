//! The master's record: one schema for what it sent, what came back and what it did.
//! The report joins these with the emulator's and the slave's records by sample number.

use crate::device::DeviceCounters;
use serde::{Deserialize, Serialize};
use tactile_math::hardware::Clocks;
use tactile_messages::samples::{stage, Flags, Signal};
use tactile_messages::stream::{InboxStats, OutboxStats};

/// What the master counted over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct MasterCounters {
    /// Forward samples produced.
    pub sent: u64,
    /// Forward samples the codec put on the network (the others went as clock only).
    pub packets_sent: u64,
    /// Backward samples used.
    pub received: u64,
    /// Operator targets outside the master's workspace (MD angles clamped).
    pub operator_clamped: u64,
    /// Backward samples not physically possible (not finite, too large, too fast,
    /// out of order), rejected and filled by the predictor.
    pub rejected: u64,
    /// Force components clamped to the device's force limit.
    pub force_clamps: u64,
    /// Joint torques clamped to the device's torque limit.
    pub torque_clamps: u64,
    /// Samples without an answer on which the last torque was held.
    pub held_samples: u64,
    /// Samples without an answer past the peer timeout: zero torque.
    pub peer_lost_samples: u64,
    /// Times the loop broke (a peer silent past the timeout).
    pub loop_breaks: u64,
    /// Times answers came back after a break.
    pub resumes: u64,
    /// `control.kind = "mmt"`: new environment models taken and rendered.
    pub models_received: u64,
    /// `control.kind = "mmt"`: new models refused (not a valid plane: corrupted, or
    /// a peer's garbage), each counted once.
    pub models_refused: u64,
    /// `arithmetic = "rtl"`: the clocks FK-HMD and KFF-HMD spent (zero otherwise).
    pub rtl: Clocks,
}

/// Sample n as it left the master.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Sent {
    /// Sample number.
    pub n: u64,
    /// The operator's target a(n), m.
    pub target: [f64; 3],
    /// Master joint angles b(n), rad.
    pub theta_md: [f64; 3],
    /// c(n), m.
    pub c: [f64; 3],
    /// The handle's true position (the device's joints, f64), m.
    pub handle: [f64; 3],
    /// The impedance hand's force on the handle, N (zero for the ideal hand).
    pub hand_force: [f64; 3],
    /// The sample's instant (its scheduled tick in realtime), ns.
    pub tick_ns: u64,
    /// When c(n) was published, ns.
    pub send_ns: u64,
    /// A 6-DoF operator's orientation c(n) carried, `[x, y, z, w]` (`None`: 3-DoF).
    pub rotation: Option<[f64; 4]>,
    /// The operator's clutch was released at this sample.
    pub released: bool,
}

/// What the master commanded for a sample, answered or not, and its passivity books
/// after it: the part an answer and a miss share.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Effect {
    /// KFF-HMD torques p(n), N m (held, or zero once the loop is broken, after a miss).
    pub tau: [f64; 3],
    /// The force the operator feels, N.
    pub felt: [f64; 3],
    /// The master's notes: clamped, rejected; held or peer lost after a miss.
    pub flags: Flags,
    /// The master's passivity observer per axis after this sample, J.
    pub observer: [f64; 3],
    /// Energy the master's port has put into the channel minus what it took out, all
    /// axes, J (its share of the channel's energy).
    pub port_net_j: f64,
    /// Energy the control dissipated this sample, J.
    pub dissipated_j: f64,
    /// `control.kind = "mmt"`: energy the rendered model's changes have added at the
    /// handle so far, J (zero with `control.mmt.update = "passive"`).
    pub model_injected_j: f64,
}

/// q(n) as it came back and the torques it produced.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Answer {
    /// The sample it answers.
    pub n: u64,
    /// q(n) as received.
    pub q: Signal,
    /// Every stage's stamp, ns.
    pub stamps: [u64; stage::COUNT],
    /// What the master commanded on it.
    pub effect: Effect,
    /// Round trip on the master's clock, ns.
    pub round_trip_ns: u64,
    /// Round trip minus injected delay, ns.
    pub overhead_ns: i64,
    /// True if it came after its deadline.
    pub late: bool,
}

/// Sample n had no answer by its deadline.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Miss {
    /// The sample.
    pub n: u64,
    /// What the master commanded instead.
    pub effect: Effect,
}

/// One entry per thing the master did with a sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum MasterSample {
    /// c(n) sent.
    Sent(Sent),
    /// q(n) came back.
    Answer(Answer),
    /// q(n) did not come by its deadline.
    Miss(Miss),
}

/// The master's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct MasterTotals {
    /// The state machine's counters.
    pub counters: MasterCounters,
    /// Answers not back by the next tick (realtime).
    pub deadline_misses: u64,
    /// Answers that came after their deadline.
    pub late: u64,
    /// Backward samples that answered nothing (a duplicate, a number never sent, or
    /// older than the late window).
    pub unexpected: u64,
    /// c(n) as published.
    pub c_out: OutboxStats,
    /// q(n) as received.
    pub q_in: InboxStats,
    /// From the first tick to now, ns.
    pub elapsed_ns: u64,
    /// A real device (`master.backend = "ros2"`): what it delivered and how the loop
    /// judged it; all zero with the simulated device.
    pub device: DeviceCounters,
}

/// The master's record type.
pub type MasterRecord = crate::Record<MasterSample, MasterTotals>;
