//! `[ros]`, `[master.ros2]` and `[slave.ros2]`: real devices and robots over ROS 2's
//! Zenoh middleware (rmw_zenoh), and the live view of a run.
//!
//! A ROS 2 driver's joint conventions are not the paper's: names, order, direction,
//! zero and unit differ from driver to driver, so each is configurable, and the map
//! is `theta = sign * raw * unit + offset` (raw in the driver's unit, theta in the
//! paper's radians). The defaults follow the Phantom Omni / Geomagic Touch drivers'
//! names (`waist`, `shoulder`, `elbow`) and ros2_control's forward position
//! controller; every one of them is to be checked against the driver at hand.

use crate::hand::{ClutchConfig, ForceMessage, GimbalConfig, HandInput};
use crate::shown::Num;
use crate::watch::WatchConfig;
use crate::{finite3, invalid, positive, ScenarioError};
use serde::{Deserialize, Serialize};

/// How the nodes reach ROS 2: one Zenoh session per node, as an rmw_zenoh node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RosConfig {
    /// ROS_DOMAIN_ID, 0 to 232: the first part of every key expression.
    pub domain_id: u32,
    /// Zenoh endpoints to connect to: rmw_zenoh's router (`ros2 run rmw_zenoh_cpp
    /// rmw_zenohd`) listens on `tcp/127.0.0.1:7447` by default.
    pub connect: Vec<String>,
    /// Zenoh endpoints to listen on (none by default: the router connects the peers).
    pub listen: Vec<String>,
    /// The nodes' ROS namespace, `""` or `/name`.
    pub namespace: String,
    /// The live view: each node's state as ROS 2 topics while it runs.
    pub live: LiveConfig,
    /// Mutual TLS for the session (`[ros.tls]`); none: in clear, as rmw_zenoh's
    /// default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tls: Option<crate::ros_tls::RosTlsConfig>,
}

impl Default for RosConfig {
    fn default() -> Self {
        RosConfig {
            domain_id: 0,
            connect: vec!["tcp/127.0.0.1:7447".into()],
            listen: Vec::new(),
            namespace: String::new(),
            live: LiveConfig::default(),
            tls: None,
        }
    }
}

/// `[ros.live]`: publish the run as it goes (off by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LiveConfig {
    /// Publish the live view.
    pub enabled: bool,
    /// Messages per topic per second, at most the loop's rate (every k-th sample,
    /// k = round(rate_hz / live rate)).
    pub rate_hz: f64,
}

impl Default for LiveConfig {
    fn default() -> Self {
        LiveConfig {
            enabled: false,
            rate_hz: 50.0,
        }
    }
}

/// Which device a side runs with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// The simulated device (the master's hand and device, the slave's arm and
    /// environment): today's loop.
    #[default]
    Simulated,
    /// A device or robot over ROS 2 (`[master.ros2]`, `[slave.ros2]`).
    Ros2,
}

/// The unit a driver reports joint angles in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum AngleUnit {
    /// Radians (ROS's convention, REP 103).
    #[default]
    Rad,
    /// Degrees.
    Deg,
}

impl AngleUnit {
    /// Radians per unit.
    pub fn radians(self) -> f64 {
        match self {
            AngleUnit::Rad => 1.0,
            AngleUnit::Deg => std::f64::consts::PI / 180.0,
        }
    }
}

/// The largest angle (an offset, a joint's limit) a map may name, rad: a hundred
/// turns, far beyond any joint, and small enough that no conversion overflows.
pub const MAX_ANGLE_RAD: f64 = 200.0 * std::f64::consts::PI;

/// How a driver's joint values become the paper's angles: `theta = sign * raw * unit
/// + offset`, checked against `min..=max`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct JointMapConfig {
    /// +1 or -1 per joint: the driver's direction against the paper's.
    pub sign: [f64; 3],
    /// Added after sign and unit, rad: the paper's angle at the driver's zero.
    pub offset: [f64; 3],
    /// `rad` or `deg`.
    pub unit: AngleUnit,
    /// Smallest paper angle accepted per joint, rad; a message outside is rejected.
    pub min: [f64; 3],
    /// Largest paper angle accepted per joint, rad.
    pub max: [f64; 3],
    /// The driver gives the third joint relative to the second, as the omni_common
    /// drivers and sawSensablePhantom give a Touch's elbow (`J2 - J1` of OpenHaptics'
    /// angles), where the paper's theta_3 is measured as OpenHaptics' J2: then
    /// `theta_3 = sign raw_3 unit + offset + theta_2`.
    pub elbow_after_shoulder: bool,
}

impl Default for JointMapConfig {
    fn default() -> Self {
        JointMapConfig {
            sign: [1.0; 3],
            offset: [0.0; 3],
            unit: AngleUnit::Rad,
            min: [-std::f64::consts::PI; 3],
            max: [std::f64::consts::PI; 3],
            elbow_after_shoulder: false,
        }
    }
}

impl JointMapConfig {
    pub(crate) fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        for (i, s) in self.sign.iter().enumerate() {
            if *s != 1.0 && *s != -1.0 {
                return Err(invalid(
                    format!("{field}.sign[{i}]"),
                    format!("{} is not 1 or -1", Num(*s)),
                ));
            }
        }
        for (name, v) in [
            ("offset", &self.offset),
            ("min", &self.min),
            ("max", &self.max),
        ] {
            finite3(v, &format!("{field}.{name}"))?;
            for (i, x) in v.iter().enumerate() {
                if x.abs() > MAX_ANGLE_RAD {
                    return Err(invalid(
                        format!("{field}.{name}[{i}]"),
                        format!(
                            "{} rad is beyond +-{MAX_ANGLE_RAD} rad: no joint turns that far",
                            Num(*x)
                        ),
                    ));
                }
            }
        }
        for i in 0..3 {
            if self.min[i] >= self.max[i] {
                return Err(invalid(
                    format!("{field}.max[{i}]"),
                    format!(
                        "{} rad is not above min {} rad",
                        Num(self.max[i]),
                        Num(self.min[i])
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// How a force in the paper's base frame is written in a device's base frame:
/// `device[i] = sign[i] * paper[axes[i]]` (the identity by default). A Touch's base
/// frame, for one, has y up where the paper has z.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ForceMapConfig {
    /// The paper's axis (0 x, 1 y, 2 z) each device axis takes, a permutation.
    pub axes: [usize; 3],
    /// +1 or -1 per device axis.
    pub sign: [f64; 3],
}

impl Default for ForceMapConfig {
    fn default() -> Self {
        ForceMapConfig {
            axes: [0, 1, 2],
            sign: [1.0; 3],
        }
    }
}

impl ForceMapConfig {
    pub(crate) fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        let mut seen = [false; 3];
        for (i, a) in self.axes.iter().enumerate() {
            if *a > 2 || seen[*a] {
                return Err(invalid(
                    format!("{field}.axes[{i}]"),
                    format!("{a}: the axes are a permutation of 0, 1, 2"),
                ));
            }
            seen[*a] = true;
        }
        for (i, s) in self.sign.iter().enumerate() {
            if *s != 1.0 && *s != -1.0 {
                return Err(invalid(
                    format!("{field}.sign[{i}]"),
                    format!("{} is not 1 or -1", Num(*s)),
                ));
            }
        }
        Ok(())
    }

    /// The paper's force in the device's frame.
    pub fn to_device(&self, f: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|i| self.sign[i] * f[self.axes[i]])
    }

    /// The device's force in the paper's frame.
    pub fn to_paper(&self, d: [f64; 3]) -> [f64; 3] {
        let mut f = [0.0; 3];
        for i in 0..3 {
            f[self.axes[i]] = self.sign[i] * d[i];
        }
        f
    }
}

/// Checks three joint names: non-empty and distinct.
pub(crate) fn joint_names(names: &[String; 3], field: &str) -> Result<(), ScenarioError> {
    for (i, n) in names.iter().enumerate() {
        if n.is_empty() || names[..i].contains(n) {
            return Err(invalid(
                format!("{field}[{i}]"),
                format!("{n:?}: names must be non-empty and distinct"),
            ));
        }
    }
    Ok(())
}

/// `[master.ros2]`: a haptic device through its ROS 2 driver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RosDeviceConfig {
    /// The driver's `sensor_msgs/msg/JointState` topic: b(n).
    pub joint_states: String,
    /// Names of the joints giving theta_1, theta_2, theta_3 (the message may hold
    /// more joints, in any order).
    pub joints: [String; 3],
    /// The driver's joint conventions.
    pub map: JointMapConfig,
    /// Where the force to render goes: `geometry_msgs/msg/WrenchStamped`, newtons,
    /// clamped to `master.force_limit`.
    pub force_topic: String,
    /// `frame_id` of the force: the device's base frame.
    pub frame_id: String,
    /// The paper's axes in the device's base frame, for the force.
    pub force_map: ForceMapConfig,
    /// Staleness and loss.
    pub watch: WatchConfig,
    /// Seconds the force rendered takes to rise from zero at the start and after each
    /// discontinuity (the device or the loop back from a loss), as OpenHaptics' force
    /// ramping does; 0: no ramp.
    pub ramp_s: f64,
    /// The fastest the force rendered may change, N/s per axis.
    pub max_force_rate: f64,
    /// Where the handle's position comes from: `joints` or `pose`.
    pub input: HandInput,
    /// The driver's `geometry_msgs/msg/PoseStamped` topic, with `input = "pose"`.
    pub pose_topic: String,
    /// The handle's orientation from all of the device's joints through its URDF (a
    /// Touch's gimbal), with `input = "joints"`; none: a 3-DoF master.
    pub gimbal: Option<GimbalConfig>,
    /// The clutch (`{ kind = "bool" | "joy" | "omni_button", topic = .. }`); none by
    /// default.
    pub clutch: ClutchConfig,
    /// The message the force goes out in: `wrench`, `omni_feedback` or
    /// `float64_multi_array`.
    pub force_message: ForceMessage,
}

impl Default for RosDeviceConfig {
    fn default() -> Self {
        RosDeviceConfig {
            joint_states: "/phantom/joint_states".into(),
            joints: ["waist".into(), "shoulder".into(), "elbow".into()],
            map: JointMapConfig::default(),
            force_topic: "/phantom/force_feedback".into(),
            frame_id: "base".into(),
            force_map: ForceMapConfig::default(),
            watch: WatchConfig::default(),
            ramp_s: 0.5,
            max_force_rate: 1000.0,
            input: HandInput::default(),
            pose_topic: "/fd/ee_pose".into(),
            gimbal: None,
            clutch: ClutchConfig::default(),
            force_message: ForceMessage::default(),
        }
    }
}

/// The longest ROS 2 topic name, characters: rmw's `RMW_TOPIC_MAX_NAME_LENGTH`
/// (255, less 8 for the middleware's prefix); a longer one is refused by every node
/// that would subscribe or publish it.
pub const MAX_TOPIC_CHARS: usize = 255 - 8;

/// A ROS 2 topic name: starts with `/`, then `/`-separated tokens of letters, digits
/// and underscores, each not starting with a digit (ROS 2's topic rules, absolute),
/// at most [`MAX_TOPIC_CHARS`] long.
pub fn topic_name(name: &str, field: &str) -> Result<(), ScenarioError> {
    let shown = crate::csv::shortened(name);
    let bad = |why: &str| Err(invalid(field, format!("{shown:?}: {why}")));
    if name.len() > MAX_TOPIC_CHARS {
        return bad(&format!(
            "{} characters, more than the {MAX_TOPIC_CHARS} a ROS 2 topic name may have (rmw's RMW_TOPIC_MAX_NAME_LENGTH)",
            name.len()
        ));
    }
    let Some(rest) = name.strip_prefix('/') else {
        return bad("a topic name starts with /");
    };
    if rest.is_empty() {
        return bad("a topic name needs at least one token after /");
    }
    for tok in rest.split('/') {
        let ok = tok.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            && !tok.is_empty()
            && !tok.starts_with(|c: char| c.is_ascii_digit());
        if !ok {
            return bad("tokens are letters, digits and _, not empty, not starting with a digit");
        }
    }
    Ok(())
}

impl RosConfig {
    /// The endpoints (`ros.connect`, `ros.listen`) that reach beyond this host without
    /// TLS.
    pub fn in_clear_to_other_hosts(&self) -> Vec<String> {
        self.connect
            .iter()
            .chain(&self.listen)
            .filter(|e| crate::endpoint::in_clear_to_another_host(e))
            .cloned()
            .collect()
    }

    /// Checks the ranges; errors name `ros.*`. `rate_hz` is the loop's.
    pub fn validate(&self, rate_hz: f64) -> Result<(), ScenarioError> {
        if self.domain_id > 232 {
            return Err(invalid(
                "ros.domain_id",
                format!("{} is outside 0..=232", self.domain_id),
            ));
        }
        if !self.namespace.is_empty() {
            topic_name(&self.namespace, "ros.namespace")?;
        }
        for (list, name) in [(&self.connect, "connect"), (&self.listen, "listen")] {
            for (i, e) in list.iter().enumerate() {
                crate::endpoint::check(e, name == "connect").map_err(|why| {
                    invalid(
                        format!("ros.{name}[{i}]"),
                        format!("{e:?}: {why} (a Zenoh endpoint is like tcp/127.0.0.1:7447)"),
                    )
                })?;
            }
        }
        crate::ros_tls::validate(self)?;
        let r = self.live.rate_hz;
        if !r.is_finite() || r <= 0.0 || r > rate_hz {
            return Err(invalid(
                "ros.live.rate_hz",
                format!("{} Hz is outside (0, {rate_hz}] (the loop's rate)", Num(r)),
            ));
        }
        Ok(())
    }
}

impl RosDeviceConfig {
    /// True if the device sends more than a position: an orientation or a clutch.
    pub fn six_dof(&self) -> bool {
        self.input == HandInput::Pose || self.gimbal.is_some() || self.clutch != ClutchConfig::None
    }

    /// Checks the ranges; errors name `master.ros2.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        topic_name(&self.joint_states, "master.ros2.joint_states")?;
        joint_names(&self.joints, "master.ros2.joints")?;
        self.map.validate("master.ros2.map")?;
        topic_name(&self.force_topic, "master.ros2.force_topic")?;
        self.force_map.validate("master.ros2.force_map")?;
        if !self.ramp_s.is_finite() || !(0.0..=10.0).contains(&self.ramp_s) {
            return Err(invalid(
                "master.ros2.ramp_s",
                format!("{} s is outside 0 to 10 s", Num(self.ramp_s)),
            ));
        }
        positive(self.max_force_rate, "master.ros2.max_force_rate", false)?;
        crate::hand::validate(
            self.input,
            &self.pose_topic,
            self.gimbal.as_ref(),
            &self.clutch,
            topic_name,
        )?;
        self.watch.validate("master.ros2.watch")
    }
}

#[cfg(test)]
#[path = "ros_tests.rs"]
mod tests;
