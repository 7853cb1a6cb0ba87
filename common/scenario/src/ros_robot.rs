//! `[slave.ros2]`: a robot over ros2_control, whatever its joint count.
//!
//! An arm from its URDF (`[slave.arm]`) is configured by that URDF alone: its joints
//! (by name, in the chain's order), their limits and their velocities. The
//! three-element keys (`joints`, `map`, `max_velocity`, `wrench_map`) describe the
//! paper's 3-DoF arm only; they are `Option`s so that writing one beside `[slave.arm]`
//! is refused by its name even when its value is the default, with what to write
//! instead (issue 52: a value equal to the default used to pass unnoticed).

use crate::ros::{joint_names, topic_name, ForceMapConfig, JointMapConfig};
use crate::shown::Num;
use crate::watch::WatchConfig;
use crate::{invalid, positive, ScenarioError};
use serde::{Deserialize, Serialize};

/// The message a robot's controller takes its references in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum RobotCommand {
    /// `std_msgs/msg/Float64MultiArray`, the joints in order: a forward position
    /// controller's `commands` (`/<controller>/commands`).
    #[default]
    Positions,
    /// `trajectory_msgs/msg/JointTrajectory` of one point, the joints by name: a
    /// joint_trajectory_controller's `/<controller>/joint_trajectory` (UR's
    /// scaled_joint_trajectory_controller, Franka's fr3_arm_controller, Kinova's,
    /// xArm's). Only with `[slave.arm]`.
    Trajectory,
    /// `geometry_msgs/msg/PoseStamped` of the tool in the arm's base link (its
    /// `frame_id`), stamped with the wall clock: for stacks that do their own IK and
    /// safety, MoveIt Servo's `/servo_node/pose_target_cmds` and FZI
    /// cartesian_controllers' `<controller>/target_frame`. The pose is the FK of the
    /// joints the gate passed. Only with `[slave.arm]`.
    Pose,
}

/// `[slave.ros2]`: a robot arm through ros2_control.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RosRobotConfig {
    /// The robot's `sensor_msgs/msg/JointState` topic: theta^SD.
    pub joint_states: String,
    /// The paper's arm only: the names of the joints moving as theta_1, theta_2,
    /// theta_3, and the order of the commands (default `joint1, joint2, joint3`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joints: Option<[String; 3]>,
    /// The paper's arm only: the robot's joint conventions (default: the identity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map: Option<JointMapConfig>,
    /// Where the joint references go: `std_msgs/msg/Float64MultiArray` for a forward
    /// position controller, in the driver's unit.
    pub command_topic: String,
    /// A force-torque sensor's `geometry_msgs/msg/WrenchStamped` (newtons, in the
    /// robot's base frame); empty: the force comes from the environment model.
    pub wrench_topic: String,
    /// The paper's arm only: the paper's axes in the sensor's frame (default: the
    /// identity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wrench_map: Option<ForceMapConfig>,
    /// Staleness and loss.
    pub watch: WatchConfig,
    /// The paper's arm only: the fastest each joint may be commanded to move, rad/s
    /// (the paper's angles): a command's step per period is cut to it (default 2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_velocity: Option<[f64; 3]>,
    /// The message the controller takes (`positions` or `trajectory`).
    pub command: RobotCommand,
    /// A trajectory point's `time_from_start`, s (default: one period).
    pub trajectory_time_s: Option<f64>,
    /// With `[slave.arm]`: the point the wrench's torque is about, `frame` (the
    /// message frame's origin, as a sensor measures it) or `tool` (the tool, in the
    /// frame's axes: Franka's `external_wrench_in_base_frame`, about its stiffness
    /// frame, given in the base).
    pub wrench_torque: TorqueAbout,
    /// The largest force a wrench message may carry, N (its length, in the sensor's
    /// frame): past it a message is no measurement (a driver's garbage, a unit
    /// mix-up, 1e300 N) and is refused and counted as a non-finite one is, the last
    /// good force kept until it goes stale [1000: past any cobot's sensing range and
    /// most wrist sensors'].
    pub max_force: f64,
}

/// Where a wrench's torque is taken about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TorqueAbout {
    /// The origin of the message's frame.
    #[default]
    Frame,
    /// The arm's tool (its URDF tip).
    Tool,
}

impl Default for RosRobotConfig {
    fn default() -> Self {
        RosRobotConfig {
            joint_states: "/joint_states".into(),
            joints: None,
            map: None,
            command_topic: "/forward_position_controller/commands".into(),
            wrench_topic: String::new(),
            wrench_map: None,
            watch: WatchConfig::default(),
            max_velocity: None,
            command: RobotCommand::Positions,
            trajectory_time_s: None,
            wrench_torque: TorqueAbout::Frame,
            max_force: 1000.0,
        }
    }
}

/// The paper's arm's joint velocity limit where `max_velocity` is not given, rad/s.
pub const PAPER_MAX_VELOCITY: f64 = 2.0;

/// What to write instead of each paper-only key beside `[slave.arm]`.
const WITH_ARM: [(&str, &str); 4] = [
    (
        "joints",
        "the arm's joints are its URDF's, from `base` to `tip`, read by those names from `joint_states` and commanded in that order: delete `joints`",
    ),
    (
        "map",
        "each joint's range is its URDF <limit lower upper> and its values are the driver's own, in radians or metres (REP 103), with no sign, offset or unit: delete [slave.ros2.map] and put the limits in the URDF",
    ),
    (
        "max_velocity",
        "each joint's speed is cut to its URDF <limit velocity> (2 rad/s where none is given): delete `max_velocity` and put the limits in the URDF",
    ),
    (
        "wrench_map",
        "a wrench is turned into the base's axes through the chain from its message's frame_id (a link of the URDF; see `wrench_torque`): delete [slave.ros2.wrench_map]",
    ),
];

impl RosRobotConfig {
    /// The paper's arm's three joint names.
    pub fn paper_joints(&self) -> [String; 3] {
        self.joints
            .clone()
            .unwrap_or_else(|| ["joint1".into(), "joint2".into(), "joint3".into()])
    }

    /// The paper's arm's joint conventions.
    pub fn paper_map(&self) -> JointMapConfig {
        self.map.clone().unwrap_or_default()
    }

    /// The paper's arm's joint velocity limits, rad/s.
    pub fn paper_max_velocity(&self) -> [f64; 3] {
        self.max_velocity.unwrap_or([PAPER_MAX_VELOCITY; 3])
    }

    /// The paper's axes in the paper arm's force sensor's frame.
    pub fn paper_wrench_map(&self) -> ForceMapConfig {
        self.wrench_map.clone().unwrap_or_default()
    }

    /// Checks the ranges; errors name `slave.ros2.*`. With `arm` (a `[slave.arm]`),
    /// the paper arm's keys are refused by name, each with what to write instead.
    pub fn validate(&self, arm: bool) -> Result<(), ScenarioError> {
        if arm {
            self.refuse_paper_keys()?;
        }
        self.command.validate(arm)?;
        topic_name(&self.joint_states, "slave.ros2.joint_states")?;
        joint_names(&self.paper_joints(), "slave.ros2.joints")?;
        self.paper_map().validate("slave.ros2.map")?;
        topic_name(&self.command_topic, "slave.ros2.command_topic")?;
        if !self.wrench_topic.is_empty() {
            topic_name(&self.wrench_topic, "slave.ros2.wrench_topic")?;
        }
        self.paper_wrench_map().validate("slave.ros2.wrench_map")?;
        positive(self.max_force, "slave.ros2.max_force", false)?;
        for (i, v) in self.paper_max_velocity().iter().enumerate() {
            positive(*v, &format!("slave.ros2.max_velocity[{i}]"), false)?;
        }
        if let Some(t) = self.trajectory_time_s {
            if !t.is_finite() || !(0.0..=1.0).contains(&t) || t == 0.0 {
                return Err(invalid(
                    "slave.ros2.trajectory_time_s",
                    format!("{} s is outside (0, 1] s", Num(t)),
                ));
            }
        }
        self.watch.validate("slave.ros2.watch")
    }

    /// The first of the paper arm's three-element keys that is given, refused by
    /// name whatever its value, with what to write instead.
    fn refuse_paper_keys(&self) -> Result<(), ScenarioError> {
        refuse_given([
            self.joints.is_some(),
            self.map.is_some(),
            self.max_velocity.is_some(),
            self.wrench_map.is_some(),
        ])
    }
}

/// The paper arm's keys in the scenario as written, beside `[slave.arm]`: refused
/// before the arrays' lengths are compared, so that six joint names for a UR5 are told
/// what to write instead, not that `joints` takes three.
pub(crate) fn refuse_written(written: &toml::Value) -> Result<(), ScenarioError> {
    let slave = written.get("slave");
    let (Some(_), Some(ros2)) = (
        slave.and_then(|s| s.get("arm")),
        slave.and_then(|s| s.get("ros2")),
    ) else {
        return Ok(());
    };
    refuse_given(WITH_ARM.map(|(key, _)| ros2.get(key).is_some()))
}

/// The first key of [`WITH_ARM`] that `given` marks, as an error with what to write
/// instead.
fn refuse_given(given: [bool; 4]) -> Result<(), ScenarioError> {
    match WITH_ARM.iter().zip(given).find(|(_, set)| *set) {
        Some(((field, instead), _)) => Err(invalid(
            format!("slave.ros2.{field}"),
            format!("is for the paper's 3-DoF arm only; with [slave.arm] {instead}"),
        )),
        None => Ok(()),
    }
}

impl RobotCommand {
    /// Checks the command fits the arm: a trajectory names joints and a pose needs
    /// the chain's FK, which only an arm from its URDF has.
    pub fn validate(self, arm: bool) -> Result<(), ScenarioError> {
        let name = match self {
            RobotCommand::Positions => return Ok(()),
            RobotCommand::Trajectory => "trajectory",
            RobotCommand::Pose => "pose",
        };
        if !arm {
            return Err(invalid(
                "slave.ros2.command",
                format!("\"{name}\" needs [slave.arm] (its URDF names the joints and the tool); the paper's three joints take \"positions\""),
            ));
        }
        Ok(())
    }
}

impl crate::Scenario {
    /// A scenario as a record or a run folder holds it: as
    /// [`Scenario::from_toml_str`](crate::Scenario::from_toml_str), except that the
    /// paper arm's four `[slave.ros2]` keys beside `[slave.arm]` are dropped, not
    /// refused, at their defaults, or at any value when the slave's backend is not
    /// ros2 (there they never had an effect). Tactile before issue 52 wrote every key,
    /// those four included, into the scenario it recorded, so its run folders still
    /// read (a sweep resumes over them); its records of format 15 are refused by the
    /// record reader on their format, not here. A scenario file a user writes gets no
    /// such leniency.
    pub fn from_recorded_toml(text: &str) -> Result<crate::Scenario, ScenarioError> {
        if let Ok(mut table) = text.parse::<toml::Table>() {
            if drop_written_defaults(&mut table) {
                if let Ok(text) = toml::to_string(&table) {
                    return crate::Scenario::from_toml_str(&text);
                }
            }
        }
        crate::Scenario::from_toml_str(text)
    }
}

/// Drops from `[slave.ros2]` each paper-arm key equal to what the old writer put
/// there (any value if the backend is not ros2), if there is a `[slave.arm]`; true
/// if it dropped one.
fn drop_written_defaults(table: &mut toml::Table) -> bool {
    let Some(slave) = table.get_mut("slave").and_then(|v| v.as_table_mut()) else {
        return false;
    };
    if !slave.contains_key("arm") {
        return false;
    }
    let ros_backend = slave.get("backend").and_then(toml::Value::as_str) == Some("ros2");
    let Some(ros2) = slave.get_mut("ros2").and_then(|v| v.as_table_mut()) else {
        return false;
    };
    let d = RosRobotConfig::default();
    let written = [
        ("joints", toml::Value::try_from(d.paper_joints())),
        ("map", toml::Value::try_from(d.paper_map())),
        (
            "max_velocity",
            toml::Value::try_from(d.paper_max_velocity()),
        ),
        ("wrench_map", toml::Value::try_from(d.paper_wrench_map())),
    ];
    let mut dropped = false;
    for (key, value) in written {
        if ros2.contains_key(key)
            && (!ros_backend || value.is_ok_and(|v| ros2.get(key) == Some(&v)))
        {
            ros2.remove(key);
            dropped = true;
        }
    }
    dropped
}
