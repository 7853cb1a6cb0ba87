//! What a 6-DoF haptic device's ROS 2 driver gives beyond three joints, in
//! `[master.ros2]`: where the handle's pose is read from (three joints and the paper's
//! kinematics, or a `PoseStamped`), its orientation through the gimbal's own joints
//! (a Touch's), the clutch (a `Bool`, a `Joy` button, a Touch's `OmniButtonEvent`), and
//! the message the force goes out in (a `WrenchStamped`, an `OmniFeedback`, a
//! `Float64MultiArray`), as the drivers take them (docs/14-six-dof-master.md).

use crate::workspace::FrameRotation;
use crate::{invalid, ScenarioError};
use serde::{Deserialize, Serialize};

/// Where the handle's position comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum HandInput {
    /// Three joints of the `JointState` (`joints`), through the paper's kinematics.
    #[default]
    Joints,
    /// A `geometry_msgs/msg/PoseStamped` (`pose_topic`): position and orientation, in
    /// the device's base frame (Force Dimension's `/fd/ee_pose`, CRTK's `measured_cp`).
    Pose,
}

/// The handle's orientation from the device's own joints: the chain of its URDF from
/// `base` to `tip`, every joint read by name from the `JointState` in the driver's
/// convention (the URDF is the driver's: its joints' zeros are the driver's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GimbalConfig {
    /// The device's URDF (relative to the scenario's folder).
    pub urdf: String,
    /// The URDF's base link.
    pub base: String,
    /// The link held in the hand (a Touch's stylus).
    pub tip: String,
    /// The URDF base's axes in the paper's frame (the master's): a vector `u` of the
    /// URDF is `R u` in the paper's. The omni_common drivers' base has z up and y away
    /// from the operator, the paper's (OpenHaptics') y up and z towards the operator:
    /// `{ rpy_deg = [-90, 0, 0] }`.
    #[serde(default)]
    pub frame: FrameRotation,
}

/// Which button of a Touch's `OmniButtonEvent` is the clutch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OmniButton {
    /// The grey (front) button.
    Grey,
    /// The white (back) button.
    White,
}

/// The clutch: held means engaged (the robot follows); released, the robot holds and
/// the handle moves freely. A driver that sends its button only on change is read as
/// the last state it sent; before the first message the clutch is released, so the
/// robot waits for the operator's first press.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ClutchConfig {
    /// No clutch: always engaged.
    #[default]
    None,
    /// A `std_msgs/msg/Bool`, true engaged (Force Dimension's `/fd/fd_clutch`).
    Bool {
        /// The topic.
        topic: String,
    },
    /// A `sensor_msgs/msg/Joy` button, 1 engaged (CRTK's `button1`, `front`:
    /// `buttons[0]`, 1 pressed, 0 released, 2 clicked: a click has been let go, so it
    /// is released).
    Joy {
        /// The topic.
        topic: String,
        /// The button's index in `buttons`.
        #[serde(default)]
        button: u32,
    },
    /// A Touch's `omni_msgs/msg/OmniButtonEvent` (omni_common's `phantom/button`).
    OmniButton {
        /// The topic.
        topic: String,
        /// `grey` or `white`.
        button: OmniButton,
    },
}

impl ClutchConfig {
    /// The topic, if there is a clutch.
    pub fn topic(&self) -> Option<&str> {
        match self {
            ClutchConfig::None => None,
            ClutchConfig::Bool { topic }
            | ClutchConfig::Joy { topic, .. }
            | ClutchConfig::OmniButton { topic, .. } => Some(topic),
        }
    }
}

/// The message the force to render goes out in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ForceMessage {
    /// `geometry_msgs/msg/WrenchStamped` (CRTK's `servo_cf`), torque zero.
    #[default]
    Wrench,
    /// `omni_msgs/msg/OmniFeedback` (omni_common's `phantom/force_feedback`), the
    /// position zero (the drivers do not use it).
    OmniFeedback,
    /// `std_msgs/msg/Float64MultiArray` `[fx, fy, fz]` (Force Dimension's
    /// `/fd/fd_controller/commands`, an effort controller's).
    Float64MultiArray,
}

/// Checks the 6-DoF part of `[master.ros2]`.
pub(crate) fn validate(
    input: HandInput,
    pose_topic: &str,
    gimbal: Option<&GimbalConfig>,
    clutch: &ClutchConfig,
    topic_name: impl Fn(&str, &str) -> Result<(), ScenarioError>,
) -> Result<(), ScenarioError> {
    if input == HandInput::Pose {
        topic_name(pose_topic, "master.ros2.pose_topic")?;
        if gimbal.is_some() {
            return Err(invalid(
                "master.ros2.gimbal",
                "a pose device's orientation is its pose's: a gimbal is only for input = \"joints\"",
            ));
        }
    }
    if let Some(g) = gimbal {
        for (field, v) in [("urdf", &g.urdf), ("base", &g.base), ("tip", &g.tip)] {
            if v.trim().is_empty() {
                return Err(invalid(
                    format!("master.ros2.gimbal.{field}"),
                    "must not be empty",
                ));
            }
        }
        crate::workspace::validate_rotation(&g.frame, "master.ros2.gimbal.frame")?;
    }
    if let Some(t) = clutch.topic() {
        topic_name(t, "master.ros2.clutch.topic")?;
    }
    Ok(())
}
