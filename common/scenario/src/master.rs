//! `[master]` and `[faults]`: the master device's limits, the operator's hand, the
//! master device's joints, and how a dead peer is noticed.

use crate::human::HumanConfig;
use crate::shown::Num;
use crate::{
    invalid, positive, positive3, Backend, PredictorConfig, RosDeviceConfig, ScenarioError,
};
use serde::{Deserialize, Serialize};

/// The master device's limits (PHANToM Omni class by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MasterConfig {
    /// Largest force the operator is made to feel, N (the Omni: ~3.3 N): one number,
    /// each axis's force clamped to it (unlike `torque_limit`, one per joint).
    pub force_limit: f64,
    /// Largest torque commanded on a master joint, N m.
    pub torque_limit: [f64; 3],
    /// How the operator's hand holds the handle.
    pub hand: HandConfig,
    /// The master device's joints (used with an impedance hand).
    pub device: MasterDeviceConfig,
    /// How the master fills forces not received (CPD/JPD-HMD).
    pub predictor: PredictorConfig,
    /// `simulated` (the hand and device above) or `ros2` (a device through its ROS 2
    /// driver, `[master.ros2]`).
    pub backend: Backend,
    /// The ROS 2 device, with `backend = "ros2"`.
    pub ros2: RosDeviceConfig,
    /// While the operator's clutch is released the robot holds and the handle moves
    /// freely: no force, or with this stiffness, N/m, a spring pulling the handle back
    /// towards the device's home (the middle of its workspace, or where a pose device
    /// started), so the next stroke starts there.
    pub clutch_spring: f64,
    /// Seconds over which a force the master switches on takes over from the force
    /// felt before it: the clutch's spring at a release, the robot's force at an
    /// engage, the loop's force when answers come back after the loop broke. A switch
    /// at full strength stepped the operator's hand by the whole force (3 N at a
    /// release of `panda-reach.toml`'s clutch); over 0.1 s the Omni's 3.3 N changes at
    /// 33 N/s at most, well inside the device's force rate (1000 N/s), yet quicker than
    /// a hand reacts (about 0.15 s). 0 switches at once. The loop breaking renders zero
    /// force at once: rendering nothing is the safe state.
    pub switch_ramp_s: f64,
    /// The simulated operator's tremor, wander and reaction to a felt force
    /// (`[master.human]`, off by default).
    pub human: HumanConfig,
}

impl Default for MasterConfig {
    fn default() -> Self {
        MasterConfig {
            force_limit: 3.3,
            torque_limit: [0.45; 3],
            hand: HandConfig::default(),
            device: MasterDeviceConfig::default(),
            predictor: PredictorConfig::default(),
            backend: Backend::default(),
            ros2: RosDeviceConfig::default(),
            clutch_spring: 0.0,
            switch_ramp_s: 0.1,
            human: HumanConfig::default(),
        }
    }
}

/// How the processes notice a dead peer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FaultConfig {
    /// Consecutive samples without an answer after which the master declares the loop
    /// broken, commands zero torque and marks the samples; and without input after
    /// which the slave holds its position.
    pub peer_timeout_samples: u64,
}

impl Default for FaultConfig {
    fn default() -> Self {
        FaultConfig {
            peer_timeout_samples: 10,
        }
    }
}

/// How the hand moves the master handle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum HandMode {
    /// An ideal hand: the handle is exactly where the trajectory says, whatever the
    /// motors push (the paper's validation; forces are computed and drive nothing).
    #[default]
    Position,
    /// A hand of mass, damping and stiffness that follows the trajectory and holds the
    /// handle; the master's joints move under the hand's force and the motor torques,
    /// so the force fed back moves the handle and delay can destabilise the loop.
    Impedance,
}

/// The operator's hand. Defaults from identifications of a hand holding a stylus or
/// knob in a pinch grasp: Hasser and Cutkosky, "System identification of the human
/// hand grasping a haptic knob", IEEE Haptics Symposium 2002; Speich, Shao and
/// Goldfarb, "Modeling the human hand as it interacts with a telemanipulation
/// system", Mechatronics 15(9), 2005. They report masses of a few hundred grams,
/// damping of a few N s/m and stiffness of a few hundred N/m rising with grip force;
/// the defaults sit in the middle of those ranges (a relaxed grasp, the case where a
/// delayed stiff contact is hardest to keep stable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HandConfig {
    /// `position` (ideal, the default) or `impedance`.
    pub mode: HandMode,
    /// Mass of the hand moving with the handle, kg.
    pub mass: f64,
    /// Damping between the hand and its intended motion, N s/m.
    pub damping: f64,
    /// Stiffness pulling the handle towards the intended position, N/m.
    pub stiffness: f64,
    /// Seconds over which the hand's target blends, along a minimum-jerk path, from
    /// where the handle starts (the devices' home, joints at zero) into the
    /// trajectory, under either hand mode, so a trajectory that starts elsewhere does
    /// not command its whole distance from home in the first sample (a circle 3.6 cm
    /// away did, saturating the slave). 0 turns it off. No effect when the
    /// trajectory's first target is exactly home (the paper's path), which therefore
    /// runs as it always has. The default, 1 s, takes a few centimetres at a peak of
    /// a few cm/s, a calm reach for a hand; longer reaches deserve a longer blend.
    pub approach_s: f64,
}

impl Default for HandConfig {
    fn default() -> Self {
        HandConfig {
            mode: HandMode::Position,
            mass: 0.2,
            damping: 4.0,
            stiffness: 250.0,
            approach_s: 1.0,
        }
    }
}

/// The master device's joints (PHANToM Omni class): about 45 g apparent mass at the
/// tip of a 0.13 m arm gives joint inertias near 8e-4 kg m^2; small viscous damping and
/// Coulomb friction of a few mN m (about 0.03 N at the tip).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MasterDeviceConfig {
    /// Inertia per joint, kg m^2.
    pub inertia: [f64; 3],
    /// Viscous damping per joint, N m s / rad.
    pub damping: [f64; 3],
    /// Coulomb friction per joint, N m (smoothed near zero velocity).
    pub friction: [f64; 3],
    /// Integration step, seconds, at most 0.01.
    pub step_s: f64,
}

impl Default for MasterDeviceConfig {
    fn default() -> Self {
        MasterDeviceConfig {
            inertia: [8.0e-4; 3],
            damping: [2.0e-4; 3],
            friction: [4.0e-3; 3],
            step_s: 2.5e-4,
        }
    }
}

impl HandConfig {
    /// Checks the ranges; errors name `master.hand.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        positive(self.mass, "master.hand.mass", false)?;
        positive(self.damping, "master.hand.damping", true)?;
        positive(self.stiffness, "master.hand.stiffness", true)?;
        positive(self.approach_s, "master.hand.approach_s", true)
    }
}

impl MasterDeviceConfig {
    /// Checks the ranges; errors name `master.device.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        positive3(&self.inertia, "master.device.inertia", false)?;
        positive3(&self.damping, "master.device.damping", true)?;
        positive3(&self.friction, "master.device.friction", true)?;
        // At least 1 us (a sample never needs more than 10,000 steps), at most 1 ms:
        // the smoothed friction's slope over the smallest default inertia needs
        // steps under 2 ms for explicit integration to stay stable.
        if !self.step_s.is_finite() || self.step_s < 1e-6 || self.step_s > 1e-3 {
            return Err(invalid(
                "master.device.step_s",
                format!("{} s is outside 1 us to 1 ms", Num(self.step_s)),
            ));
        }
        Ok(())
    }
}

impl MasterConfig {
    /// Checks the ranges; errors name `master.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if !self.force_limit.is_finite() || self.force_limit <= 0.0 {
            return Err(invalid(
                "master.force_limit",
                format!("{} N must be positive", Num(self.force_limit)),
            ));
        }
        positive3(&self.torque_limit, "master.torque_limit", false)?;
        self.hand.validate()?;
        self.device.validate()?;
        self.predictor.validate("master.predictor")?;
        positive(self.clutch_spring, "master.clutch_spring", true)?;
        if self.clutch_spring > 1000.0 {
            return Err(invalid(
                "master.clutch_spring",
                format!(
                    "{} N/m is stiffer than a desk device renders (1000 N/m)",
                    Num(self.clutch_spring)
                ),
            ));
        }
        if !self.switch_ramp_s.is_finite() || !(0.0..=10.0).contains(&self.switch_ramp_s) {
            return Err(invalid(
                "master.switch_ramp_s",
                format!("{} s is outside 0 to 10 s", Num(self.switch_ramp_s)),
            ));
        }
        self.ros2.validate()
    }
}
