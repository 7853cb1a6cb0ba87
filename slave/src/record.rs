//! The slave's record: one schema for what it received, computed and commanded. The
//! report joins it with the master's and the emulator's records by sample number.

use crate::hsd::SlaveCounters;
use serde::{Deserialize, Serialize};
use tactile_common::samples::Signal;
use tactile_node::ipc::{InboxStats, OutboxStats};

/// One step on a received v(n).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Step {
    /// Sample number of v(n).
    pub n: u64,
    /// v(n) as received (values, provenance, injected delay, flags).
    pub received: Signal,
    /// IK-HSD reference angles, rad.
    pub theta_ref: [f64; 3],
    /// Joint angles after the step, rad.
    pub theta: [f64; 3],
    /// Controller torques after clamping, N m.
    pub torque: [f64; 3],
    /// FK-HSD tool position l(n), m.
    pub tool: [f64; 3],
    /// Nearest surface point s^OBJ(n), m (zero without contact).
    pub surface: [f64; 3],
    /// h(n) before the backward channel, N.
    pub force: [f64; 3],
    /// Torque clamps this step.
    pub clamps: u32,
    /// Object index in contact, or u32::MAX.
    pub contact_object: u32,
    /// `FLAG_*` bits of h(n).
    pub flags: u32,
}

/// One step of holding position while the input is silent.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct HoldStep {
    /// Held steps so far in the run.
    pub step: u64,
    /// Angles held, rad.
    pub theta_ref: [f64; 3],
    /// Joint angles after the step, rad.
    pub theta: [f64; 3],
    /// Controller torques, N m.
    pub torque: [f64; 3],
    /// Tool position (true device), m.
    pub tool: [f64; 3],
}

/// One entry per step the slave took.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum SlaveSample {
    /// A step on v(n).
    Step(Step),
    /// A step holding position.
    Hold(HoldStep),
}

/// The slave's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SlaveTotals {
    /// The state machine's counters.
    pub counters: SlaveCounters,
    /// v(n) as received.
    pub v_in: InboxStats,
    /// h(n) as published.
    pub h_out: OutboxStats,
}

/// The slave's record type.
pub type SlaveRecord = tactile_node::record::Record<SlaveSample, SlaveTotals>;
