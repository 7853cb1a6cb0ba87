//! Scenario types of the bilateral loop: how the operator's hand holds the master
//! (`[master.hand]`), the master device's joints (`[master.device]`) and the stability
//! control on the channel (`[control]`). Validated like the rest of the scenario: an
//! error names the dotted field.

use crate::scenario::{invalid, positive3, ScenarioError};
use serde::{Deserialize, Serialize};

fn positive(v: f64, field: &str, zero_ok: bool) -> Result<(), ScenarioError> {
    if !v.is_finite() || v < 0.0 || (!zero_ok && v == 0.0) {
        let want = if zero_ok { "non-negative" } else { "positive" };
        return Err(invalid(field, format!("{v} must be finite and {want}")));
    }
    Ok(())
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
#[serde(deny_unknown_fields)]
pub struct HandConfig {
    /// `position` (ideal, the default) or `impedance`.
    #[serde(default)]
    pub mode: HandMode,
    /// Mass of the hand moving with the handle, kg.
    #[serde(default = "default_hand_mass")]
    pub mass: f64,
    /// Damping between the hand and its intended motion, N s/m.
    #[serde(default = "default_hand_damping")]
    pub damping: f64,
    /// Stiffness pulling the handle towards the intended position, N/m.
    #[serde(default = "default_hand_stiffness")]
    pub stiffness: f64,
    /// Seconds over which the intended position blends from where the handle starts
    /// (the devices' home) into the trajectory, so a trajectory that starts elsewhere
    /// does not yank the handle. No effect when the trajectory starts at home.
    #[serde(default = "default_approach")]
    pub approach_s: f64,
}

fn default_hand_mass() -> f64 {
    0.2
}
fn default_hand_damping() -> f64 {
    4.0
}
fn default_hand_stiffness() -> f64 {
    250.0
}
fn default_approach() -> f64 {
    1.0
}

impl Default for HandConfig {
    fn default() -> Self {
        HandConfig {
            mode: HandMode::Position,
            mass: default_hand_mass(),
            damping: default_hand_damping(),
            stiffness: default_hand_stiffness(),
            approach_s: default_approach(),
        }
    }
}

/// The master device's joints (PHANToM Omni class): about 45 g apparent mass at the
/// tip of a 0.13 m arm gives joint inertias near 8e-4 kg m^2; small viscous damping and
/// Coulomb friction of a few mN m (about 0.03 N at the tip).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MasterDeviceConfig {
    /// Inertia per joint, kg m^2.
    #[serde(default = "default_md_inertia")]
    pub inertia: [f64; 3],
    /// Viscous damping per joint, N m s / rad.
    #[serde(default = "default_md_damping")]
    pub damping: [f64; 3],
    /// Coulomb friction per joint, N m (smoothed near zero velocity).
    #[serde(default = "default_md_friction")]
    pub friction: [f64; 3],
    /// Integration step, seconds, at most 0.01.
    #[serde(default = "default_md_step")]
    pub step_s: f64,
}

fn default_md_inertia() -> [f64; 3] {
    [8.0e-4; 3]
}
fn default_md_damping() -> [f64; 3] {
    [2.0e-4; 3]
}
fn default_md_friction() -> [f64; 3] {
    [4.0e-3; 3]
}
fn default_md_step() -> f64 {
    2.5e-4
}

impl Default for MasterDeviceConfig {
    fn default() -> Self {
        MasterDeviceConfig {
            inertia: default_md_inertia(),
            damping: default_md_damping(),
            friction: default_md_friction(),
            step_s: default_md_step(),
        }
    }
}

/// Stability control on the channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ControlKind {
    /// Positions forward, forces back, nothing else (observers still watch).
    #[default]
    None,
    /// Time-domain passivity approach, two-port, position-force architecture.
    Tdpa,
    /// Wave variables with an impedance-matched slave.
    Wave,
}

impl ControlKind {
    /// The name used in scenarios and reports.
    pub fn name(self) -> &'static str {
        match self {
            ControlKind::None => "none",
            ControlKind::Tdpa => "tdpa",
            ControlKind::Wave => "wave",
        }
    }
}

/// `[control]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlConfig {
    /// `none`, `tdpa` or `wave`.
    #[serde(default)]
    pub kind: ControlKind,
    /// Wave impedance b, N s/m: larger feels stiffer contact and more damping in free
    /// motion.
    #[serde(default = "default_wave_impedance")]
    pub wave_impedance: f64,
    /// TDPA: speeds below this count as this when the master's passivity controller
    /// computes its damping (v^2 in a denominator), m/s.
    #[serde(default = "default_velocity_floor")]
    pub velocity_floor: f64,
    /// TDPA: the largest damping the master's passivity controller adds, N s/m; a
    /// deficit it cannot remove at once is carried to the next samples.
    #[serde(default = "default_max_damping")]
    pub max_damping: f64,
    /// TDPA: the fastest the slave's reference is pulled back towards the master's
    /// position when energy allows (position drift compensation), m/s; 0 disables it.
    #[serde(default = "default_drift_rate")]
    pub drift_rate: f64,
}

fn default_wave_impedance() -> f64 {
    10.0
}
// Measured on wall-delay over floors 1e-5..1e-3 m/s and caps 200..1e4 N s/m: these
// kept the channel's energy closest to zero without a codec (README). Larger caps make
// the force chatter between full and zero, and the sampling's prediction error grows.
fn default_velocity_floor() -> f64 {
    1.0e-3
}
fn default_max_damping() -> f64 {
    200.0
}
fn default_drift_rate() -> f64 {
    0.05
}

impl Default for ControlConfig {
    fn default() -> Self {
        ControlConfig {
            kind: ControlKind::None,
            wave_impedance: default_wave_impedance(),
            velocity_floor: default_velocity_floor(),
            max_damping: default_max_damping(),
            drift_rate: default_drift_rate(),
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
                format!("{} s is outside 1 us to 1 ms", self.step_s),
            ));
        }
        Ok(())
    }
}

impl ControlConfig {
    /// Checks the ranges; errors name `control.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        positive(self.wave_impedance, "control.wave_impedance", false)?;
        positive(self.velocity_floor, "control.velocity_floor", false)?;
        positive(self.max_damping, "control.max_damping", false)?;
        positive(self.drift_rate, "control.drift_rate", true)
    }
}
