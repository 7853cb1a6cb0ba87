//! The topics a run is seen through, recorded (`run.mcap`) and live alike: one list,
//! so a recording and a live run look the same to a viewer.

/// How often a topic carries a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cadence {
    /// Once, at the first sample.
    Once,
    /// Every sample.
    Sample,
    /// At the first sample and once a second of run time.
    Second,
}

/// A topic: name, ROS 2 type, cadence, what it carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Topic {
    /// Topic name.
    pub name: &'static str,
    /// ROS 2 type, `pkg/msg/Type`.
    pub ty: &'static str,
    /// How often.
    pub cadence: Cadence,
    /// What it carries (for the guide and `--help`).
    pub about: &'static str,
}

const fn t(name: &'static str, ty: &'static str, cadence: Cadence, about: &'static str) -> Topic {
    Topic {
        name,
        ty,
        cadence,
        about,
    }
}

/// Every topic, in the order a recording declares its channels.
pub const TOPICS: [Topic; 14] = [
    t(
        "/robot_description",
        "std_msgs/msg/String",
        Cadence::Once,
        "URDF of both arms in the paper's dimensions",
    ),
    t(
        "/tf_static",
        "tf2_msgs/msg/TFMessage",
        Cadence::Once,
        "world -> each base, forearm -> tool",
    ),
    t(
        "/tf",
        "tf2_msgs/msg/TFMessage",
        Cadence::Sample,
        "both arms' link transforms from the joint angles",
    ),
    t(
        "/master/joint_states",
        "sensor_msgs/msg/JointState",
        Cadence::Sample,
        "master angles b(n), velocities, torques p(n)",
    ),
    t(
        "/slave/joint_states",
        "sensor_msgs/msg/JointState",
        Cadence::Sample,
        "slave angles, velocities, controller torques",
    ),
    t(
        "/master/target",
        "geometry_msgs/msg/PoseStamped",
        Cadence::Sample,
        "the operator's target a(n), master_base",
    ),
    t(
        "/master/handle",
        "geometry_msgs/msg/PoseStamped",
        Cadence::Sample,
        "the handle's position, master_base",
    ),
    t(
        "/slave/tool",
        "geometry_msgs/msg/PoseStamped",
        Cadence::Sample,
        "the tool l(n) from FK-HSD, slave_base",
    ),
    t(
        "/slave/force",
        "geometry_msgs/msg/WrenchStamped",
        Cadence::Sample,
        "contact force h(n), slave_base",
    ),
    t(
        "/master/force",
        "geometry_msgs/msg/WrenchStamped",
        Cadence::Sample,
        "q(n) as the master received it, master_base",
    ),
    t(
        "/master/felt",
        "geometry_msgs/msg/WrenchStamped",
        Cadence::Sample,
        "the force the operator feels, master_base",
    ),
    t(
        "/slave/environment",
        "visualization_msgs/msg/MarkerArray",
        Cadence::Second,
        "the environment's objects, slave_base",
    ),
    t(
        "/tactile/timing",
        "tactile_msgs/msg/SampleTiming",
        Cadence::Sample,
        "round trip, overhead, injected delays, flags, passivity observers",
    ),
    t(
        "/slave/bodies",
        "visualization_msgs/msg/MarkerArray",
        Cadence::Sample,
        "a physics world's moving bodies and the tool body, the arm's base frame",
    ),
];

/// The topic named `name`.
pub fn topic(name: &str) -> Option<&'static Topic> {
    TOPICS.iter().find(|t| t.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_topic_has_a_schema() {
        for t in TOPICS {
            assert!(crate::schema::ros2msg(t.ty).is_some(), "{}", t.name);
        }
    }
}
