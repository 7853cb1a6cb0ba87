//! The master side's per-sample logic (OP + MD + HMD) as a pure state machine.
//!
//! [`Master::forward`] turns sample n of the master's [`Input`] into c(n): the
//! simulated operator's or a real device's joints b(n) (the MD model), then FK-HMD, or
//! a pose device's position; a 6-DoF input's orientation and clutch with it, the same
//! for every kind. [`Master::backward`] turns
//! a received q(n) into joint torques p(n) = J(b)^T q (KFF-HMD). Each gives the
//! sample for the wire and the master's record of it. The process edge and the
//! in-process simulation call the same functions.
//!
//! The MD model is the hand's mode: `position`, an ideal hand that puts the handle on
//! the trajectory (the torques drive nothing), or `impedance`, a hand holding the
//! simulated device ([`HeldDevice`]) that the torques push back. The channel's control
//! ([`MasterSide`]) decides what is sent for c(n) and which force comes of q(n).
//! Either hand reaches the trajectory from the devices' home along [`Approach`].

use crate::human::Human;
use crate::operator::{Approach, Operate, OperatorSource, Scripted, IDENTITY};
use crate::simulated::HeldDevice;
use switch::{Rendering, Switch};
use tactile_control::codec::{Deadband, Estimate, Guess, Predictor};
use tactile_control::mmt::ModelReceiver;
use tactile_control::passivity::{MasterForce, MasterSide};
use tactile_devices::hand::Hand;
use tactile_math::engine::Engine;
use tactile_messages::samples::{Backward, Flags, Forward};
use tactile_records::master::{Answer, Effect, MasterCounters, Sent};
use tactile_scenario::ControlKind;
use tactile_scenario::{HandInput, HandMode, MasterConfig, Scenario, ScenarioError};

/// The master's input at one sample: the kinds of one master device. The simulated
/// operator gives a target the simulated hand moves the handle to; a device gives the
/// handle itself (three joints, or a position); either, if it is 6-DoF, an orientation
/// and a clutch, which [`Master::forward`] takes the same way for every kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Input {
    /// The scenario's operator: a simulated hand (ideal or impedance) on the simulated
    /// three-joint device, following the trajectory (its orientation and clutch too).
    Simulated,
    /// A real device: three joints (the paper's, or a gimbal's arm with its
    /// orientation) or a pose device.
    Device(DeviceReading),
}

/// A real device's reading as the loop holds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeviceReading {
    /// Joints or pose (`None` until the device has given one).
    pub hand: Option<Hand>,
    /// What `hand.point` holds: three joint angles or a position.
    pub kind: HandInput,
    /// The clutch, engaged or not (`None`: the device has none).
    pub clutch: Option<bool>,
}

/// The master: operator source, device model and HMD kernels.
#[derive(Debug)]
pub struct Master {
    engine: Engine,
    /// The physical master device: f64 kernels (encoders read the true angles).
    truth: Engine,
    source: OperatorSource,
    /// An operator from outside in place of `source`'s targets (the Python API).
    scripted: Option<Scripted>,
    t_s: f64,
    t_s_ns: u64,
    theta_md: [f64; 3],
    counters: MasterCounters,
    limits: MasterConfig,
    peer_timeout: u64,
    silent: u64,
    last_tau: [f64; 3],
    last_felt: [f64; 3],
    /// The impedance hand's device and where its intended position was last sample.
    held: Option<(HeldDevice, [f64; 3])>,
    /// The way from the devices' home onto the trajectory, for either hand.
    approach: Option<Approach>,
    control: MasterSide,
    last_theta: [f64; 3],
    codec: Deadband,
    predictor: Predictor,
    /// The operator's clutch is released at this sample (6-DoF only).
    released: bool,
    /// A real device's first reading: its pose is measured from there.
    origin: Option<Hand>,
    /// The devices' home (the handle with the joints at zero), m.
    home: [f64; 3],
    /// Where the handle is at this sample, m (the clutch spring's end).
    handle: [f64; 3],
    /// The device gives a position, not joints: there are no joint torques to compute.
    pose_input: bool,
    /// `control.kind = "mmt"`: the slave's latest model, rendered against the handle.
    mmt: Option<ModelReceiver>,
    /// Which force the hand is rendered, and the blend when that changes.
    switch: Switch,
    /// The simulated operator's tremor, wander and reaction (`[master.human]`).
    human: Option<Human>,
    /// The path's sample the hand is at (behind the run's after a pause).
    progress: u64,
}

/// `q` relative to `q0` (both `[x, y, z, w]`): the turn from `q0` to `q`, about the
/// base's axes (`q q0^-1`).
fn relative(q: [f64; 4], q0: [f64; 4]) -> [f64; 4] {
    let unit = |r: [f64; 4]| {
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(r[3], r[0], r[1], r[2]))
    };
    let d = unit(q) * unit(q0).inverse();
    [d.i, d.j, d.k, d.w]
}

impl Master {
    /// A master for the scenario with a loaded operator source.
    pub fn new(scenario: &Scenario, source: OperatorSource) -> Result<Master, ScenarioError> {
        source.check_six_dof(scenario)?;
        let geometry = scenario.device.geometry()?;
        let cordic = scenario.cordic.config()?;
        let no_engine = |e: tactile_rtl::RtlError| ScenarioError::Invalid {
            field: e.field().into(),
            problem: e.to_string(),
        };
        let lengths = geometry.lengths();
        let home = tactile_math::kernels::fk(&lengths, &tactile_math::arith::StdTrig, [0.0; 3]);
        // Wave variables are neither positions nor forces: the codec measures them from
        // zero, and the predictor's plausibility bound is wider.
        let wave = scenario.control.kind == ControlKind::Wave;
        let approach = Approach::new(
            &source,
            home,
            scenario.master.hand.approach_s,
            scenario.t_s(),
        );
        let held = (scenario.master.hand.mode == HandMode::Impedance).then(|| {
            let device = HeldDevice::new(
                scenario.master.device.clone(),
                scenario.master.hand.clone(),
                lengths,
                [0.0; 3],
            );
            (device, home)
        });
        Ok(Master {
            engine: tactile_rtl::engine(scenario.arithmetic, geometry, cordic)
                .map_err(no_engine)?,
            truth: Engine::new(tactile_math::arith::ArithKind::F64, geometry, cordic)
                .map_err(|e| no_engine(e.into()))?,
            source,
            scripted: None,
            t_s: scenario.t_s(),
            t_s_ns: scenario.t_s_ns(),
            theta_md: [0.0; 3],
            counters: MasterCounters::default(),
            limits: scenario.master.clone(),
            peer_timeout: scenario.faults.peer_timeout_samples,
            silent: 0,
            last_tau: [0.0; 3],
            last_felt: [0.0; 3],
            held,
            approach,
            last_theta: [0.0; 3],
            codec: Deadband::new(
                &scenario.codec.forward,
                if wave { [0.0; 3] } else { home },
                if wave { 1e-3 } else { 5e-4 },
            ),
            predictor: Predictor::new(
                &scenario.master.predictor,
                scenario.t_s(),
                if wave { 1e6 } else { 1e5 },
            ),
            control: MasterSide::new(&scenario.control, scenario.t_s()),
            released: false,
            origin: None,
            home,
            handle: home,
            pose_input: false,
            mmt: (scenario.control.kind == ControlKind::Mmt).then(|| {
                ModelReceiver::new(
                    &scenario.control.mmt,
                    scenario.t_s(),
                    scenario.master.force_limit,
                )
            }),
            switch: Switch::new(scenario.master.switch_ramp_s, scenario.t_s()),
            human: Human::new(&scenario.master.human, scenario.t_s(), scenario.seed),
            progress: 0,
        })
    }

    /// Takes the simulated hand's targets from `operate` instead of the scenario's
    /// operator (whose orientation and clutch are then refused: `operate` gives
    /// positions). The approach from home always runs, since the first target is not
    /// known before the run. Call before the first sample.
    pub fn set_operator(&mut self, operate: Box<dyn Operate>) -> Result<(), ScenarioError> {
        if self.source.six_dof() {
            return Err(ScenarioError::Invalid {
                field: "operator".into(),
                problem: "its trajectory has an orientation or a clutch (6-DoF), but a scripted operator gives positions only: give a 3-DoF operator".into(),
            });
        }
        self.approach = Approach::from_home(self.home, self.limits.hand.approach_s);
        self.scripted = Some(Scripted::new(operate, self.home));
        Ok(())
    }

    /// Fills gaps in h(n) with `guess` instead of the predictor's kind
    /// (`[master.predictor]`'s acceptance and horizon still hold).
    pub fn set_predictor(&mut self, guess: Box<dyn Guess>) {
        self.predictor.set_guess(guess);
    }

    /// Counters so far.
    pub fn counters(&self) -> MasterCounters {
        MasterCounters {
            rtl: self.engine.hardware_clocks(),
            ..self.counters
        }
    }

    /// Sample n forward from the master's input, whichever kind it is: b(n) (the
    /// simulated hand's device, a device's three joints) through FK-HMD, or a pose
    /// device's position, as c(n), written with its record into `out` (filled where they lie:
    /// returned, they were copied at each call on the way out, a dozen copies a
    /// sample). A 6-DoF input's orientation and clutch go onto c(n) the same way for
    /// every kind. `now_ns` is the tick time; it becomes the origin timestamp of all
    /// three values.
    pub fn forward(&mut self, n: u64, now_ns: u64, input: Input, out: (&mut Forward, &mut Sent)) {
        let (f, sent) = out;
        let pose = match input {
            Input::Simulated => self.simulated(n, now_ns, (&mut *f, &mut *sent)),
            Input::Device(reading) => self.measured(n, now_ns, reading, (&mut *f, &mut *sent)),
        };
        if let Some((r, engaged)) = pose {
            self.turn(f, sent, r, engaged);
        }
    }

    /// The simulated operator's sample n: a(n) -> MD encoders b(n) -> c(n); its
    /// orientation and clutch if the trajectory is 6-DoF.
    fn simulated(
        &mut self,
        n: u64,
        now_ns: u64,
        out: (&mut Forward, &mut Sent),
    ) -> Option<([f64; 4], bool)> {
        let (target, hand_force) = match self.held.is_some() {
            false => (self.ideal_hand(n), [0.0; 3]),
            true => self.impedance_hand(n),
        };
        self.encode(n, now_ns, target, hand_force, out);
        if !self.source.six_dof() {
            return None;
        }
        let t = n as f64 * self.t_s;
        let r = self
            .source
            .rotation(self.progress, self.t_s)
            .unwrap_or(IDENTITY);
        let r = match &self.approach {
            Some(a) => a.apply_rotation(r, t),
            None => r,
        };
        Some((r, self.source.engaged(self.progress, self.t_s)))
    }

    /// A 6-DoF sample's orientation `r` and clutch onto c(n) and its record; released,
    /// the operator feels the clutch spring instead of the robot.
    fn turn(&mut self, f: &mut Forward, sent: &mut Sent, r: [f64; 4], engaged: bool) {
        f.rotation = r;
        f.signal.flags |= Flags::POSE;
        sent.rotation = Some(r);
        self.released = !engaged;
        if let Some(m) = self.mmt.as_mut() {
            m.clutch(self.released, self.handle);
        }
        if self.released {
            f.signal.flags |= Flags::RELEASED;
            sent.released = true;
        }
    }

    /// A real device's sample n (the operator's hand is the real one, so the target is
    /// where the handle is): b(n) = three joints as measured, or a pose device's
    /// position moved so that its first reading is the devices' home. A 6-DoF device's
    /// orientation goes relative to its first reading (the operator's home, as a
    /// trajectory's), with its clutch (`None`: none, always engaged). Until the device
    /// has given a reading the handle is taken to be at home, unturned (no origin is
    /// captured from it).
    fn measured(
        &mut self,
        n: u64,
        now_ns: u64,
        reading: DeviceReading,
        (f, sent): (&mut Forward, &mut Sent),
    ) -> Option<([f64; 4], bool)> {
        self.pose_input = reading.kind == HandInput::Pose;
        let (hand, origin) = match reading.hand {
            Some(h) => (h, *self.origin.get_or_insert(h)),
            None => {
                let home = Hand {
                    point: [0.0; 3],
                    rotation: None,
                };
                (home, home)
            }
        };
        match reading.kind {
            HandInput::Joints => {
                self.theta_md = hand.point;
                let handle = self.truth.fk(hand.point);
                self.encode(n, now_ns, handle, [0.0; 3], (f, sent));
            }
            HandInput::Pose => {
                let c = [0, 1, 2].map(|k| self.home[k] + hand.point[k] - origin.point[k]);
                let moved = match n {
                    0 => [0.0; 3],
                    _ => [0, 1, 2].map(|k| c[k] - self.handle[k]),
                };
                self.encode_at(n, now_ns, (c, c, [0.0; 3]), moved, (f, sent));
            }
        }
        if hand.rotation.is_none() && reading.clutch.is_none() {
            return None;
        }
        let r = match (hand.rotation, origin.rotation) {
            (Some(q), Some(q0)) => relative(q, q0),
            _ => IDENTITY,
        };
        Some((r, reading.clutch.unwrap_or(true)))
    }

    /// The torques commanded now, N m.
    pub fn tau(&self) -> [f64; 3] {
        self.last_tau
    }

    /// The force the operator is made to feel now (after the last answer or miss), N.
    pub fn felt(&self) -> [f64; 3] {
        self.last_felt
    }

    /// FK-HMD of b(n), the control and codec, and the record of the sample.
    fn encode(
        &mut self,
        n: u64,
        now_ns: u64,
        target: [f64; 3],
        hand_force: [f64; 3],
        out: (&mut Forward, &mut Sent),
    ) {
        let c = self.engine.fk(self.theta_md);
        let moved = self.moved(n);
        let handle = self.truth.fk(self.theta_md);
        let (f, sent) = out;
        self.encode_at(n, now_ns, (c, target, hand_force), moved, (f, &mut *sent));
        self.handle = handle;
        sent.handle = handle;
    }

    /// c(n) (`at`: c, the hand's target and its force) having `moved` since the last
    /// sample, through the control and codec, and the record of the sample, into `out`.
    fn encode_at(
        &mut self,
        n: u64,
        now_ns: u64,
        (c, target, hand_force): ([f64; 3], [f64; 3], [f64; 3]),
        moved: [f64; 3],
        (f, sent): (&mut Forward, &mut Sent),
    ) {
        self.handle = c;
        self.control.measure(moved);
        // The envelope (number, run, stamps) is the driver's.
        *f = Forward::default();
        f.signal.value = self.control.transmit(c);
        f.signal.energy = self.control.energy();
        let speed = tactile_math::vec3::norm(self.control.velocity());
        if self.codec.send(f.signal.value, speed) {
            self.counters.packets_sent += 1;
        } else {
            f.signal.flags |= Flags::UNSENT;
        }
        f.signal.sent_seq = [n; 3];
        f.signal.origin_seq = [n; 3];
        f.signal.origin_ns = [now_ns; 3];
        self.counters.sent += 1;
        *sent = Sent {
            n,
            target,
            theta_md: self.theta_md,
            c,
            handle: c,
            hand_force,
            tick_ns: now_ns,
            send_ns: 0,
            rotation: None,
            released: false,
        };
    }

    /// The handle's displacement since the last sample, J(b(n)) (b(n) - b(n-1)), in
    /// the HMD's arithmetic.
    fn moved(&mut self, n: u64) -> [f64; 3] {
        let last = std::mem::replace(&mut self.last_theta, self.theta_md);
        if n == 0 {
            return [0.0; 3];
        }
        let j = self.engine.jacobian(self.theta_md);
        let d = [0, 1, 2].map(|k| self.theta_md[k] - last[k]);
        [0, 1, 2].map(|i| j[i][0] * d[0] + j[i][1] * d[1] + j[i][2] * d[2])
    }

    /// True while the loop is broken (no answer for the peer timeout).
    pub fn peer_lost(&self) -> bool {
        self.silent >= self.peer_timeout
    }

    /// q(n) back: clamp the force to the device's limit, KFF-HMD torques on the current
    /// master angles, clamp them. A NaN or infinite force never reaches a torque: it is
    /// rejected and the last torque held. The edge stamps `MASTER_DONE` and then calls
    /// [`Master::account`].
    pub fn backward(&mut self, q: &Backward) -> Answer {
        self.counters.received += 1;
        if self.peer_lost() {
            self.counters.resumes += 1;
        }
        self.silent = 0;
        let mut flags = Flags::NONE;
        // CPD/JPD-HMD: a value not sent or not new (the channel held it) is filled by
        // the predictor; one that is not physically possible (not finite, too large,
        // too fast) is rejected and filled likewise, never reaching a torque.
        let new = !q
            .signal
            .flags
            .intersects(Flags::UNSENT | Flags::SUBSTITUTED);
        let fresh = (new || !self.predictor.has_value()).then(|| {
            let at = q.signal.sent_seq.iter().copied().min().unwrap_or(q.seq);
            (at, q.signal.value)
        });
        let est = self.predictor.estimate(q.seq, fresh);
        let energy = match est {
            Estimate::Fresh(_) => q.signal.energy,
            _ => [0.0; 3],
        };
        match est {
            Estimate::Rejected(_) => {
                self.counters.rejected += 1;
                flags |= Flags::REJECTED;
            }
            Estimate::Refused(_) => flags |= Flags::GUESS_REFUSED,
            Estimate::Fresh(_) | Estimate::Predicted(_) => {}
        }
        let value = self.rendered(q, est.value());
        let out = self.control.receive(value, energy, self.limits.force_limit);
        if self.command(&out) {
            flags |= Flags::CLAMPED;
        }
        self.answer(q, flags, &out)
    }

    /// Takes the control's force as the felt force and its KFF-HMD torques, clamped;
    /// counts the clamps and says whether there were any.
    fn command(&mut self, out: &MasterForce) -> bool {
        let (mode, to) = match self.released {
            false => (Rendering::Loop, out.force),
            true => (Rendering::Clutch, self.clutch_spring()),
        };
        let felt = self.switch.render(mode, to, self.last_felt);
        // A pose device takes the force itself: no joints, no torques to clamp.
        let raw = match self.pose_input {
            false => self.engine.kff(self.theta_md, felt),
            true => [0.0; 3],
        };
        let tau: [f64; 3] = [0, 1, 2].map(|j| {
            let l = self.limits.torque_limit[j];
            raw[j].clamp(-l, l)
        });
        let tau_clamped = tau.iter().zip(&raw).filter(|(a, b)| a != b).count() as u64;
        self.counters.force_clamps += u64::from(out.clamped);
        self.counters.torque_clamps += tau_clamped;
        self.last_felt = felt;
        self.last_tau = tau;
        u64::from(out.clamped) + tau_clamped > 0
    }

    /// While the clutch is released: the spring towards the devices' home, within the
    /// force limit (zero without one).
    fn clutch_spring(&self) -> [f64; 3] {
        let (k, limit) = (self.limits.clutch_spring, self.limits.force_limit);
        if k == 0.0 {
            return [0.0; 3];
        }
        [0, 1, 2].map(|i| (k * (self.home[i] - self.handle[i])).clamp(-limit, limit))
    }

    fn answer(&self, q: &Backward, flags: Flags, out: &MasterForce) -> Answer {
        Answer {
            n: q.seq,
            q: q.signal,
            stamps: q.stamps,
            effect: self.effect(flags, out),
            round_trip_ns: 0,
            overhead_ns: 0,
            late: false,
        }
    }

    /// What was commanded, and the books after it.
    fn effect(&self, flags: Flags, out: &MasterForce) -> Effect {
        Effect {
            tau: self.last_tau,
            felt: self.last_felt,
            flags,
            observer: out.observer,
            port_net_j: self.control.ledger().net(),
            dissipated_j: out.dissipated,
            model_injected_j: self.mmt.as_ref().map_or(0.0, |r| r.renderer().injected()),
        }
    }
}

// What the master does when no answer came, and the round trip of one that did.
mod hand;
mod miss;
// MMT's models taken and rendered against the handle.
mod model;
mod switch;

#[cfg(test)]
mod tests;

#[cfg(test)]
mod device_tests;
