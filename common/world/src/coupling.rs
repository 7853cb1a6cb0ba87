//! The virtual coupling: a spring and a damper between the arm's tool frame and the
//! tool body, on position and on orientation (CHAI3D's Bullet tool does the same).
//!
//! **Integrated implicitly at the substep h.** The force is the one at the end of the
//! substep, `F = K (x_a' - x_t') + B (v_a - v_t')`, with the tool's next velocity
//! `v_t' = v_t + h F / m` and position `x_t' = x_t + h v_t'` (the engine's
//! semi-implicit Euler), which solves to
//! `F = [K (e + h (v_a - v_t)) + B (v_a - v_t)] / (1 + (K h^2 + B h) / m)`.
//! For the tool alone this is backward Euler of a mass on a spring and damper, which
//! never adds energy, for any K, B >= 0, h and m (the test below checks it); an
//! explicit spring would need `2 h B / m + h^2 K / m < 4` and, by Colgate and
//! Schenkel's bound for a sampled spring, `B > K h / 2` to stay passive. The rotation
//! is the same with the tool's inverse inertia in place of `1 / m`.
//!
//! **Seen from the arm** the coupling is a spring and damper whose force is sampled
//! once per sample T (the mean over the substeps) and held: the sampled-wall bound of
//! Colgate and Brown, `b > K T / 2 + |B|`, is what the arm's own damping b (its servo's
//! and its joints', mapped to the tool) must exceed for the loop through the arm to stay
//! passive ([`arm_damping_needed`]). With the defaults (K = 1000 N/m, B = 10 N s/m,
//! T = 1 ms) that is 10.5 N s/m; at 100 Hz, 15 N s/m.

use crate::error::WorldError;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use tactile_scenario::world::ToolConfig;

/// The coupling's gains and its substep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// Stiffness, N/m.
    pub k: f64,
    /// Damping, N s/m.
    pub b: f64,
    /// Rotational stiffness, N m/rad.
    pub ka: f64,
    /// Rotational damping, N m s/rad.
    pub ba: f64,
    /// The substep, s.
    pub h: f64,
}

impl Gains {
    /// The tool's gains at the substep `h` (the scenario checked their ranges).
    pub fn of(t: &ToolConfig, h: f64) -> Result<Gains, WorldError> {
        Ok(Gains {
            k: t.stiffness,
            b: t.damping,
            ka: t.angular_stiffness,
            ba: t.angular_damping,
            h,
        })
    }

    /// The force on the tool (of mass `m`) for one substep: `e` the tool frame's
    /// position minus the tool's, `va` and `vt` their velocities.
    pub fn force(
        &self,
        m: f64,
        e: Vector3<f64>,
        va: Vector3<f64>,
        vt: Vector3<f64>,
    ) -> Vector3<f64> {
        let (k, b, h) = (self.k, self.b, self.h);
        let dv = va - vt;
        (e * k + dv * (k * h + b)) / (1.0 + (k * h * h + b * h) / m)
    }

    /// The torque on the tool for one substep: `theta` the rotation vector from the
    /// tool's orientation to the tool frame's, `wa` and `wt` the angular velocities,
    /// `inv_inertia` the tool's inverse inertia in the world.
    pub fn torque(
        &self,
        inv_inertia: &Matrix3<f64>,
        theta: Vector3<f64>,
        wa: Vector3<f64>,
        wt: Vector3<f64>,
    ) -> Vector3<f64> {
        let (k, b, h) = (self.ka, self.ba, self.h);
        let rhs = theta * k + (wa - wt) * (k * h + b);
        let lhs = Matrix3::identity() + inv_inertia * (k * h * h + b * h);
        lhs.lu().solve(&rhs).unwrap_or_else(Vector3::zeros)
    }
}

/// The rotation vector (axis times angle, at most pi) turning `from` into `to`.
pub fn rotation_error(to: &UnitQuaternion<f64>, from: &UnitQuaternion<f64>) -> Vector3<f64> {
    (to * from.inverse()).scaled_axis()
}

/// The damping the arm must have at its tool, N s/m, for the coupling of stiffness
/// `k` and damping `b`, sampled every `period` s, to be passive (Colgate and Brown:
/// `b_arm > k T / 2 + |b|`).
pub fn arm_damping_needed(k: f64, b: f64, period: f64) -> f64 {
    k * period / 2.0 + b.abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tool of mass m on the coupling to a fixed target, stepped as the engine steps
    /// it: its energy (kinetic plus the spring's) never rises, whatever the gains.
    #[test]
    fn the_implicit_coupling_never_adds_energy() {
        for &(k, b, m, h) in &[
            (1000.0, 10.0, 0.1, 2.5e-4),
            (1e6, 0.0, 1e-3, 1e-3),
            (1e5, 1e3, 1e-4, 1e-2),
            (10.0, 0.0, 1.0, 1e-3),
        ] {
            let g = Gains {
                k,
                b,
                ka: 0.0,
                ba: 0.0,
                h,
            };
            let (mut x, mut v) = (
                Vector3::new(0.01, -0.02, 0.005),
                Vector3::new(0.3, 0.0, -1.0),
            );
            let energy = |x: &Vector3<f64>, v: &Vector3<f64>| {
                0.5 * m * v.norm_squared() + 0.5 * k * x.norm_squared()
            };
            let mut e0 = energy(&x, &v);
            for _ in 0..10_000 {
                let f = g.force(m, -x, Vector3::zeros(), v);
                v += f * (h / m);
                x += v * h;
                let e1 = energy(&x, &v);
                assert!(
                    e1 <= e0 * (1.0 + 1e-12) + 1e-15,
                    "k {k} b {b} m {m} h {h}: {e0} -> {e1}"
                );
                e0 = e1;
            }
        }
    }

    /// An explicit spring (the force from the position at the substep's start) with
    /// the same gains does add energy: what the implicit form is for.
    #[test]
    fn an_explicit_spring_with_those_gains_would_not() {
        let (k, m, h) = (1e6, 1e-3, 1e-3);
        let (mut x, mut v) = (0.01f64, 0.0f64);
        let e0 = 0.5 * k * x * x;
        for _ in 0..10 {
            v += -k * x * h / m;
            x += v * h;
        }
        assert!(0.5 * m * v * v + 0.5 * k * x * x > 100.0 * e0);
    }

    #[test]
    fn the_steady_force_is_the_spring_and_rotation_errors_are_short() {
        let g = Gains {
            k: 1000.0,
            b: 10.0,
            ka: 2.0,
            ba: 0.02,
            h: 2.5e-4,
        };
        let f = g.force(
            0.1,
            Vector3::new(0.002, 0.0, 0.0),
            Vector3::zeros(),
            Vector3::zeros(),
        );
        // At rest the implicit force is K e shrunk by 1 + (K h^2 + B h) / m.
        let shrink = 1.0 + (1000.0 * 6.25e-8 + 10.0 * 2.5e-4) / 0.1;
        assert!((f.x - 2.0 / shrink).abs() < 1e-12, "{f}");
        let a = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 3.0);
        let b = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -3.0);
        let e = rotation_error(&a, &b);
        assert!(
            (e.z - (6.0 - 2.0 * std::f64::consts::PI)).abs() < 1e-9,
            "{e}"
        );
        assert_eq!(arm_damping_needed(1000.0, 10.0, 1e-3), 10.5);
    }
}
