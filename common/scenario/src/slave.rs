//! `[slave]` and `[environment]`: the slave's joint controller and dynamics, and the
//! objects the tool can touch.

use crate::shown::Num;
use crate::world::{
    is_default, BodyConfig, Engine, JointConfig, SolverConfig, ToolConfig, WorldBounds,
};
use crate::{finite3, invalid, positive3, ScenarioError};
use crate::{ArmConfig, Backend, PredictorConfig, RosRobotConfig};
use serde::{Deserialize, Serialize};

/// The slave side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct SlaveConfig {
    /// Joint controller.
    pub controller: ControllerConfig,
    /// Joint dynamics of the slave device.
    pub dynamics: DynamicsConfig,
    /// How the slave fills positions not received (CPD-HSD).
    pub predictor: PredictorConfig,
    /// `simulated` (the arm and environment model) or `ros2` (a robot through
    /// ros2_control, `[slave.ros2]`).
    pub backend: Backend,
    /// The ROS 2 robot, with `backend = "ros2"`.
    pub ros2: RosRobotConfig,
    /// Any serial arm from its URDF, simulated, in place of the paper's arm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arm: Option<ArmConfig>,
}

/// PD or PID per joint: u = kp e + ki integral(e) + kd de/dt, clamped to the limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControllerConfig {
    /// Proportional gains, N m / rad.
    pub kp: [f64; 3],
    /// Integral gains, N m / (rad s); zero gives PD.
    pub ki: [f64; 3],
    /// Derivative gains, N m s / rad.
    pub kd: [f64; 3],
    /// Torque limit per joint, N m (the Omni's 3.3 N at its 0.132 m arm: ~0.44 N m).
    pub torque_limit: [f64; 3],
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig {
            kp: [6.0; 3],
            ki: [0.0; 3],
            kd: [0.12; 3],
            torque_limit: [0.45; 3],
        }
    }
}

/// Per-joint inertia and viscous damping, integrated at a fixed step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DynamicsConfig {
    /// Inertia per joint, kg m^2.
    pub inertia: [f64; 3],
    /// Viscous damping per joint, N m s / rad.
    pub damping: [f64; 3],
    /// Integration step, seconds, at most 0.01; each sample integrates t_s in steps of
    /// at most this (one step of t_s when t_s is shorter).
    pub step_s: f64,
}

impl Default for DynamicsConfig {
    fn default() -> Self {
        DynamicsConfig {
            inertia: [2.0e-3; 3],
            damping: [5.0e-3; 3],
            step_s: 2.5e-4,
        }
    }
}

/// The slave's environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Environment {
    /// Objects; the one the tool penetrates most deeply produces the contact force.
    pub objects: Vec<Object>,
    /// `[[environment.changes]]`: objects that move or change stiffness during the run
    /// (a wall pushed 1 cm, a material that hardens), in any order.
    pub changes: Vec<Change>,
    /// `analytic` (the springs of `objects`, the default) or `physics` (the rigid
    /// bodies below, docs/16). The keys below belong to `physics`; each is written
    /// back only when it is not its default, so an analytic scenario reads and writes
    /// as it always did.
    #[serde(skip_serializing_if = "is_default")]
    pub engine: Engine,
    /// Gravity, m/s^2 (physics only; default `[0, 0, -9.81]`).
    #[serde(skip_serializing_if = "is_default_gravity")]
    pub gravity: [f64; 3],
    /// Whole physics steps (collision detection, the coupling, the solver) per sample
    /// of the loop, 1 to 64 (default 1: the solver already takes
    /// `solver.iterations` substeps of its own inside each step).
    #[serde(skip_serializing_if = "is_default_substeps")]
    pub substeps: u32,
    /// The world's box: a dynamic body leaving it is an event.
    #[serde(skip_serializing_if = "is_default")]
    pub bounds: WorldBounds,
    /// The contact solver's settings.
    #[serde(skip_serializing_if = "is_default")]
    pub solver: SolverConfig,
    /// `[[environment.bodies]]`: the world's bodies.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<BodyConfig>,
    /// `[[environment.joints]]`: revolute and prismatic joints between bodies.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<JointConfig>,
    /// `[environment.tool]`: the tool body and its coupling to the arm.
    #[serde(skip_serializing_if = "is_default")]
    pub tool: ToolConfig,
}

/// Gravity of a physics world unless told: the Earth's, along -z.
pub const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];
/// Substeps per sample unless told.
pub const SUBSTEPS: u32 = 1;

fn is_default_gravity(g: &[f64; 3]) -> bool {
    *g == GRAVITY
}

fn is_default_substeps(n: &u32) -> bool {
    *n == SUBSTEPS
}

impl Default for Environment {
    fn default() -> Self {
        Environment {
            objects: Vec::new(),
            changes: Vec::new(),
            engine: Engine::default(),
            gravity: GRAVITY,
            substeps: SUBSTEPS,
            bounds: WorldBounds::default(),
            solver: SolverConfig::default(),
            bodies: Vec::new(),
            joints: Vec::new(),
            tool: ToolConfig::default(),
        }
    }
}

/// A change to one object at one moment of the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Change {
    /// When, s from the start: the change holds from the first sample n with
    /// `n t_s >= at_s`.
    pub at_s: f64,
    /// Which object (its index in `objects`).
    pub object: usize,
    /// Moved by this, m (its point or centre).
    pub move_by: [f64; 3],
    /// Its stiffness per axis from then on, N/m (unchanged when left out).
    pub stiffness: Option<[f64; 3]>,
}

impl Change {
    /// The first sample n the change holds from: `n t_s >= at_s` (a nanosecond's
    /// slack, so `at_s = 0.3` at 100 Hz is sample 30, not 31).
    pub fn first_sample(&self, t_s: f64) -> u64 {
        (self.at_s / t_s - 1e-9).ceil().max(0.0) as u64
    }
}

impl Environment {
    /// The changes as the slave applies them, each with its index in `changes` and
    /// the first sample it holds from: by that sample, changes at one sample in the
    /// file's order (a stable sort).
    pub fn changes_in_order(&self, t_s: f64) -> Vec<(usize, u64, &Change)> {
        let mut v: Vec<(usize, u64, &Change)> = self
            .changes
            .iter()
            .enumerate()
            .map(|(k, c)| (k, c.first_sample(t_s), c))
            .collect();
        v.sort_by_key(|(_, n, _)| *n);
        v
    }
}

impl Object {
    /// What places the object, by the name its field has (`point` of a plane,
    /// `center` of a sphere or a box), and its value.
    pub fn position(&self) -> (&'static str, [f64; 3]) {
        match self {
            Object::Plane { point, .. } => ("point", *point),
            Object::Sphere { center, .. } | Object::Box { center, .. } => ("center", *center),
        }
    }

    /// The object after `c`: moved, and with the new stiffness if it gives one.
    pub fn changed(&self, c: &Change) -> Object {
        let moved = |p: &[f64; 3]| std::array::from_fn(|i| p[i] + c.move_by[i]);
        let k = |s: &[f64; 3]| c.stiffness.unwrap_or(*s);
        match self {
            Object::Plane {
                point,
                normal,
                stiffness,
            } => Object::Plane {
                point: moved(point),
                normal: *normal,
                stiffness: k(stiffness),
            },
            Object::Sphere {
                center,
                radius,
                stiffness,
            } => Object::Sphere {
                center: moved(center),
                radius: *radius,
                stiffness: k(stiffness),
            },
            Object::Box {
                center,
                half_extents,
                stiffness,
            } => Object::Box {
                center: moved(center),
                half_extents: *half_extents,
                stiffness: k(stiffness),
            },
        }
    }
}

/// A rigid object with a stiffness per axis (the paper's h_x, h_y, h_z).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Object {
    /// Half-space behind a plane: contact when (p - point) . normal < 0.
    Plane {
        /// A point on the plane, metres.
        point: [f64; 3],
        /// Outward normal (normalised on load).
        normal: [f64; 3],
        /// Stiffness per axis, N/m.
        stiffness: [f64; 3],
    },
    /// Solid sphere.
    Sphere {
        /// Centre, metres.
        center: [f64; 3],
        /// Radius, metres.
        radius: f64,
        /// Stiffness per axis, N/m.
        stiffness: [f64; 3],
    },
    /// Solid axis-aligned box.
    Box {
        /// Centre, metres.
        center: [f64; 3],
        /// Half extents along x, y, z, metres.
        half_extents: [f64; 3],
        /// Stiffness per axis, N/m.
        stiffness: [f64; 3],
    },
}

/// The PHANToM Omni's nominal maximum stiffness, N/m (0.7 N/mm): above it a scenario
/// loads with a warning (the device cannot render it without buzzing).
pub const NOMINAL_MAX_STIFFNESS: f64 = 700.0;
/// Stiffness refused outright, N/m: ten times the nominal maximum.
pub const MAX_STIFFNESS: f64 = 10.0 * NOMINAL_MAX_STIFFNESS;

impl Object {
    /// Stiffness per axis.
    pub fn stiffness(&self) -> [f64; 3] {
        match self {
            Object::Plane { stiffness, .. }
            | Object::Sphere { stiffness, .. }
            | Object::Box { stiffness, .. } => *stiffness,
        }
    }
}

impl SlaveConfig {
    /// Checks the ranges; errors name `slave.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let c = &self.controller;
        positive3(&c.kp, "slave.controller.kp", true)?;
        positive3(&c.ki, "slave.controller.ki", true)?;
        positive3(&c.kd, "slave.controller.kd", true)?;
        positive3(&c.torque_limit, "slave.controller.torque_limit", false)?;
        let d = &self.dynamics;
        positive3(&d.inertia, "slave.dynamics.inertia", false)?;
        positive3(&d.damping, "slave.dynamics.damping", true)?;
        // A sample shorter than the step is integrated in one step of t_s; a step
        // longer than 10 ms makes the default joints' integration unstable.
        if !d.step_s.is_finite() || d.step_s < 1e-6 || d.step_s > 0.01 {
            return Err(invalid(
                "slave.dynamics.step_s",
                format!("{} s is outside 1 us to 10 ms", Num(d.step_s)),
            ));
        }
        self.predictor.validate("slave.predictor")?;
        if let Some(arm) = &self.arm {
            arm.validate()?;
        }
        self.ros2.validate(self.arm.is_some())
    }
}

impl Environment {
    /// Checks every object and change, and the physics world's keys with the task
    /// that names its bodies; errors name `environment.objects[k].*`,
    /// `environment.changes[k].*`, `environment.bodies[k].*` and `task.*`.
    pub fn validate_with(&self, task: Option<&crate::TaskConfig>) -> Result<(), ScenarioError> {
        self.validate()?;
        self.validate_physics(task)
    }

    /// Checks every object and change; errors name `environment.objects[k].*` and
    /// `environment.changes[k].*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        for (k, c) in self.changes.iter().enumerate() {
            self.validate_change(k, c)?;
        }
        for (k, o) in self.objects.iter().enumerate() {
            let f = format!("environment.objects[{k}]");
            positive3(&o.stiffness(), &format!("{f}.stiffness"), true)?;
            for (i, h) in o.stiffness().iter().enumerate() {
                if *h > MAX_STIFFNESS {
                    return Err(invalid(
                    format!("{f}.stiffness[{i}]"),
                    format!(
                        "{} N/m is above {MAX_STIFFNESS} N/m, ten times the device's nominal maximum",
                        Num(*h)
                    ),
                ));
                }
            }
            match o {
                Object::Plane { point, normal, .. } => {
                    finite3(point, &format!("{f}.point"))?;
                    finite3(normal, &format!("{f}.normal"))?;
                    if normal.iter().map(|v| v * v).sum::<f64>() < 1e-12 {
                        return Err(invalid(
                            format!("{f}.normal"),
                            "must not be the zero vector",
                        ));
                    }
                }
                Object::Sphere { center, radius, .. } => {
                    finite3(center, &format!("{f}.center"))?;
                    if !radius.is_finite() || *radius <= 0.0 {
                        return Err(invalid(
                            format!("{f}.radius"),
                            format!("{} must be positive", Num(*radius)),
                        ));
                    }
                }
                Object::Box {
                    center,
                    half_extents,
                    ..
                } => {
                    finite3(center, &format!("{f}.center"))?;
                    positive3(half_extents, &format!("{f}.half_extents"), false)?;
                }
            }
        }
        Ok(())
    }

    fn validate_change(&self, k: usize, c: &Change) -> Result<(), ScenarioError> {
        let f = format!("environment.changes[{k}]");
        if !c.at_s.is_finite() || c.at_s < 0.0 {
            return Err(invalid(
                format!("{f}.at_s"),
                format!("{} s must be finite and non-negative", Num(c.at_s)),
            ));
        }
        if c.object >= self.objects.len() {
            return Err(invalid(
                format!("{f}.object"),
                format!(
                    "{} is not an object: there are {}",
                    c.object,
                    self.objects.len()
                ),
            ));
        }
        finite3(&c.move_by, &format!("{f}.move_by"))?;
        if c.move_by.iter().any(|v| v.abs() > 1.0) {
            return Err(invalid(format!("{f}.move_by"), "moves more than 1 m"));
        }
        if let Some(s) = &c.stiffness {
            positive3(s, &format!("{f}.stiffness"), true)?;
            if let Some(i) = s.iter().position(|h| *h > MAX_STIFFNESS) {
                return Err(invalid(
                    format!("{f}.stiffness[{i}]"),
                    format!("{} N/m is above {MAX_STIFFNESS} N/m", Num(s[i])),
                ));
            }
        }
        Ok(())
    }
}
