//! The master device held by an impedance hand: the joints move under the hand's force
//! (through J^T) and the motor torques p(n), against the joints' inertia, damping and
//! friction. The encoders b(n) read these joints.
//!
//! The hand is a mass moving with the handle, pulled towards the intended position by
//! a spring and a damper (Hogan's impedance model of the arm, "Impedance control: an
//! approach to manipulation", ASME JDSMC 107, 1985). Its mass adds `m J^T J` to the
//! joint-space inertia, so each step solves a 3x3 system (nalgebra); the velocity
//! product term of a moving Jacobian (m J^T J' theta') is left out: at hand speeds
//! below 0.5 m/s it is under a percent of the spring's force. Integration is
//! semi-implicit Euler at a fixed step, so a run depends only on its inputs.

use nalgebra::{Matrix3, Vector3};
use tactile_math::arith::StdTrig;
use tactile_math::geometry::Lengths;
use tactile_math::kernels;
use tactile_scenario::{HandConfig, MasterDeviceConfig};

/// Velocity, rad/s, below which Coulomb friction fades in (tanh smoothing, so the
/// integration stays smooth through zero velocity).
const FRICTION_SMOOTHING: f64 = 0.01;

/// The master device and the hand on it.
#[derive(Debug, Clone)]
pub struct HeldDevice {
    cfg: MasterDeviceConfig,
    hand: HandConfig,
    lengths: Lengths<f64>,
    /// Joint angles, rad.
    pub theta: [f64; 3],
    /// Joint velocities, rad/s.
    pub velocity: [f64; 3],
    /// The hand's force on the handle at the end of the last step, N.
    pub hand_force: [f64; 3],
}

impl HeldDevice {
    /// A device at rest at `theta`.
    pub fn new(
        cfg: MasterDeviceConfig,
        hand: HandConfig,
        lengths: Lengths<f64>,
        theta: [f64; 3],
    ) -> Self {
        HeldDevice {
            cfg,
            hand,
            lengths,
            theta,
            velocity: [0.0; 3],
            hand_force: [0.0; 3],
        }
    }

    /// The handle's true position, m.
    pub fn handle(&self) -> [f64; 3] {
        kernels::fk(&self.lengths, &StdTrig, self.theta)
    }

    /// Advances by `dt` under motor torques `tau` while the hand's intended position
    /// moves linearly from `from` to `to` over the interval.
    pub fn advance(&mut self, tau: [f64; 3], from: [f64; 3], to: [f64; 3], dt: f64) {
        let steps = (dt / self.cfg.step_s).ceil().max(1.0) as u32;
        let h = dt / f64::from(steps);
        let v_d = Vector3::from_fn(|i, _| (to[i] - from[i]) / dt);
        for k in 1..=steps {
            let s = f64::from(k) / f64::from(steps);
            let x_d = Vector3::from_fn(|i, _| from[i] + s * (to[i] - from[i]));
            let acc = self.acceleration(tau, x_d, v_d);
            for (j, a) in acc.into_iter().enumerate() {
                self.velocity[j] += h * a;
                self.theta[j] += h * self.velocity[j];
            }
        }
    }

    /// Joint accelerations at the present state: (I + m J^T J) theta'' = J^T F_hand +
    /// tau - b theta' - friction.
    fn acceleration(&mut self, tau: [f64; 3], x_d: Vector3<f64>, v_d: Vector3<f64>) -> [f64; 3] {
        let j = kernels::jacobian(&self.lengths, &StdTrig, self.theta);
        let jm = Matrix3::from_fn(|r, c| j[r][c]);
        let qd = Vector3::from(self.velocity);
        let x = Vector3::from(self.handle());
        let xd = jm * qd;
        let f = (x_d - x) * self.hand.stiffness + (v_d - xd) * self.hand.damping;
        self.hand_force = [f[0], f[1], f[2]];
        let mut torque = jm.transpose() * f;
        for i in 0..3 {
            let w = self.velocity[i];
            torque[i] += tau[i]
                - self.cfg.damping[i] * w
                - self.cfg.friction[i] * (w / FRICTION_SMOOTHING).tanh();
        }
        let inertia = Matrix3::from_diagonal(&Vector3::from(self.cfg.inertia))
            + jm.transpose() * jm * self.hand.mass;
        // Positive definite (a positive diagonal plus a Gram matrix): Cholesky always
        // succeeds; the diagonal alone is the fallback should rounding say otherwise.
        let acc = match inertia.cholesky() {
            Some(ch) => ch.solve(&torque),
            None => Vector3::from_fn(|i, _| torque[i] / self.cfg.inertia[i]),
        };
        [acc[0], acc[1], acc[2]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_math::geometry::Geometry;

    fn device() -> HeldDevice {
        let hand = HandConfig {
            mode: tactile_scenario::HandMode::Impedance,
            ..HandConfig::default()
        };
        HeldDevice::new(
            MasterDeviceConfig::default(),
            hand,
            Geometry::OMNI.lengths(),
            [0.0, 0.3, 0.5],
        )
    }

    #[test]
    fn the_hand_brings_the_handle_to_rest_at_its_intended_position() {
        let mut d = device();
        let start = d.handle();
        let goal = [start[0] + 0.01, start[1] - 0.01, start[2] + 0.005];
        for _ in 0..3000 {
            d.advance([0.0; 3], goal, goal, 1e-3);
        }
        let p = d.handle();
        // Friction holds the handle short of the goal by at most friction / stiffness
        // at the tip: 4 mN m over a 0.13 m arm, 0.03 N, against 250 N/m: 0.12 mm per
        // joint, so well within 0.5 mm.
        let err = (0..3).map(|i| (p[i] - goal[i]).powi(2)).sum::<f64>().sqrt();
        assert!(err < 5e-4, "{err} m from the goal");
        assert!(
            d.velocity.iter().all(|w| w.abs() < 1e-3),
            "{:?}",
            d.velocity
        );
    }

    #[test]
    fn a_motor_force_pushes_the_handle_against_the_hand_spring() {
        // A constant 1 N along +z through J^T: at rest the hand's spring balances it,
        // so the handle sits 1 / 250 m = 4 mm off (friction aside).
        let mut d = device();
        let start = d.handle();
        for _ in 0..4000 {
            let j = kernels::jacobian(&d.lengths, &StdTrig, d.theta);
            let tau = [0, 1, 2].map(|k| j[2][k]);
            d.advance(tau, start, start, 1e-3);
        }
        let dz = d.handle()[2] - start[2];
        assert!((dz - 0.004).abs() < 5e-4, "{dz}");
    }
}
