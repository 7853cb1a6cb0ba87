//! The paper's slave arm: three joints, the HSD's kernels (IK, FK, FBF) in the
//! scenario's arithmetic, FCS's PID and SD's joint dynamics over t_s with the contact
//! force acting on the joints; the physical world (the true tool, the contact) in f64.

use crate::arm::{Controller, Dynamics};
use crate::environment::deepest_contact;
use crate::slave_arm::SlaveArm;
use crate::world::Touch;
use tactile_math::arith::StdTrig;
use tactile_math::engine::Engine;
use tactile_math::geometry::Lengths;
use tactile_math::joints::Joints;
use tactile_math::kernels::{self, IkStatus};
use tactile_math::vec3::distance;
use tactile_messages::samples::Flags;
use tactile_records::slave::{ArmJoints, HoldStep, SlaveCounters};
use tactile_ros::view::{SampleView, SlaveView};
use tactile_scenario::{Scenario, ScenarioError};

/// The paper's arm, simulated or a real robot's three joints.
#[derive(Debug)]
pub struct PaperArm {
    engine: Engine,
    truth: Lengths<f64>,
    controller: Controller,
    dynamics: Dynamics,
    /// IK's last valid answer: the joints' reference theta_ref.
    reference: [f64; 3],
    /// Where the arm is: the simulated joints, or the robot's as last measured.
    theta: [f64; 3],
    /// FCS's torques of the last period (zero for a real robot's, whose own
    /// controller applies them).
    torque: [f64; 3],
    /// The reference held since the input went silent, if it is.
    hold_from: Option<[f64; 3]>,
}

impl PaperArm {
    /// The arm at rest at zero angles, its kernels in the scenario's arithmetic.
    pub fn new(scenario: &Scenario) -> Result<PaperArm, ScenarioError> {
        let geometry = scenario.device.geometry()?;
        let engine = tactile_rtl::engine(scenario.arithmetic, geometry, scenario.cordic.config()?)
            .map_err(|e| ScenarioError::Invalid {
                field: e.field().into(),
                problem: e.to_string(),
            })?;
        Ok(PaperArm {
            engine,
            truth: geometry.lengths(),
            controller: Controller::new(scenario.slave.controller.clone()),
            dynamics: Dynamics::new(scenario.slave.dynamics.clone(), [0.0; 3]),
            reference: [0.0; 3],
            theta: [0.0; 3],
            torque: [0.0; 3],
            hold_from: None,
        })
    }

    /// Integrates the joints over one sample under `torque`, pushed back by whatever
    /// the tool touches (true tool position, f64): the scene's springs at each
    /// integration step, or a physics world's force held over the sample.
    fn integrate(&mut self, torque: [f64; 3], touch: Touch<'_>, dt: f64) {
        let truth = self.truth;
        self.dynamics.advance(torque, dt, |s| {
            let f = match touch {
                Touch::Scene(objects) => {
                    let tool = kernels::fk(&truth, &StdTrig, s.theta);
                    match deepest_contact(objects, tool) {
                        Some(c) => kernels::fbf(c.surface, tool, c.stiffness),
                        None => return [0.0; 3],
                    }
                }
                Touch::Held(f) => f,
            };
            let j = kernels::jacobian(&truth, &StdTrig, s.theta);
            [0, 1, 2].map(|k| j[0][k] * f[0] + j[1][k] * f[1] + j[2][k] * f[2])
        });
        self.theta = self.dynamics.state.theta;
    }

    /// FCS then SD toward `reference`: the torques kept for the record, the clamps
    /// counted into `c` and returned.
    fn servo(
        &mut self,
        reference: [f64; 3],
        touch: Touch<'_>,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> u32 {
        let state = self.dynamics.state;
        let cmd = self
            .controller
            .update(reference, state.theta, state.velocity, dt);
        self.integrate(cmd.torque, touch, dt);
        self.torque = cmd.torque;
        c.torque_clamps += u64::from(cmd.clamped);
        cmd.clamped
    }
}

impl SlaveArm for PaperArm {
    /// IK-HSD, then JPD-HSD (pass-through); an invalid answer keeps the last
    /// reference. The paper's arm has no clutch: `released` is a 6-DoF master's.
    fn follow(
        &mut self,
        position: [f64; 3],
        _: Option<[f64; 4]>,
        _: bool,
        _: f64,
        c: &mut SlaveCounters,
    ) -> Flags {
        let ik = self.engine.ik(position);
        let flags = match ik.status {
            IkStatus::Reachable => Flags::NONE,
            IkStatus::Clamped => {
                c.ik_clamped += 1;
                Flags::IK_CLAMPED
            }
            IkStatus::Invalid => {
                c.rejected += 1;
                Flags::REJECTED
            }
        };
        if ik.status != IkStatus::Invalid {
            self.reference = ik.theta;
        }
        flags
    }

    fn advance(
        &mut self,
        measured: Option<&Joints>,
        touch: Touch<'_>,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> u32 {
        if let Some(q) = measured {
            self.theta = q.to_array3();
            self.torque = [0.0; 3];
            return 0;
        }
        self.servo(self.reference, touch, dt, c)
    }

    /// Simulated, the joints are held where they were; a real robot is commanded the
    /// reference it had.
    fn hold(
        &mut self,
        measured: Option<&Joints>,
        touch: Touch<'_>,
        dt: f64,
        c: &mut SlaveCounters,
    ) -> HoldStep {
        let now = match measured {
            Some(_) => self.reference,
            None => self.dynamics.state.theta,
        };
        let from = *self.hold_from.get_or_insert_with(|| {
            c.holds += 1;
            now
        });
        c.held_steps += 1;
        match measured {
            Some(q) => {
                self.theta = q.to_array3();
                self.torque = [0.0; 3];
            }
            None => {
                self.reference = from;
                self.servo(from, touch, dt, c);
            }
        }
        let p0 = kernels::fk(&self.truth, &StdTrig, from);
        let p = kernels::fk(&self.truth, &StdTrig, self.theta);
        c.hold_drift_max_m = c.hold_drift_max_m.max(distance(p, p0));
        HoldStep {
            step: c.held_steps,
            tool: p,
        }
    }

    fn end_hold(&mut self) {
        self.hold_from = None;
    }

    /// FK-HSD in the HSD's arithmetic, and the true tool.
    fn tool(&self) -> ([f64; 3], [f64; 3]) {
        (
            self.engine.fk(self.theta),
            kernels::fk(&self.truth, &StdTrig, self.theta),
        )
    }

    /// FBF-HSD in the HSD's arithmetic.
    fn contact_force(&self, surface: [f64; 3], tool: [f64; 3], stiffness: [f64; 3]) -> [f64; 3] {
        self.engine.fbf(surface, tool, stiffness)
    }

    fn felt(&self, f: [f64; 3]) -> [f64; 3] {
        f
    }

    fn reference(&self) -> Joints {
        Joints::from(self.reference)
    }

    fn counters(&self, c: SlaveCounters) -> SlaveCounters {
        SlaveCounters {
            rtl: self.engine.hardware_clocks(),
            ..c
        }
    }

    /// The three angles, their reference (IK-HSD's, or the one held) and FCS's
    /// torques; the paper's arm has no orientation, clutch or sensor torque.
    fn joints(&self, torque: [f64; 3], _: Option<[f64; 4]>) -> ArmJoints {
        ArmJoints {
            q_ref: Joints::from(self.reference),
            q: Joints::from(self.theta),
            tau: Joints::from(self.torque),
            torque,
            ..ArmJoints::default()
        }
    }

    fn live(&self, view: SlaveView) -> SampleView {
        SampleView {
            slave: Some(view),
            ..SampleView::default()
        }
    }
}
