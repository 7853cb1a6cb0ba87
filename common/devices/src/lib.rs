//! What lies outside a node's loop, and how the loop sees it: a haptic device under the
//! operator's hand and a robot arm, with their joints mapped and checked ([`map`]),
//! each tick's judgement of how fresh their newest sample is ([`watch`]) and what the
//! loop holds through staleness and loss ([`held`]); over ROS 2 on rmw_zenoh (the
//! node's session [`rmw_node`], the device [`ros_hand`], the robots [`ros_devices`]
//! and [`ros_arm`], and the live view
//! [`live_view`], behind the `zenoh` feature; what the nodes share opening them,
//! [`ros_side`]). The judgements are pure and always
//! built; the I/O only with Zenoh.

pub mod admit;
pub mod arm_map;
pub mod gate;
pub mod hand;
pub mod held;
#[cfg(feature = "zenoh")]
pub mod live_arm;
#[cfg(feature = "zenoh")]
pub mod live_view;
pub mod map;
#[cfg(feature = "zenoh")]
pub mod rmw_node;
#[cfg(feature = "zenoh")]
pub mod ros_arm;
#[cfg(feature = "zenoh")]
pub mod ros_devices;
#[cfg(feature = "zenoh")]
pub mod ros_hand;
pub mod ros_side;
pub mod watch;

pub use map::{JointMap, Reject};
pub use tactile_math::joints::Joints;
pub use tactile_peripheral::{LiveSink, Peripheral};
pub use tactile_records::device::DeviceCounters;
pub use watch::{Change, Reading};

/// A real master device, as the master's loop uses it: the handle in (three joints,
/// or a pose; with an orientation and a clutch on a 6-DoF device), force out.
pub trait HapticDevice: Peripheral {
    /// The handle's newest reading at this tick, judged.
    fn read(&mut self, now_ns: u64) -> (Reading<hand::Hand>, Change);
    /// What a reading's point is: three joint angles or a position.
    fn input(&self) -> tactile_scenario::HandInput {
        tactile_scenario::HandInput::Joints
    }
    /// The clutch: engaged (true) or released; `None` for a device without one.
    fn clutch(&self) -> Option<bool> {
        None
    }
    /// Sends the force to render, N, in the paper's base frame, through the gate.
    fn render(&mut self, force: [f64; 3], now_ns: u64);
    /// The force rises from zero again (the device or the loop back from a loss).
    fn restart_ramp(&mut self);
    /// Leaves the device rendering nothing: the zero force, sent so it arrives (the
    /// driver holds its last command). True if it was sent to a listening driver.
    fn release(&mut self) -> bool;
}

/// A real slave robot, as the slave's loop uses it: joint references out, joint
/// values and (when it has a sensor) the contact force in. Its joints are the arm's
/// (the paper's three angles, or an arm's from its URDF, in its order and units).
pub trait Robot: Peripheral {
    /// The joints' newest values at this tick, judged.
    fn read(&mut self, now_ns: u64) -> (Reading<Joints>, Change);
    /// The contact force at this tick, N in the paper's frame (an arm's: its base's
    /// axes), if the robot has a force sensor (else the environment model gives it);
    /// zero when the sensor's newest reading is older than the timeout.
    fn force(&mut self, now_ns: u64) -> Option<[f64; 3]>;
    /// The torque that came with the last [`Robot::force`], about the tool, in the
    /// base's axes, N m (zero for a robot whose sensor gives none).
    fn torque(&self) -> [f64; 3] {
        [0.0; 3]
    }
    /// Sends the joint references (rad in the paper's convention; an arm's in its
    /// URDF's), through the gate.
    fn command(&mut self, reference: Joints, now_ns: u64);
    /// Leaves the robot holding: its own last angles commanded, sent so they arrive.
    /// True if it was sent to a listening controller.
    fn release(&mut self) -> bool;
}

/// A ROS 2 session, publisher or subscription that could not be made, with what was
/// being done.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{context}: {detail}")]
pub struct RosError {
    /// What was being done.
    pub context: String,
    /// Zenoh's description.
    pub detail: String,
}

impl RosError {
    /// The error of `context`, from anything that says why.
    pub fn new(context: &str, e: impl std::fmt::Display) -> RosError {
        RosError {
            context: context.to_string(),
            detail: e.to_string(),
        }
    }
}
