//! The slave's joint controller (FCS) and the slave device's joint dynamics (SD).
//!
//! The controller is a PID per joint with the derivative taken on the measured
//! velocity (no derivative kick when a delayed or noisy reference jumps), conditional
//! integration as anti-windup, and a torque clamp per joint that is counted. The device
//! is three decoupled joints, I theta'' = u + tau_env - b theta', integrated with
//! semi-implicit Euler at a fixed step so the result depends only on the inputs.

use tactile_scenario::{ControllerConfig, DynamicsConfig};

/// PID joint controller state.
#[derive(Debug, Clone)]
pub struct Controller {
    cfg: ControllerConfig,
    integral: [f64; 3],
}

/// One controller output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Torques after clamping, N m.
    pub torque: [f64; 3],
    /// How many joints hit their torque limit this sample.
    pub clamped: u32,
}

impl Controller {
    /// A controller at rest.
    pub fn new(cfg: ControllerConfig) -> Self {
        Controller {
            cfg,
            integral: [0.0; 3],
        }
    }

    /// Torques that drive `theta` towards `reference`, for one sample of `dt` seconds.
    pub fn update(
        &mut self,
        reference: [f64; 3],
        theta: [f64; 3],
        velocity: [f64; 3],
        dt: f64,
    ) -> Command {
        let mut torque = [0.0; 3];
        let mut clamped = 0;
        for j in 0..3 {
            let e = reference[j] - theta[j];
            let unclamped = self.cfg.kp[j] * e + self.cfg.ki[j] * self.integral[j]
                - self.cfg.kd[j] * velocity[j];
            let limit = self.cfg.torque_limit[j];
            torque[j] = unclamped.clamp(-limit, limit);
            if torque[j] != unclamped {
                clamped += 1;
            } else {
                // Integrate only while unsaturated, so the integral cannot wind up.
                self.integral[j] += e * dt;
            }
        }
        Command { torque, clamped }
    }
}

/// Joint state of the slave device.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointState {
    /// Angles, rad.
    pub theta: [f64; 3],
    /// Velocities, rad/s.
    pub velocity: [f64; 3],
}

/// The slave device's joint dynamics.
#[derive(Debug, Clone)]
pub struct Dynamics {
    cfg: DynamicsConfig,
    /// Current state.
    pub state: JointState,
}

impl Dynamics {
    /// A device at rest at `theta`.
    pub fn new(cfg: DynamicsConfig, theta: [f64; 3]) -> Self {
        Dynamics {
            cfg,
            state: JointState {
                theta,
                velocity: [0.0; 3],
            },
        }
    }

    /// Advances by `dt` seconds under `torque`, in fixed steps of at most `step_s`;
    /// `external` gives the environment's joint torques at a state (contact).
    pub fn advance(
        &mut self,
        torque: [f64; 3],
        dt: f64,
        mut external: impl FnMut(&JointState) -> [f64; 3],
    ) {
        let steps = (dt / self.cfg.step_s).ceil().max(1.0) as u32;
        let h = dt / f64::from(steps);
        for _ in 0..steps {
            let ext = external(&self.state);
            for j in 0..3 {
                let acc = (torque[j] + ext[j] - self.cfg.damping[j] * self.state.velocity[j])
                    / self.cfg.inertia[j];
                self.state.velocity[j] += h * acc;
                self.state.theta[j] += h * self.state.velocity[j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pd_settles_on_a_step_and_clamps_large_errors() {
        let mut ctl = Controller::new(ControllerConfig::default());
        let mut dev = Dynamics::new(DynamicsConfig::default(), [0.0; 3]);
        let reference = [0.3, -0.2, 0.1];
        let mut clamps = 0;
        for _ in 0..300 {
            let cmd = ctl.update(reference, dev.state.theta, dev.state.velocity, 0.01);
            clamps += cmd.clamped;
            assert!(cmd.torque.iter().all(|t| t.abs() <= 0.45));
            dev.advance(cmd.torque, 0.01, |_| [0.0; 3]);
        }
        for (theta, want) in dev.state.theta.iter().zip(reference) {
            assert!((theta - want).abs() < 1e-3, "{:?}", dev.state);
        }
        // A 0.3 rad step asks for 1.8 N m at first: the clamp must have acted.
        assert!(clamps > 0);
    }

    #[test]
    fn integral_removes_steady_state_error_under_a_constant_load() {
        let cfg = ControllerConfig {
            ki: [20.0; 3],
            ..ControllerConfig::default()
        };
        let mut ctl = Controller::new(cfg);
        let mut dev = Dynamics::new(DynamicsConfig::default(), [0.0; 3]);
        for _ in 0..2000 {
            let cmd = ctl.update([0.0; 3], dev.state.theta, dev.state.velocity, 0.01);
            dev.advance(cmd.torque, 0.01, |_| [0.05; 3]);
        }
        assert!(
            dev.state.theta.iter().all(|t| t.abs() < 1e-4),
            "{:?}",
            dev.state
        );
    }
}
