//! The slave side's per-sample logic (HSD + SD + ENV) as a pure state machine.
//!
//! [`Slave::step`] takes the forward sample v(n) and writes the backward sample h(n).
//! Its handler ([`crate::handler`]) is what the loop's driver calls, in the node
//! program and in the in-process simulation alike, so both compute identical values.
//!
//! One step: the channel's control (the received position itself, or TDPA's or the
//! wave's reference) -> CPD (pass-through) -> IK-HSD -> JPD (pass-through) -> FCS (PID)
//! -> SD joint dynamics over t_s, with the contact force of the environment acting on
//! the joints -> FK-HSD -> ENV nearest surface point -> FBF-HSD -> the control's value
//! to send back (the force, or the backward wave).
//! The HSD kernels (IK, FK, FBF) run in the scenario's arithmetic; the physical world
//! (the device's true tool position and the contact force on it) is f64.

use crate::arm::{Controller, Dynamics, JointState};
use crate::environment::{deepest_contact, Scene};
use crate::urdf_arm::{ArmState, Followed, UrdfArm};
use tactile_control::codec::{Deadband, Estimate, Predictor};
use tactile_control::passivity::SlaveSide;
use tactile_math::arith::StdTrig;
use tactile_math::engine::Engine;
use tactile_math::geometry::Lengths;
use tactile_math::kernels::{self, IkStatus};
use tactile_math::vec3::distance;
use tactile_messages::samples::{
    Backward, Forward, FLAG_CONTACT, FLAG_IK_CLAMPED, FLAG_POSE, FLAG_REJECTED, FLAG_RELEASED,
    FLAG_SUBSTITUTED, FLAG_UNSENT,
};
use tactile_records::slave::{HoldStep, SlaveCounters, Step};
use tactile_scenario::{Scenario, ScenarioError};

/// The slave: HSD kernels, controller, device and environment.
#[derive(Debug)]
pub struct Slave {
    engine: Engine,
    truth: Lengths<f64>,
    controller: Controller,
    dynamics: Dynamics,
    objects: Scene,
    t_s: f64,
    reference: [f64; 3],
    counters: SlaveCounters,
    hold_from: Option<[f64; 3]>,
    control: SlaveSide,
    last_force: [f64; 3],
    last_tool: [f64; 3],
    codec: Deadband,
    predictor: Predictor,
    /// A real robot's joints (and force sensor) for the next step, in place of SD.
    measured: Option<Measured>,
    /// A real arm's joints (`[slave.arm]` over ROS 2) for the next step.
    measured_arm: Option<Vec<f64>>,
    /// Any arm from its URDF in place of the paper's (`[slave.arm]`).
    arm: Option<UrdfArm>,
    /// A 6-DoF master's last accepted orientation (held while none valid comes).
    rotation: Option<[f64; 4]>,
    /// A real arm's measured torque about the tool for the next step, N m.
    measured_torque: [f64; 3],
}

/// What a real robot measured for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Joint angles theta^SD, rad.
    pub theta: [f64; 3],
    /// Contact force from a force-torque sensor, N (None: the environment model).
    pub force: Option<[f64; 3]>,
}

impl Slave {
    /// A slave at rest (zero joint angles, or a URDF arm at its home) for the
    /// scenario; `arm` is the scenario's `[slave.arm]` loaded (`UrdfArm::of_scenario`).
    pub fn new(scenario: &Scenario, arm: Option<UrdfArm>) -> Result<Slave, ScenarioError> {
        if scenario.slave.arm.is_some() != arm.is_some() {
            return Err(ScenarioError::Invalid {
                field: "slave.arm".into(),
                problem: "the arm's URDF must be loaded with the scenario that names it".into(),
            });
        }
        let geometry = scenario.device.geometry()?;
        let engine = tactile_rtl::engine(scenario.arithmetic, geometry, scenario.cordic.config()?)
            .map_err(|e| ScenarioError::Invalid {
                field: e.field().into(),
                problem: e.to_string(),
            })?;
        let truth = geometry.lengths();
        let start = kernels::fk(&truth, &StdTrig, [0.0; 3]);
        // Wave variables are neither positions nor forces: the codec measures them from
        // zero, and the predictor's plausibility bound is wider.
        let wave = scenario.control.kind == tactile_scenario::ControlKind::Wave;
        Ok(Slave {
            engine,
            truth,
            control: SlaveSide::new(&scenario.control, scenario.t_s(), start),
            last_force: [0.0; 3],
            last_tool: start,
            codec: Deadband::new(
                &scenario.codec.backward,
                [0.0; 3],
                if wave { 5e-3 } else { 0.02 },
            ),
            predictor: Predictor::new(
                &scenario.slave.predictor,
                scenario.t_s(),
                if wave { 1e6 } else { 100.0 },
            ),
            controller: Controller::new(scenario.slave.controller.clone()),
            dynamics: Dynamics::new(scenario.slave.dynamics.clone(), [0.0; 3]),
            objects: Scene::new(&scenario.environment.objects),
            t_s: scenario.t_s(),
            reference: [0.0; 3],
            counters: SlaveCounters::default(),
            hold_from: None,
            measured: None,
            measured_arm: None,
            arm,
            rotation: None,
            measured_torque: [0.0; 3],
        })
    }

    /// Counters so far.
    pub fn counters(&self) -> SlaveCounters {
        SlaveCounters {
            rtl: self.engine.hardware_clocks(),
            dynamics_failed: self.arm.as_ref().map_or(0, |a| a.dynamics_failures()),
            ..self.counters
        }
    }

    /// The device's joint state.
    pub fn joints(&self) -> JointState {
        self.dynamics.state
    }

    /// The URDF arm, if the slave is one.
    pub fn arm(&self) -> Option<&UrdfArm> {
        self.arm.as_ref()
    }

    /// A URDF arm's joints, if the slave is one.
    pub fn arm_state(&self) -> Option<&ArmState> {
        self.arm.as_ref().map(UrdfArm::state)
    }

    /// One sample of t_s with no input: hold the joints where they were when the input
    /// went silent (the master or the network is gone; the device must not wander).
    pub fn hold(&mut self) -> HoldStep {
        if let Some(arm) = self.arm.as_mut() {
            let h = arm.hold(self.t_s, &self.objects);
            log_first_failure(arm);
            let c = &mut self.counters;
            c.holds += u64::from(h.started);
            c.held_steps += 1;
            c.torque_clamps += u64::from(h.clamps);
            c.hold_drift_max_m = c.hold_drift_max_m.max(h.drift_m);
            // The arm's joints are in its own record entry: not three angles.
            return HoldStep {
                step: c.held_steps,
                tool: h.tool,
                ..HoldStep::default()
            };
        }
        let theta_now = self.dynamics.state.theta;
        let from = *self.hold_from.get_or_insert_with(|| {
            self.counters.holds += 1;
            theta_now
        });
        self.reference = from;
        self.counters.held_steps += 1;
        let cmd = self.controller.update(
            from,
            self.dynamics.state.theta,
            self.dynamics.state.velocity,
            self.t_s,
        );
        self.counters.torque_clamps += u64::from(cmd.clamped);
        self.advance(cmd.torque);
        let p0 = kernels::fk(&self.truth, &StdTrig, from);
        let p = kernels::fk(&self.truth, &StdTrig, self.dynamics.state.theta);
        let drift = distance(p, p0);
        self.counters.hold_drift_max_m = self.counters.hold_drift_max_m.max(drift);
        HoldStep {
            step: self.counters.held_steps,
            theta_ref: from,
            theta: self.dynamics.state.theta,
            torque: cmd.torque,
            tool: p,
        }
    }

    /// Integrates the device over one sample under `torque`, pushed back by whatever the
    /// tool touches (true tool position, f64).
    fn advance(&mut self, torque: [f64; 3]) {
        let truth = self.truth;
        let objects = &self.objects;
        self.dynamics.advance(torque, self.t_s, |s| {
            let tool = kernels::fk(&truth, &StdTrig, s.theta);
            match deepest_contact(objects, tool) {
                Some(c) => {
                    let f = kernels::fbf(c.surface, tool, c.stiffness);
                    let j = kernels::jacobian(&truth, &StdTrig, s.theta);
                    [0, 1, 2].map(|k| j[0][k] * f[0] + j[1][k] * f[1] + j[2][k] * f[2])
                }
                None => [0.0; 3],
            }
        });
    }

    /// The real robot's state for the next step: SD is the robot, FCS is its own
    /// controller (the step's `theta_ref` is what it is commanded).
    pub fn measure(&mut self, m: Measured) {
        self.measured = Some(m);
    }

    /// A real arm's state for the next step: its joints `q` (the URDF's order and
    /// units) and its force sensor's force in the base's axes, if it has one.
    pub fn measure_arm(&mut self, q: Vec<f64>, force: Option<[f64; 3]>, torque: [f64; 3]) {
        self.measured_arm = Some(q);
        self.measured_torque = torque;
        self.measured = Some(Measured {
            theta: [0.0; 3],
            force,
        });
    }

    /// One sample of holding with a real arm measured at `q`: it is commanded the
    /// reference it had when the input went silent.
    pub fn hold_measured_arm(&mut self, q: &[f64]) -> HoldStep {
        let Some(arm) = self.arm.as_mut() else {
            return self.hold();
        };
        let h = arm.hold_measured(q, self.t_s);
        let c = &mut self.counters;
        c.holds += u64::from(h.started);
        c.held_steps += 1;
        c.hold_drift_max_m = c.hold_drift_max_m.max(h.drift_m);
        HoldStep {
            step: c.held_steps,
            tool: h.tool,
            ..HoldStep::default()
        }
    }

    /// One sample of holding with a real robot: it is commanded the reference held
    /// from when the input went silent, and `theta` is where it is.
    pub fn hold_measured(&mut self, theta: [f64; 3]) -> HoldStep {
        let reference = self.reference;
        let from = *self.hold_from.get_or_insert_with(|| {
            self.counters.holds += 1;
            reference
        });
        self.counters.held_steps += 1;
        let p0 = kernels::fk(&self.truth, &StdTrig, from);
        let p = kernels::fk(&self.truth, &StdTrig, theta);
        let drift = distance(p, p0);
        self.counters.hold_drift_max_m = self.counters.hold_drift_max_m.max(drift);
        HoldStep {
            step: self.counters.held_steps,
            theta_ref: from,
            theta,
            torque: [0.0; 3],
            tool: p,
        }
    }

    /// One sample: v(n) in, h(n) into `h`, and the step's record. Stamps are copied
    /// from `v`; the edge sets its own. h(n) is filled where it lies (a follower's
    /// reply): returned, it was copied twice a sample on its way there.
    pub fn step(&mut self, v: &Forward, h: &mut Option<Backward>) -> Step {
        self.counters.steps += 1;
        self.hold_from = None;
        if let Some(arm) = self.arm.as_mut() {
            arm.end_hold();
        }
        let (mut flags, observer, dissipated_j) = self.follow(v);
        let measured = self.measured.take();
        let (theta, torque, clamps) = self.move_joints(measured);
        let (tool, force, surface, contact_object) =
            self.sense(theta, measured.and_then(|m| m.force), &mut flags);
        self.reply(v, force, tool, flags, h);
        Step {
            n: v.seq,
            received: v.signal,
            reference: self.control.position(),
            theta_ref: self.reference,
            theta,
            torque,
            tool,
            surface,
            force,
            observer,
            port_net_j: self.control.ledger().net(),
            dissipated_j,
            clamps,
            contact_object,
            flags,
        }
    }

    /// CPD-HSD, the channel's control and IK-HSD: the new reference angles from v(n).
    /// A value not sent or not new (the channel held it) is filled by the predictor;
    /// one that is not physically possible (not finite, too large, too fast) is
    /// rejected and filled likewise, never reaching the control, IK or a torque.
    /// Returns the flags so far, the observer and the energy dissipated.
    fn follow(&mut self, v: &Forward) -> (u32, [f64; 3], f64) {
        let mut flags = 0;
        let new = v.signal.flags & (FLAG_UNSENT | FLAG_SUBSTITUTED) == 0;
        let fresh = (new || !self.predictor.has_value()).then(|| {
            let at = v.signal.sent_seq.iter().copied().min().unwrap_or(v.seq);
            (at, v.signal.value)
        });
        let est = self.predictor.estimate(v.seq, fresh);
        let energy = match est {
            Estimate::Fresh(_) => v.signal.energy,
            _ => [0.0; 3],
        };
        if let Estimate::Rejected(_) = est {
            flags |= FLAG_REJECTED;
            self.counters.rejected += 1;
        }
        if !self.predictor.has_value() {
            return (flags, [0.0; 3], 0.0);
        }
        let r = self.control.receive(est.value(), energy, self.last_force);
        self.accept_rotation(v, &mut flags);
        if let Some(arm) = self.arm.as_mut() {
            if v.signal.flags & FLAG_RELEASED != 0 {
                arm.release();
            } else {
                let f = arm.follow(r.position, self.rotation, self.t_s);
                flags |= count_followed(&mut self.counters, f);
            }
            return (flags, r.observer, r.dissipated);
        }
        // IK-HSD, then JPD-HSD: pass-through.
        let ik = self.engine.ik(r.position);
        match ik.status {
            IkStatus::Reachable => {}
            IkStatus::Clamped => {
                flags |= FLAG_IK_CLAMPED;
                self.counters.ik_clamped += 1;
            }
            IkStatus::Invalid => {
                flags |= FLAG_REJECTED;
                self.counters.rejected += 1;
            }
        }
        if ik.status != IkStatus::Invalid {
            self.reference = ik.theta;
        }
        (flags, r.observer, r.dissipated)
    }

    /// A 6-DoF sample's orientation, if it is a rotation (finite, of norm one within
    /// [`ROTATION_TOLERANCE`]): taken, normalized; otherwise rejected and counted,
    /// and the last one held.
    fn accept_rotation(&mut self, v: &Forward, flags: &mut u32) {
        if v.signal.flags & FLAG_POSE == 0 {
            return;
        }
        let q = v.rotation;
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm.is_finite() && (norm - 1.0).abs() <= ROTATION_TOLERANCE {
            self.rotation = Some(q.map(|x| x / norm));
        } else if *flags & FLAG_REJECTED == 0 {
            *flags |= FLAG_REJECTED;
            self.counters.rejected += 1;
        }
    }

    /// The orientation the arm follows (a 6-DoF master's, as last accepted).
    pub fn rotation(&self) -> Option<[f64; 4]> {
        self.rotation
    }

    /// FCS and SD: the joint controller and the simulated joints, or the real robot
    /// (its own controller follows the reference; its encoders say where it is).
    /// Returns the angles, the torques and the torque clamps.
    fn move_joints(&mut self, measured: Option<Measured>) -> ([f64; 3], [f64; 3], u32) {
        if let Some(m) = measured {
            if let (Some(arm), Some(q)) = (self.arm.as_mut(), self.measured_arm.take()) {
                arm.set_measured(&q, self.t_s);
            }
            return (m.theta, [0.0; 3], 0);
        }
        if let Some(arm) = self.arm.as_mut() {
            // The arm's joints are in its own record entry: not three angles.
            let clamps = arm.advance(self.t_s, &self.objects);
            self.counters.torque_clamps += u64::from(clamps);
            log_first_failure(arm);
            return ([0.0; 3], [0.0; 3], clamps);
        }
        let state = self.dynamics.state;
        let cmd = self
            .controller
            .update(self.reference, state.theta, state.velocity, self.t_s);
        self.counters.torque_clamps += u64::from(cmd.clamped);
        self.advance(cmd.torque);
        (self.dynamics.state.theta, cmd.torque, cmd.clamped)
    }

    /// FK-HSD in the HSD's arithmetic, then ENV and FBF-HSD: the tool, the contact
    /// force (a force-torque sensor's if there is one), the surface point and the
    /// object touched (u32::MAX for none).
    fn sense(
        &mut self,
        theta: [f64; 3],
        sensor: Option<[f64; 3]>,
        flags: &mut u32,
    ) -> ([f64; 3], [f64; 3], [f64; 3], u32) {
        let (tool, truth) = match &self.arm {
            // A URDF arm's kernels are f64 (tactile-chain): its FK is the truth.
            Some(arm) => {
                let tool = arm.tool();
                (tool, tool)
            }
            None => (
                self.engine.fk(theta),
                kernels::fk(&self.truth, &StdTrig, theta),
            ),
        };
        let contact = deepest_contact(&self.objects, truth);
        let (force, surface, object) = match (sensor, contact) {
            (Some(f), _) => {
                // A force-torque sensor: its force is h(n); no surface is known. An
                // arm's is in its base's axes: turned into the master's and scaled.
                let f = self.arm.as_ref().map_or(f, |a| a.felt(f));
                if f.iter().any(|x| *x != 0.0) {
                    *flags |= FLAG_CONTACT;
                    self.counters.contact_steps += 1;
                }
                (f, [0.0; 3], u32::MAX)
            }
            (None, Some(c)) => {
                *flags |= FLAG_CONTACT;
                self.counters.contact_steps += 1;
                let f = match &self.arm {
                    Some(a) => a.felt_environment(kernels::fbf(c.surface, tool, c.stiffness)),
                    None => self.engine.fbf(c.surface, tool, c.stiffness),
                };
                (f, c.surface, c.object as u32)
            }
            (None, None) => ([0.0; 3], [0.0; 3], u32::MAX),
        };
        (tool, force, surface, object)
    }

    /// h(n) into `h`: the control's value of the force, through the codec, with the
    /// provenance of the oldest position value it used.
    fn reply(
        &mut self,
        v: &Forward,
        force: [f64; 3],
        tool: [f64; 3],
        flags: u32,
        h: &mut Option<Backward>,
    ) {
        self.last_force = force;
        let oldest = (0..3).min_by_key(|&i| v.signal.origin_seq[i]).unwrap_or(0);
        let out = h.insert(Backward {
            seq: v.seq,
            stamps: v.stamps,
            ..Backward::default()
        });
        out.signal.value = self.control.transmit(force);
        out.signal.energy = self.control.energy();
        out.signal.sent_seq = [v.seq; 3];
        let speed = distance(tool, self.last_tool) / self.t_s;
        self.last_tool = tool;
        if self.codec.send(out.signal.value, speed) {
            self.counters.packets_sent += 1;
        } else {
            out.signal.flags |= FLAG_UNSENT;
        }
        out.signal.origin_seq = [v.signal.origin_seq[oldest]; 3];
        out.signal.origin_ns = [v.signal.origin_ns[oldest]; 3];
        out.signal.delay_samples = [v.signal.delay_samples[oldest]; 3];
        out.signal.flags |= flags;
        // A 6-DoF sample is answered with a wrench: a real arm's measured torque about
        // the tool; the torque of the simulated point contact at the tool is zero.
        let torque = std::mem::take(&mut self.measured_torque);
        out.torque = self.arm.as_ref().map_or(torque, |a| a.felt(torque));
        out.signal.flags |= v.signal.flags & FLAG_POSE;
    }
}

/// How far from one a received quaternion's norm may be (the sender normalized it;
/// a wire carries it exactly): anything further is not a rotation and is rejected.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// The arm's first failed dynamics step, logged with its cause (the slave's handler
/// logs how many more each second): a run whose arm stands still says why.
fn log_first_failure(arm: &mut UrdfArm) {
    if let Some(e) = arm.take_failure() {
        if arm.dynamics_failures() == 1 {
            tracing::warn!(
                "slave.arm: the dynamics failed ({e}): the arm stands still while they do"
            );
        }
    }
}

/// Counts what a URDF arm's IK call did; the flags it sets on h(n).
fn count_followed(c: &mut SlaveCounters, f: Followed) -> u32 {
    c.ik_joint_limited += u64::from(f.joint_limited);
    c.ik_velocity_limited += u64::from(f.velocity_limited);
    c.ik_damped += u64::from(f.damped);
    let mut flags = 0;
    if f.unreachable {
        flags |= FLAG_IK_CLAMPED;
        c.ik_clamped += 1;
    }
    if f.refused {
        flags |= FLAG_REJECTED;
        c.rejected += 1;
    }
    if f.workspace_clamped {
        flags |= FLAG_IK_CLAMPED;
        c.workspace_clamped += 1;
    }
    flags
}
