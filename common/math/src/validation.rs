//! The paper's validation run and its MSE table, reproduced from our kernels.
//!
//! The paper moves the master from rest through three 4 s joint moves (theta1 0 -> pi/2,
//! then theta2 0 -> pi/4, then theta3 0 -> pi/4) sampled at t_s = 10 ms, 1200 samples,
//! and compares the FPGA (hybrid) outputs against the f32 software model per module and
//! variable. The paper does not say what feeds KFF and FBF; we use (and document):
//!
//! * **FK-HMD, FK-HSD**: the trajectory's joint angles (the paper's two rows are equal,
//!   so both modules saw the same angles).
//! * **IK-HSD**: the f32 software model's FK of the trajectory: the positions the
//!   master would send.
//! * **FBF-HSD**: tool at that same f32 FK position, object point at the tool's rest
//!   position (FK of zero angles), stiffness [`SPRING_N_PER_M`] on each axis: a virtual
//!   spring pulling the operator home, non-zero on all three axes for the whole run and
//!   peaking near the Omni's 3.3 N.
//! * **KFF-HMD**: the trajectory's angles and the f32 FBF force above.
//!
//! Every module gets identical f32 inputs in both arithmetics, so the table isolates
//! each module's own arithmetic error, as the paper's per-module table does.

use crate::arith::{Real, StdTrig, Trig};
use crate::cordic::{Cordic, CordicConfig, CordicError};
use crate::geometry::{Geometry, Lengths};
use crate::kernels;
use serde::Serialize;

/// Samples in the paper's run.
pub const SAMPLES: usize = 1200;
/// Sampling period, seconds.
pub const T_S: f64 = 0.01;
/// Duration of each joint move, seconds.
pub const MOVE_S: f64 = 4.0;
/// Stiffness of the home spring feeding FBF and KFF, N/m per axis.
pub const SPRING_N_PER_M: f64 = 12.0;
/// Joint targets of the three moves, radians.
pub const TARGETS: [f64; 3] = [
    std::f64::consts::FRAC_PI_2,
    std::f64::consts::FRAC_PI_4,
    std::f64::consts::FRAC_PI_4,
];

/// The paper's four waypoints: joint angles and the printed tool positions (metres,
/// three decimals as printed).
pub const WAYPOINTS: [([f64; 3], [f64; 3]); 4] = [
    ([0.0, 0.0, 0.0], [0.0, -0.107, -0.035]),
    (
        [std::f64::consts::FRAC_PI_2, 0.0, 0.0],
        [-0.132, -0.107, -0.167],
    ),
    (
        [
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_4,
            0.0,
        ],
        [-0.093, -0.013, -0.167],
    ),
    (
        [
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::FRAC_PI_4,
        ],
        [-0.186, 0.025, -0.167],
    ),
];

/// Joint angles of the validation trajectory at time `t` seconds: joint k ramps
/// linearly from 0 to its target during [4k, 4k + 4) s and then holds it.
pub fn paper_joint_path(t: f64) -> [f64; 3] {
    let mut theta = [0.0; 3];
    for (k, th) in theta.iter_mut().enumerate() {
        let start = MOVE_S * k as f64;
        let frac = ((t - start) / MOVE_S).clamp(0.0, 1.0);
        *th = TARGETS[k] * frac;
    }
    theta
}

/// The 1200 samples of the validation trajectory, sample n at t = n t_s.
pub fn paper_trajectory() -> Vec<[f64; 3]> {
    (0..SAMPLES)
        .map(|n| paper_joint_path(n as f64 * T_S))
        .collect()
}

/// One row of the MSE table.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct MseRow {
    /// Module name as in the paper, e.g. `FK-HMD`.
    pub module: &'static str,
    /// Variable name as in the paper, e.g. `x^HMD`.
    pub variable: &'static str,
    /// Our MSE of hybrid against f32.
    pub mse: f64,
    /// The paper's MSE for the same module and variable.
    pub paper_mse: f64,
    /// Our MSE of f32 against the f64 reference, for scale.
    pub f32_vs_f64_mse: f64,
}

/// The paper's table, in its order: (module, variable, MSE).
pub const PAPER_MSE: [(&str, &str, f64); 15] = [
    ("FK-HMD", "x^HMD", 2.333e-8),
    ("FK-HMD", "y^HMD", 8.316e-9),
    ("FK-HMD", "z^HMD", 1.656e-8),
    ("KFF-HMD", "tau1^HMD", 1.467e-7),
    ("KFF-HMD", "tau2^HMD", 5.207e-9),
    ("KFF-HMD", "tau3^HMD", 3.350e-7),
    ("FK-HSD", "x^ENV", 2.333e-8),
    ("FK-HSD", "y^ENV", 8.316e-9),
    ("FK-HSD", "z^ENV", 1.656e-8),
    ("IK-HSD", "theta1^HSD", 3.731e-6),
    ("IK-HSD", "theta2^HSD", 2.847e-6),
    ("IK-HSD", "theta3^HSD", 2.702e-6),
    ("FBF-HSD", "Fx^HSD", 2.437e-16),
    ("FBF-HSD", "Fy^HSD", 1.731e-16),
    ("FBF-HSD", "Fz^HSD", 3.360e-16),
];

/// Outputs of the five modules over the run, per sample: FK-HMD, KFF-HMD, FK-HSD,
/// IK-HSD, FBF-HSD, three variables each.
type ModuleOutputs = Vec<[f64; 15]>;

/// Runs the five modules over the inputs in one arithmetic.
fn run_modules<R: Real, T: Trig<R>>(
    g: &Lengths<R>,
    trig: &T,
    inputs: &[ValidationInput],
) -> ModuleOutputs {
    let c = |v: [f64; 3]| v.map(R::from_f64);
    let h = [R::from_f64(SPRING_N_PER_M); 3];
    inputs
        .iter()
        .map(|inp| {
            let fk = kernels::fk(g, trig, c(inp.theta));
            let kff = kernels::kff(g, trig, c(inp.theta), c(inp.force));
            let ik = kernels::ik(g, trig, c(inp.position)).theta;
            let fbf = kernels::fbf(c(inp.home), c(inp.position), h);
            let mut row = [0.0; 15];
            for (k, v) in fk
                .iter()
                .chain(&kff)
                .chain(&fk)
                .chain(&ik)
                .chain(&fbf)
                .enumerate()
            {
                row[k] = v.to_f64();
            }
            row
        })
        .collect()
}

/// The inputs each module sees at one sample (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValidationInput {
    /// Joint angles of the trajectory.
    pub theta: [f64; 3],
    /// f32 FK of `theta`: tool position.
    pub position: [f64; 3],
    /// f32 FK of zero angles: the spring's anchor, the object point for FBF.
    pub home: [f64; 3],
    /// f32 FBF of the spring: the force fed to KFF.
    pub force: [f64; 3],
}

/// The inputs of the validation run for `geometry`.
pub fn validation_inputs(geometry: &Geometry) -> Vec<ValidationInput> {
    let g32: Lengths<f32> = geometry.lengths();
    let home32 = kernels::fk(&g32, &StdTrig, [0.0f32; 3]);
    let h32 = [SPRING_N_PER_M as f32; 3];
    let widen = |v: [f32; 3]| v.map(f64::from);
    paper_trajectory()
        .into_iter()
        .map(|theta| {
            let pos32 = kernels::fk(&g32, &StdTrig, theta.map(|t| t as f32));
            ValidationInput {
                theta: widen(theta.map(|t| t as f32)),
                position: widen(pos32),
                home: widen(home32),
                force: widen(kernels::fbf(home32, pos32, h32)),
            }
        })
        .collect()
}

fn mse_columns(a: &ModuleOutputs, b: &ModuleOutputs) -> [f64; 15] {
    let mut acc = [0.0; 15];
    for (ra, rb) in a.iter().zip(b) {
        for k in 0..15 {
            let d = ra[k] - rb[k];
            acc[k] += d * d;
        }
    }
    acc.map(|s| s / a.len().max(1) as f64)
}

/// The MSE table: hybrid (with `cordic`) against f32, beside the paper's figures.
pub fn mse_table(geometry: &Geometry, cordic: CordicConfig) -> Result<Vec<MseRow>, CordicError> {
    let inputs = validation_inputs(geometry);
    let cordic = Cordic::new(cordic)?;
    let g32: Lengths<f32> = geometry.lengths();
    let g64: Lengths<f64> = geometry.lengths();
    let hybrid = run_modules(&g32, &cordic, &inputs);
    let f32_out = run_modules(&g32, &StdTrig, &inputs);
    let f64_out = run_modules(&g64, &StdTrig, &inputs);
    let ours = mse_columns(&hybrid, &f32_out);
    let f32_err = mse_columns(&f32_out, &f64_out);
    Ok(PAPER_MSE
        .iter()
        .enumerate()
        .map(|(k, &(module, variable, paper_mse))| MseRow {
            module,
            variable,
            mse: ours[k],
            paper_mse,
            f32_vs_f64_mse: f32_err[k],
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trajectory_shape() {
        let t = paper_trajectory();
        assert_eq!(t.len(), SAMPLES);
        assert_eq!(t[0], [0.0; 3]);
        assert_eq!(t[400], [TARGETS[0], 0.0, 0.0]);
        assert_eq!(t[800], [TARGETS[0], TARGETS[1], 0.0]);
        assert!((t[1199][2] - TARGETS[2] * 399.0 / 400.0).abs() < 1e-12);
    }

    #[test]
    fn spring_force_stays_near_device_limit() {
        let max = validation_inputs(&Geometry::PAPER)
            .iter()
            .map(|i| i.force.iter().map(|f| f * f).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        assert!(max > 2.5 && max < 3.3, "peak spring force {max} N");
    }
}
