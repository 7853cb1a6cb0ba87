//! What a node's driver knows of a device or robot outside its loop, whatever it is: a
//! [`Peripheral`] (heard from or not, what it delivered, what it dropped and why, a
//! [`Reject`]), a [`LiveSink`] for the live view, and the once-a-second log line
//! ([`log_second`]). The devices, robots and arms themselves (their joints, URDFs,
//! gimbals, ROS 2 sessions) are `tactile-devices`' and the nodes'; the runtime depends
//! on this crate alone, so it knows no arm and no gimbal.

pub use tactile_records::device::DeviceCounters;

/// Why a message was dropped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Reject {
    /// Not a well-formed message of the topic's type.
    #[error("not a well-formed message: {0}")]
    Malformed(#[from] tactile_ros::CdrError),
    /// A named joint is not in the message (or has no position).
    #[error("joint {0:?} is missing")]
    Missing(String),
    /// A value is NaN or infinite.
    #[error("joint {0:?} is not finite")]
    NotFinite(String),
    /// A value outside the configured range.
    #[error("joint {joint:?} at {value} rad is outside {min}..={max}")]
    OutOfRange {
        /// The joint.
        joint: String,
        /// Its angle, rad (the paper's convention).
        value: f64,
        /// Smallest accepted.
        min: f64,
        /// Largest accepted.
        max: f64,
    },
    /// A force that is NaN or infinite.
    #[error("force is not finite")]
    ForceNotFinite,
    /// A force larger than any measurement could be (`[slave.ros2] max_force`).
    #[error("force of {force:.3e} N is above max_force ({max} N): no measurement")]
    ForceImplausible {
        /// Its length, N.
        force: f64,
        /// The bound, N.
        max: f64,
    },
    /// A pose that is not one: not finite, or an orientation that is not a rotation.
    #[error("not a pose: {0}")]
    BadPose(String),
    /// A sample on the topic's name whose key carries another type's hash.
    #[error(
        "type hash {0} is not the topic type's (its RIHS01 hash, or Humble's TypeHashNotSupported)"
    )]
    WrongType(String),
    /// A sample without rmw_zenoh's attachment, or with a malformed one.
    #[error("rmw_zenoh's attachment: {0}")]
    Attachment(String),
    /// A `JointState` naming a joint twice: which of its values holds is undefined.
    #[error("joint {0:?} is named twice")]
    DuplicateJoint(String),
    /// A button's value that is neither 0 (released) nor 1 (pressed).
    #[error("{field} is {value}: a button is 0 or 1")]
    BadButton {
        /// The message's field.
        field: &'static str,
        /// Its value.
        value: i32,
    },
    /// A force in a frame the arm's URDF does not have (it cannot be turned into the
    /// base's).
    #[error("force in frame {0:?}, which is not a link of the arm's URDF")]
    UnknownFrame(String),
}

/// A device or robot as the loop's driver sees it, whatever it is: whether it has
/// been heard from, what it delivered, and what it sent that was dropped.
pub trait Peripheral {
    /// `device` or `robot`, for messages.
    fn kind(&self) -> &'static str;
    /// True once a good message has come.
    fn heard(&self) -> bool;
    /// What it delivered and how it was judged.
    fn counters(&self) -> DeviceCounters;
    /// The first message dropped since the last call, for the log.
    fn take_reject(&self) -> Option<Reject>;
    /// Where it is read from, for messages.
    fn describe(&self) -> String;
    /// Why nothing can come yet, if the way to it is not even open (the ROS 2 session
    /// reached no router or peer); None once it is, or where there is no such way.
    fn unreached(&self) -> Option<String> {
        None
    }
}

/// Where a loop hands its state for the live view: takes it only every k-th sample,
/// and never blocks.
pub trait LiveSink<S> {
    /// True if sample `n` is one the live view publishes.
    fn due(&self, n: u64) -> bool;
    /// Hands the state over (dropped and counted if the publisher is behind).
    fn offer(&mut self, state: S);
}

/// Logs, at most once a second (call it when the counters are due), the stale and
/// lost ticks of `who` since the last call and what it sent that was dropped.
pub fn log_second(
    who: &str,
    seen: &mut DeviceCounters,
    now: &DeviceCounters,
    reject: Option<Reject>,
) {
    if now.stale != seen.stale || now.lost != seen.lost || now.rejected != seen.rejected {
        tracing::warn!(
            "{who} in the last second: {} stale and {} lost ticks, {} messages dropped{}",
            now.stale - seen.stale,
            now.lost - seen.lost,
            now.rejected - seen.rejected,
            reject.map_or(String::new(), |r| format!(" (first: {r})"))
        );
    }
    *seen = *now;
}
