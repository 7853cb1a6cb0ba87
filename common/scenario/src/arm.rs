//! `[slave.arm]`: the slave as any serial arm from its URDF, simulated (its rigid-body
//! dynamics from the URDF's inertias, a joint-space PD with gravity compensation, the
//! IK of `tactile-chain`). Without this table the slave is the paper's 3-DoF arm with
//! its closed-form kernels.
//!
//! The loop still carries positions in the master's frame: the arm's tool target is its
//! home pose moved by `scale` times the master's displacement from the paper arm's
//! home, the orientation held at home; the environment is evaluated at the arm's tool
//! mapped back into the master's frame, so a scenario's objects and stiffnesses keep
//! their meaning whatever the arm.

use crate::shown::Num;
use crate::workspace::{self, apply, apply_transpose, FrameRotation, Scale, Workspace};
use crate::{invalid, positive, ScenarioError};
use serde::{Deserialize, Serialize};

/// The slave arm from a URDF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmConfig {
    /// The URDF file (relative to the scenario's folder).
    pub urdf: String,
    /// The link poses are given in (the arm's base).
    pub base: String,
    /// The link the IK moves (the tool).
    pub tip: String,
    /// Joint values at the start, one per degree of freedom in chain order, rad or m.
    pub home: Vec<f64>,
    /// Proportional gains of the joint PD, one per degree of freedom, N m/rad.
    pub kp: Vec<f64>,
    /// Derivative gains, one per degree of freedom, N m s/rad.
    pub kd: Vec<f64>,
    /// Metres the arm's tool moves per metre of the master's: one number, or one per
    /// axis of the arm's base frame.
    #[serde(default)]
    pub scale: Scale,
    /// The master's base frame in the arm's (`{ rpy_deg = [r, p, y] }` or `{ quaternion
    /// = [x, y, z, w] }`): the master's displacements and turns are rotated by it on the
    /// way out, the force back by its inverse. None by default.
    #[serde(default)]
    pub rotation: FrameRotation,
    /// The box of the base frame the tool may be sent into (`{ min = [..], max = [..] }`,
    /// m): a target outside is clamped onto it and counted. None by default.
    #[serde(default)]
    pub workspace: Option<Workspace>,
    /// Newtons the operator feels per newton at the robot's tool.
    #[serde(default = "one")]
    pub force_scale: f64,
    /// Integration step of the arm's dynamics, s (at most 10 ms).
    #[serde(default = "step")]
    pub step_s: f64,
    /// Gravity in the base frame, m/s^2.
    #[serde(default = "gravity")]
    pub gravity: [f64; 3],
    /// The IK's settings.
    #[serde(default)]
    pub ik: ArmIkConfig,
    /// How the simulated arm's joints are driven: `joint` (a PD on the IK's joint
    /// references with gravity compensation) or `cartesian` (an impedance at the tool).
    #[serde(default)]
    pub servo: ArmServo,
    /// The Cartesian impedance's settings (`servo = "cartesian"`).
    #[serde(default)]
    pub cartesian: CartesianConfig,
}

/// The simulated arm's servo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ArmServo {
    /// A joint-space PD on the IK's references (`kp`, `kd`), gravity compensated:
    /// what a position-controlled arm (UR, a joint_trajectory_controller) does.
    #[default]
    Joint,
    /// A Cartesian impedance at the tool, `tau = J^T (K e - D v) + g` and a
    /// null-space PD toward the IK's references: what franka_ros'
    /// cartesian_impedance_example_controller does.
    Cartesian,
}

/// A Cartesian impedance at the tool, in the base frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CartesianConfig {
    /// Translational stiffness, N/m, then rotational, N m/rad (x, y, z each).
    pub stiffness: [f64; 6],
    /// Damping, N s/m and N m s/rad; default `2 sqrt(stiffness)` (critical for a unit
    /// mass, as franka_ros' example).
    pub damping: Option<[f64; 6]>,
    /// The null space's stiffness toward the IK's references, N m/rad (damped
    /// critically for a unit inertia).
    pub nullspace_stiffness: f64,
}

impl Default for CartesianConfig {
    fn default() -> Self {
        CartesianConfig {
            stiffness: [3000.0, 3000.0, 3000.0, 300.0, 300.0, 300.0],
            damping: None,
            nullspace_stiffness: 10.0,
        }
    }
}

impl CartesianConfig {
    /// The damping in use.
    pub fn damping(&self) -> [f64; 6] {
        self.damping
            .unwrap_or_else(|| self.stiffness.map(|k| 2.0 * k.sqrt()))
    }

    fn validate(&self) -> Result<(), ScenarioError> {
        for (i, k) in self.stiffness.iter().enumerate() {
            positive(*k, &format!("slave.arm.cartesian.stiffness[{i}]"), false)?;
        }
        for (i, d) in self.damping.iter().flatten().enumerate() {
            positive(*d, &format!("slave.arm.cartesian.damping[{i}]"), true)?;
        }
        positive(
            self.nullspace_stiffness,
            "slave.arm.cartesian.nullspace_stiffness",
            true,
        )
    }
}

fn one() -> f64 {
    1.0
}
fn step() -> f64 {
    2.5e-4
}
fn gravity() -> [f64; 3] {
    [0.0, 0.0, -9.81]
}

/// The IK's settings (`tactile_chain::IkConfig`), each with its default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArmIkConfig {
    /// Newton steps per sample at most.
    pub max_iterations: u32,
    /// Metres an orientation error of one radian weighs against a position error.
    pub orientation_weight: f64,
    /// The largest damping, reached at a singularity (weighted units, m).
    pub damping_max: f64,
    /// Smallest singular value below which the damping starts (weighted units, m).
    pub singular_threshold: f64,
    /// Fraction of the gap to the home posture closed per sample in the null space
    /// (redundant arms).
    pub posture_gain: f64,
    /// Fraction of each URDF velocity limit the reference may use.
    pub velocity_scale: f64,
}

impl Default for ArmIkConfig {
    fn default() -> Self {
        ArmIkConfig {
            max_iterations: 4,
            orientation_weight: 0.1,
            damping_max: 0.04,
            singular_threshold: 0.02,
            posture_gain: 0.02,
            velocity_scale: 1.0,
        }
    }
}

impl ArmConfig {
    /// Where the tool goes in the arm's base frame for the master's `position`: the
    /// master's displacement from `master_home`, rotated into the arm's axes and
    /// scaled, from the tool's home `home_tool`. The loop's one map from the master's
    /// workspace to the arm's; [`ArmConfig::to_master`] undoes it. The workspace box is
    /// applied by the arm after the clutch's offsets ([`ArmConfig::clamp`]).
    pub fn to_robot(
        &self,
        home_tool: [f64; 3],
        master_home: [f64; 3],
        position: [f64; 3],
    ) -> [f64; 3] {
        let d = self.rotate([0, 1, 2].map(|k| position[k] - master_home[k]));
        let s = self.scale.axes();
        [0, 1, 2].map(|k| home_tool[k] + s[k] * d[k])
    }

    /// The master's position for the tool at `p` in the arm's base frame.
    pub fn to_master(&self, home_tool: [f64; 3], master_home: [f64; 3], p: [f64; 3]) -> [f64; 3] {
        let s = self.scale.axes();
        let d = self.rotate_back([0, 1, 2].map(|k| (p[k] - home_tool[k]) / s[k]));
        [0, 1, 2].map(|k| master_home[k] + d[k])
    }

    /// A displacement `d` in the base frame (a clutch's offset) as one in the
    /// master's frame: the map's linear part, undone.
    pub fn shift_to_master(&self, d: [f64; 3]) -> [f64; 3] {
        self.to_master([0.0; 3], [0.0; 3], d)
    }

    /// A force or torque at the arm's tool, in its base's axes, as the operator is
    /// made to feel it: rotated into the master's axes and scaled by `force_scale`.
    pub fn force_to_master(&self, f: [f64; 3]) -> [f64; 3] {
        self.rotate_back(f).map(|v| self.force_scale * v)
    }

    /// A force in the master's axes (the environment's, evaluated there) as it acts on
    /// the arm's tool, in the base's axes.
    pub fn force_to_robot(&self, f: [f64; 3]) -> [f64; 3] {
        self.rotate(f)
    }

    /// A vector of the master's axes in the base's (untouched, signs of zero and all,
    /// without a rotation).
    fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        match self.rotation.is_identity() {
            true => v,
            false => apply(&self.rotation.matrix(), v),
        }
    }

    /// A vector of the base's axes in the master's.
    fn rotate_back(&self, v: [f64; 3]) -> [f64; 3] {
        match self.rotation.is_identity() {
            true => v,
            false => apply_transpose(&self.rotation.matrix(), v),
        }
    }

    /// A point of the base frame clamped into the workspace box, and whether it had to
    /// be (never, without a box).
    pub fn clamp(&self, p: [f64; 3]) -> ([f64; 3], bool) {
        match &self.workspace {
            Some(w) => w.clamp(p),
            None => (p, false),
        }
    }

    /// Checks what can be checked without the URDF; the lengths of `home`, `kp` and
    /// `kd` against the chain's degrees of freedom are checked where the URDF is read.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        for (field, v) in [
            ("urdf", &self.urdf),
            ("base", &self.base),
            ("tip", &self.tip),
        ] {
            if v.trim().is_empty() {
                return Err(invalid(format!("slave.arm.{field}"), "must not be empty"));
            }
        }
        for (field, v) in [("home", &self.home), ("kp", &self.kp), ("kd", &self.kd)] {
            if v.is_empty() || v.len() > MAX_ARM_DOF {
                return Err(invalid(
                    format!("slave.arm.{field}"),
                    format!(
                        "has {} values; it takes one per joint (1 to {MAX_ARM_DOF})",
                        v.len()
                    ),
                ));
            }
        }
        for (i, x) in self.home.iter().enumerate() {
            if !x.is_finite() {
                return Err(invalid(
                    format!("slave.arm.home[{i}]"),
                    format!("{x} is not a finite number"),
                ));
            }
        }
        for (field, v, zero_ok) in [("kp", &self.kp, false), ("kd", &self.kd, true)] {
            for (i, x) in v.iter().enumerate() {
                positive(*x, &format!("slave.arm.{field}[{i}]"), zero_ok)?;
            }
        }
        workspace::validate(
            &self.scale,
            &self.rotation,
            self.workspace.as_ref(),
            self.force_scale,
        )?;
        if !self.step_s.is_finite() || self.step_s < 1e-6 || self.step_s > 0.01 {
            return Err(invalid(
                "slave.arm.step_s",
                format!("{} s is outside 1 us to 10 ms", Num(self.step_s)),
            ));
        }
        for (i, g) in self.gravity.iter().enumerate() {
            if !g.is_finite() || g.abs() > 100.0 {
                return Err(invalid(
                    format!("slave.arm.gravity[{i}]"),
                    format!("{} m/s^2 is not a finite number within 100", Num(*g)),
                ));
            }
        }
        self.cartesian.validate()?;
        self.ik.validate()
    }
}

/// The most degrees of freedom an arm may have (a record holds its joints whole).
pub const MAX_ARM_DOF: usize = 16;

impl ArmIkConfig {
    fn validate(&self) -> Result<(), ScenarioError> {
        if !(1..=50).contains(&self.max_iterations) {
            return Err(invalid(
                "slave.arm.ik.max_iterations",
                format!("{} is outside 1..=50", self.max_iterations),
            ));
        }
        positive(
            self.orientation_weight,
            "slave.arm.ik.orientation_weight",
            false,
        )?;
        positive(self.damping_max, "slave.arm.ik.damping_max", false)?;
        positive(
            self.singular_threshold,
            "slave.arm.ik.singular_threshold",
            false,
        )?;
        positive(self.posture_gain, "slave.arm.ik.posture_gain", true)?;
        if self.posture_gain > 1.0 {
            return Err(invalid("slave.arm.ik.posture_gain", "must be at most 1"));
        }
        if !(self.velocity_scale > 0.0 && self.velocity_scale <= 1.0) {
            return Err(invalid(
                "slave.arm.ik.velocity_scale",
                format!("{} is outside (0, 1]", Num(self.velocity_scale)),
            ));
        }
        Ok(())
    }
}
