//! What a node counted of the device or robot outside its loop (a haptic device, a
//! robot arm over ROS 2): in the master's and the slave's totals.

use serde::{Deserialize, Serialize};

/// What a device or robot delivered and how the loop judged it, for the record and
/// the summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct DeviceCounters {
    /// Messages received on the device's topics.
    pub messages: u64,
    /// Messages dropped: not decodable, a named joint missing, a value not finite or
    /// out of range.
    pub rejected: u64,
    /// Ticks that took a fresh sample.
    pub fresh: u64,
    /// Ticks that held a stale sample.
    pub stale: u64,
    /// Ticks with the device lost (or not heard from yet).
    pub lost: u64,
    /// Times the device was lost.
    pub losses: u64,
    /// Messages published to the device (forces, joint commands).
    pub published: u64,
    /// Messages that could not be published.
    pub publish_errors: u64,
    /// Ticks whose force-torque reading was older than the timeout, or not there yet:
    /// zero force used, never a stale contact.
    pub force_lost: u64,
    /// Commands the gate did not let through (not finite, or outside the joints' range
    /// in the driver's unit): the last good one was sent again instead, or nothing.
    pub gated: u64,
    /// Commands the gate cut: a force to its limit or by its rate, a joint step to the
    /// velocity limit.
    pub limited: u64,
    /// Times the force on the device was ramped up from zero (at the start, when the
    /// device or the loop came back, after a non-finite force).
    pub ramps: u64,
    /// Whether the zero (the device) or the hold (the robot) at the end was sent, and
    /// a subscriber was matched to receive it.
    pub released: bool,
}
