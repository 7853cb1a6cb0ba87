//! The slave side's per-sample logic (HSD + SD + ENV) as a pure state machine.
//!
//! [`Slave::step`] takes the forward sample v(n) and writes the backward sample h(n).
//! Its handler ([`crate::handler`]) is what the loop's driver calls, in the node
//! program and in the in-process simulation alike, so both compute identical values.
//!
//! One step: the channel's control (the received position itself, or TDPA's or the
//! wave's reference) -> CPD (pass-through) -> the arm's IK (IK-HSD for the paper's arm)
//! -> JPD (pass-through) -> the arm's servo and dynamics over t_s (FCS and SD), or a
//! real robot's measured joints -> the arm's FK -> ENV nearest surface point -> FBF ->
//! the control's value to send back (the force, or the backward wave). The arm is
//! one trait ([`crate::slave_arm::SlaveArm`]); the paper's runs its kernels in the
//! scenario's arithmetic, the physical world (the true tool, the contact) in f64.

use crate::environment::deepest_contact;
use crate::slave_arm::SlaveArm;
use crate::world::{Felt, SlaveWorld};
use tactile_control::codec::{Deadband, Estimate, Guess, Predictor};
use tactile_control::mmt::ModelSender;
use tactile_control::passivity::SlaveSide;
use tactile_math::arith::StdTrig;
use tactile_math::joints::Joints;
use tactile_math::kernels;
use tactile_math::vec3::distance;
use tactile_messages::samples::{Backward, Flags, Forward};
use tactile_records::slave::{HoldStep, SlaveCounters, Step, WorldCounters};
use tactile_scenario::{Change, Scenario, ScenarioError};

/// The slave: its arm (the paper's or a URDF's), its world (the analytic scene or a
/// physics world) and the channel's control, codec and predictor.
#[derive(Debug)]
pub struct Slave {
    arm: Box<dyn SlaveArm>,
    world: SlaveWorld,
    /// What the physics world said went wrong, for the run's record (the handler
    /// takes them).
    events: Vec<String>,
    t_s: f64,
    counters: SlaveCounters,
    control: SlaveSide,
    last_force: [f64; 3],
    last_tool: [f64; 3],
    codec: Deadband,
    predictor: Predictor,
    /// A real robot's reading for the next step, in place of the simulation.
    measured: Option<Measured>,
    /// A 6-DoF master's last accepted orientation (held while none valid comes).
    rotation: Option<[f64; 4]>,
    /// `control.kind = "mmt"`: the environment's estimate, and the model last sent.
    mmt: Option<ModelSender>,
    /// `[[environment.changes]]` still to come, by the sample they hold from, latest
    /// first (so the next is popped off the end).
    changes: Vec<(u64, Change)>,
}

/// What a real robot measured for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Its joints, in the arm's order and units.
    pub joints: Joints,
    /// Contact force from a force-torque sensor, N (None: the environment model): the
    /// paper's robot's in the paper's frame, a URDF arm's in its base's axes.
    pub force: Option<[f64; 3]>,
    /// The torque about the tool from the same sensor, in the force's axes, N m (zero
    /// without one): a 6-DoF sample is answered with this wrench.
    pub torque: [f64; 3],
}

impl Slave {
    /// A slave at rest with `arm` (the scenario's, [`crate::peripherals::of_scenario`])
    /// in `world` (the scenario's, [`SlaveWorld::of_scenario`]).
    pub fn new(
        scenario: &Scenario,
        arm: Box<dyn SlaveArm>,
        world: SlaveWorld,
    ) -> Result<Slave, ScenarioError> {
        // Where the paper's arm's tool is at zero angles: where the master starts.
        let start = kernels::fk(&scenario.device.geometry()?.lengths(), &StdTrig, [0.0; 3]);
        // Wave variables are neither positions nor forces: the codec measures them from
        // zero, and the predictor's plausibility bound is wider.
        let wave = scenario.control.kind == tactile_scenario::ControlKind::Wave;
        Ok(Slave {
            arm,
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
            world,
            events: Vec::new(),
            t_s: scenario.t_s(),
            counters: SlaveCounters::default(),
            measured: None,
            rotation: None,
            mmt: (scenario.control.kind == tactile_scenario::ControlKind::Mmt)
                .then(|| ModelSender::new(&scenario.control.mmt)),
            changes: changes(scenario),
        })
    }

    /// Fills gaps in v(n) with `guess` instead of the predictor's kind
    /// (`[slave.predictor]`'s acceptance and horizon still hold).
    pub fn set_predictor(&mut self, guess: Box<dyn Guess>) {
        self.predictor.set_guess(guess);
    }

    /// Counters so far.
    pub fn counters(&self) -> SlaveCounters {
        self.arm.counters(self.counters)
    }

    /// The arm.
    pub fn arm(&self) -> &dyn SlaveArm {
        self.arm.as_ref()
    }

    /// What the world counted so far.
    pub fn world_counters(&self) -> WorldCounters {
        self.world.counters()
    }

    /// A physics world's state after the last step, for the record (None for the
    /// analytic scene).
    pub fn world_sample(&self) -> Option<tactile_records::slave::WorldSample> {
        self.world.sample()
    }

    /// What the physics world said went wrong since the last call, as text.
    pub fn take_events(&mut self) -> std::vec::Drain<'_, String> {
        self.events.drain(..)
    }

    /// One sample of t_s with no input: hold the arm where it was when the input went
    /// silent (the master or the network is gone; the arm must not wander); a real
    /// robot's `measured` joints say where it is.
    pub fn hold(&mut self, measured: Option<&Joints>) -> HoldStep {
        let held = self
            .arm
            .hold(measured, self.world.touch(), self.t_s, &mut self.counters);
        // The world goes on while the input is silent (a box keeps sliding); nothing
        // is sent back.
        self.step_world();
        held
    }

    /// Steps a physics world one sample with the arm's tool frame (nothing for the
    /// analytic scene, which is a function of the tool's position).
    fn step_world(&mut self) -> Option<Felt> {
        let SlaveWorld::Physics(p) = &mut self.world else {
            return None;
        };
        Some(p.step(self.arm.tool_frame(), self.t_s, &mut self.events))
    }

    /// A real robot's reading for the next step: its joints (SD is the robot, FCS its
    /// own controller, which is commanded the step's reference), its force sensor's
    /// force and the torque about the tool (see [`Measured::force`] for their frame).
    pub fn measure(&mut self, m: Measured) {
        self.measured = Some(m);
    }

    /// One sample: v(n) in, h(n)'s payload into `h` (the driver writes its number,
    /// run and stamps), and the step's record. h(n) is filled where it lies (a
    /// follower's reply): returned, it was copied twice a sample on its way there.
    pub fn step(&mut self, v: &Forward, h: &mut Option<Backward>) -> Step {
        self.counters.steps += 1;
        while self.changes.last().is_some_and(|(n, _)| *n <= v.seq) {
            if let Some((_, c)) = self.changes.pop() {
                self.world.apply(&c);
            }
        }
        self.arm.end_hold();
        let (mut flags, observer, dissipated_j) = self.follow(v);
        let measured = self.measured.take();
        let joints = measured.as_ref().map(|m| &m.joints);
        let clamps = self
            .arm
            .advance(joints, self.world.touch(), self.t_s, &mut self.counters);
        let felt = self.step_world();
        // A real force-torque sensor's reading wins; then a physics world's coupling;
        // then (in `sense`) the analytic scene.
        let (sensor, torque) = match (measured.and_then(|m| m.force.map(|f| (f, m.torque))), felt) {
            (Some((f, t)), _) => (Some((f, None)), t),
            (None, Some(w)) => (Some((w.force, Some(w.contact))), w.torque),
            (None, None) => (None, measured.map_or([0.0; 3], |m| m.torque)),
        };
        let (tool, force, surface, contact_object) = self.sense(sensor, &mut flags);
        self.reply(v, (force, torque), tool, flags, h);
        let model = h.as_ref().map_or_else(Default::default, |h| h.model);
        Step {
            n: v.seq,
            received: v.signal,
            reference: self.control.position(),
            tool,
            surface,
            force,
            observer,
            port_net_j: self.control.ledger().net(),
            dissipated_j,
            clamps,
            contact_object,
            flags,
            model,
        }
    }

    /// CPD-HSD, the channel's control and IK-HSD: the new reference angles from v(n).
    /// A value not sent or not new (the channel held it) is filled by the predictor;
    /// one that is not physically possible (not finite, too large, too fast) is
    /// rejected and filled likewise, never reaching the control, IK or a torque.
    /// Returns the flags so far, the observer and the energy dissipated.
    fn follow(&mut self, v: &Forward) -> (Flags, [f64; 3], f64) {
        let mut flags = Flags::NONE;
        let new = !v
            .signal
            .flags
            .intersects(Flags::UNSENT | Flags::SUBSTITUTED);
        let fresh = (new || !self.predictor.has_value()).then(|| {
            let at = v.signal.sent_seq.iter().copied().min().unwrap_or(v.seq);
            (at, v.signal.value)
        });
        let est = self.predictor.estimate(v.seq, fresh);
        let energy = match est {
            Estimate::Fresh(_) => v.signal.energy,
            _ => [0.0; 3],
        };
        match est {
            Estimate::Rejected(_) => {
                flags |= Flags::REJECTED;
                self.counters.rejected += 1;
            }
            Estimate::Refused(_) => flags |= Flags::GUESS_REFUSED,
            Estimate::Fresh(_) | Estimate::Predicted(_) => {}
        }
        if !self.predictor.has_value() {
            return (flags, [0.0; 3], 0.0);
        }
        let r = self.control.receive(est.value(), energy, self.last_force);
        self.accept_rotation(v, &mut flags);
        let released = v.signal.flags.intersects(Flags::RELEASED);
        flags |= self.arm.follow(
            r.position,
            self.rotation,
            released,
            self.t_s,
            &mut self.counters,
        );
        (flags, r.observer, r.dissipated)
    }

    /// A 6-DoF sample's orientation, if it is a rotation (finite, of norm one within
    /// [`ROTATION_TOLERANCE`]): taken, normalized; otherwise rejected and counted,
    /// and the last one held.
    fn accept_rotation(&mut self, v: &Forward, flags: &mut Flags) {
        if !v.signal.flags.intersects(Flags::POSE) {
            return;
        }
        let q = v.rotation;
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm.is_finite() && (norm - 1.0).abs() <= ROTATION_TOLERANCE {
            self.rotation = Some(q.map(|x| x / norm));
        } else {
            // A sample counts once, whether its position was rejected too or not.
            if !flags.intersects(Flags::REJECTED) {
                self.counters.rejected += 1;
            }
            *flags |= Flags::ROTATION_REJECTED;
        }
    }

    /// The orientation the arm follows (a 6-DoF master's, as last accepted).
    pub fn rotation(&self) -> Option<[f64; 4]> {
        self.rotation
    }

    /// FK-HSD in the HSD's arithmetic, then ENV and FBF-HSD: the tool, the contact
    /// force, the surface point and the object touched (u32::MAX for none). A
    /// force-torque sensor's force, or a physics world's coupling force (with its
    /// contact, if the tool touches a body), is h(n) in place of FBF's.
    fn sense(
        &mut self,
        sensor: Option<Sensor>,
        flags: &mut Flags,
    ) -> ([f64; 3], [f64; 3], [f64; 3], u32) {
        let (tool, truth) = self.arm.tool();
        let contact = match &self.world {
            SlaveWorld::Analytic(scene) if sensor.is_none() => deepest_contact(scene, truth),
            _ => None,
        };
        let (force, surface, object) = match (sensor, contact) {
            (Some((f, touched)), _) => {
                // A sensor's force (a real arm's, or the physics world's coupling) is
                // h(n). An arm's is in its base's axes: turned into the master's and
                // scaled. A real sensor knows no surface; the world does.
                let f = self.arm.felt(f);
                let (surface, object) = match touched.flatten() {
                    Some((p, body)) => (self.arm.point_to_master(p), body),
                    None => ([0.0; 3], u32::MAX),
                };
                // A sensor's force is contact; the world's coupling also carries the
                // tool's own inertia and damping, so there contact is a touch.
                let touching = match touched {
                    Some(_) => object != u32::MAX,
                    None => f.iter().any(|x| *x != 0.0),
                };
                if touching {
                    *flags |= Flags::CONTACT;
                    self.counters.contact_steps += 1;
                }
                (f, surface, object)
            }
            (None, Some(c)) => {
                *flags |= Flags::CONTACT;
                self.counters.contact_steps += 1;
                let f = self.arm.contact_force(c.surface, tool, c.stiffness);
                (f, c.surface, c.object as u32)
            }
            (None, None) => ([0.0; 3], [0.0; 3], u32::MAX),
        };
        (tool, force, surface, object)
    }

    /// h(n) into `h`: the control's value of the force, through the codec, with the
    /// provenance of the oldest position value it used; with the force, a real arm's
    /// measured torque about the tool (zero for the simulated point contact).
    fn reply(
        &mut self,
        v: &Forward,
        (force, torque): ([f64; 3], [f64; 3]),
        tool: [f64; 3],
        flags: Flags,
        h: &mut Option<Backward>,
    ) {
        self.last_force = force;
        let oldest = (0..3).min_by_key(|&i| v.signal.origin_seq[i]).unwrap_or(0);
        // The envelope (number, run, stamps) is the driver's.
        let out = h.insert(Backward::default());
        out.signal.value = self.control.transmit(force);
        out.signal.energy = self.control.energy();
        out.signal.sent_seq = [v.seq; 3];
        let speed = distance(tool, self.last_tool) / self.t_s;
        self.last_tool = tool;
        if self.codec.send(out.signal.value, speed) {
            self.counters.packets_sent += 1;
        } else {
            out.signal.flags |= Flags::UNSENT;
        }
        out.signal.origin_seq = [v.signal.origin_seq[oldest]; 3];
        out.signal.origin_ns = [v.signal.origin_ns[oldest]; 3];
        out.signal.delay_samples = [v.signal.delay_samples[oldest]; 3];
        out.signal.flags |= flags;
        // A 6-DoF sample is answered with a wrench.
        out.torque = self.arm.felt(torque);
        out.signal.flags |= v.signal.flags & Flags::POSE;
        // MMT: the tool and the force as the master sees them (its frame and axes), the
        // model as its handle meets it (less the clutch's offset).
        if let Some(m) = self.mmt.as_mut() {
            if m.update(tool, force, self.arm.clutch_shift()) {
                self.counters.models_sent += 1;
                // A new model goes out now, whatever the force's deadband says.
                if out.signal.flags.intersects(Flags::UNSENT) {
                    out.signal.flags.remove(Flags::UNSENT);
                    self.counters.packets_sent += 1;
                }
            }
            out.model = m.sent();
        }
    }
}

/// The scenario's environment changes by the first sample each holds from, latest
/// first (popped from the end: in the order `Environment::changes_in_order` gives).
fn changes(scenario: &Scenario) -> Vec<(u64, Change)> {
    let mut v: Vec<(u64, Change)> = scenario
        .environment
        .changes_in_order(scenario.t_s())
        .into_iter()
        .map(|(_, n, c)| (n, c.clone()))
        .collect();
    v.reverse();
    v
}

/// A force sensed at the tool, N in the arm's frame, and, from a physics world, its
/// contact point (arm's frame) and body, if it touches one (`None`: a real sensor,
/// which knows no surface).
type Sensor = ([f64; 3], Option<Option<([f64; 3], u32)>>);

/// How far from one a received quaternion's norm may be (the sender normalized it;
/// a wire carries it exactly): anything further is not a rotation and is rejected.
pub const ROTATION_TOLERANCE: f64 = 1e-6;
