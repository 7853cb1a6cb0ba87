//! `[slave]` and `[environment]`: the slave's joint controller and dynamics, and the
//! objects the tool can touch.

use crate::PredictorConfig;
use serde::{Deserialize, Serialize};

/// The slave side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SlaveConfig {
    /// Joint controller.
    #[serde(default)]
    pub controller: ControllerConfig,
    /// Joint dynamics of the slave device.
    #[serde(default)]
    pub dynamics: DynamicsConfig,
    /// How the slave fills positions not received (CPD-HSD).
    #[serde(default)]
    pub predictor: PredictorConfig,
}

/// PD or PID per joint: u = kp e + ki integral(e) + kd de/dt, clamped to the limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerConfig {
    /// Proportional gains, N m / rad.
    #[serde(default = "default_kp")]
    pub kp: [f64; 3],
    /// Integral gains, N m / (rad s); zero gives PD.
    #[serde(default)]
    pub ki: [f64; 3],
    /// Derivative gains, N m s / rad.
    #[serde(default = "default_kd")]
    pub kd: [f64; 3],
    /// Torque limit per joint, N m (the Omni's 3.3 N at its 0.132 m arm: ~0.44 N m).
    #[serde(default = "default_torque_limit")]
    pub torque_limit: [f64; 3],
}

fn default_kp() -> [f64; 3] {
    [6.0; 3]
}
fn default_kd() -> [f64; 3] {
    [0.12; 3]
}
fn default_torque_limit() -> [f64; 3] {
    [0.45; 3]
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig {
            kp: default_kp(),
            ki: [0.0; 3],
            kd: default_kd(),
            torque_limit: default_torque_limit(),
        }
    }
}

/// Per-joint inertia and viscous damping, integrated at a fixed step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsConfig {
    /// Inertia per joint, kg m^2.
    #[serde(default = "default_inertia")]
    pub inertia: [f64; 3],
    /// Viscous damping per joint, N m s / rad.
    #[serde(default = "default_damping")]
    pub damping: [f64; 3],
    /// Integration step, seconds, at most 0.01; each sample integrates t_s in steps of
    /// at most this (one step of t_s when t_s is shorter).
    #[serde(default = "default_step")]
    pub step_s: f64,
}

fn default_inertia() -> [f64; 3] {
    [2.0e-3; 3]
}
fn default_damping() -> [f64; 3] {
    [5.0e-3; 3]
}
fn default_step() -> f64 {
    2.5e-4
}

impl Default for DynamicsConfig {
    fn default() -> Self {
        DynamicsConfig {
            inertia: default_inertia(),
            damping: default_damping(),
            step_s: default_step(),
        }
    }
}

/// The slave's environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Environment {
    /// Objects; the one the tool penetrates most deeply produces the contact force.
    #[serde(default)]
    pub objects: Vec<Object>,
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
