//! What the slave does with its samples, as the loop's driver hands them over
//! (`tactile_runtime::driver`): one step of [`Slave`] on each v(n), with the real
//! robot's angles and force in place of the simulated arm where there is one, and
//! its position held while input is silent. The driver owns the pacing, the waits and
//! the protocol.

use crate::hsd::{Measured, Slave};
use crate::urdf_arm::UrdfArm;
use std::sync::Arc;
use std::time::Duration;
use tactile_devices::held::Held;
use tactile_devices::{Peripheral, Robot};
use tactile_messages::samples::{Backward, Forward};
use tactile_records::slave::{ArmJoints, SlaveCounters, SlaveSample, SlaveTotals};
use tactile_ros::view::{ArmSample, SampleView, SlaveView};
use tactile_runtime::driver::{changed, Counts, Failure, Follower, Handler, Io, Reply};
use tactile_scenario::Scenario;

/// How long without input before the slave holds: the scenario's peer timeout in
/// samples, but never under 50 ms (a lockstep master may pause that long for its own
/// reasons).
pub fn hold_timeout(scenario: &Scenario) -> Duration {
    let t = Duration::from_nanos(scenario.faults.peer_timeout_samples * scenario.t_s_ns());
    t.max(Duration::from_millis(50))
}

/// A real robot: the paper's three joints, or an arm from its URDF.
pub enum RealRobot {
    /// Three joints shaped like the paper's arm.
    Paper(Box<dyn Robot>),
    /// An arm of `[slave.arm]`, its joints by the URDF's names.
    Arm(Box<dyn Robot<Vec<f64>>>),
}

impl std::fmt::Debug for RealRobot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RealRobot::Paper(r) => write!(f, "Paper({})", r.describe()),
            RealRobot::Arm(r) => write!(f, "Arm({})", r.describe()),
        }
    }
}

/// A real robot as the loop holds it.
struct Hardware<V> {
    robot: Box<dyn Robot<V>>,
    /// Its joints as the loop holds them.
    held: Held<V>,
    /// What it was last commanded (held while it is lost).
    commanded: Option<V>,
    /// The reference of the step just taken, commanded once h(n) is on its way.
    due: Option<V>,
}

/// What a robot gave for one tick: its joints, its force sensor's force (`None`
/// without one) and the torque that came with it.
type Reading<V> = (V, Option<[f64; 3]>, [f64; 3]);

impl<V: Clone + Default> Hardware<V> {
    fn new(robot: Box<dyn Robot<V>>) -> Self {
        Hardware {
            robot,
            held: Held::default(),
            commanded: None,
            due: None,
        }
    }

    /// Reads the robot for this tick (its joints, its force sensor's force and
    /// torque); says so in the record when it is lost or back.
    fn read(&mut self, n: u64, io: &mut Io) -> Result<Reading<V>, Failure> {
        let who = self.robot.describe();
        let judged = self.robot.read(io.now());
        let meanwhile = "holding its last safe reference";
        if let Some(what) = self.held.take(judged, ("robot", &who), meanwhile) {
            io.event(n, &what)?;
        }
        let force = self.robot.force(io.now());
        Ok((self.held.theta.clone(), force, self.robot.torque()))
    }

    /// Commands `reference`, or, while the robot is lost, the last reference it had.
    fn command(&mut self, reference: V) {
        if !self.held.lost {
            self.commanded = Some(reference);
        }
        if let Some(c) = self.commanded.clone() {
            self.robot.command(c, tactile_messages::clock::now_ns());
        }
    }

    fn release(&mut self) -> String {
        let heard = self.robot.release();
        format!(
            "{} commanded to hold where it is{}",
            self.robot.describe(),
            if heard {
                ""
            } else {
                " (not heard from, or no controller listening: it holds its last command)"
            }
        )
    }
}

/// The real robot the handler drives, if any.
enum Robots {
    None,
    Paper(Hardware<[f64; 3]>),
    Arm(Hardware<Vec<f64>>),
}

/// The slave's handler: its state machine, the real robot if there is one, and what
/// it keeps between the driver's calls.
pub struct SlaveHandler {
    slave: Slave,
    robot: Robots,
    /// A URDF arm's base link and joint names, for the live view.
    arm_names: Option<(Arc<str>, Arc<[String]>)>,
    holding: bool,
    idle: (Duration, Duration),
    /// The last step's state for the live view (a step's record is 368 bytes; the
    /// view needs a quarter of it).
    last_view: Option<SlaveView>,
    clamps_seen: (u64, u64),
    /// A URDF arm's failed dynamics periods at the last second's log.
    failures_seen: u64,
}

impl std::fmt::Debug for SlaveHandler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SlaveHandler")
            .field("robot", &self.peripheral().map(|r| r.describe()))
            .field("holding", &self.holding)
            .finish_non_exhaustive()
    }
}

impl SlaveHandler {
    /// The handler of `slave` for `scenario`, with a real robot (`None`: the
    /// simulated arm).
    pub fn new(slave: Slave, scenario: &Scenario, robot: Option<RealRobot>) -> Self {
        let arm_names = slave.arm().map(|a| {
            let c = a.chain();
            let names: Vec<String> = c.dofs.iter().map(|d| d.name.clone()).collect();
            (Arc::from(c.base.as_str()), Arc::from(names))
        });
        SlaveHandler {
            slave,
            arm_names,
            robot: match robot {
                None => Robots::None,
                Some(RealRobot::Paper(r)) => Robots::Paper(Hardware::new(r)),
                Some(RealRobot::Arm(r)) => Robots::Arm(Hardware::new(r)),
            },
            holding: false,
            idle: (
                hold_timeout(scenario),
                Duration::from_nanos(scenario.t_s_ns()),
            ),
            last_view: None,
            clamps_seen: (0, 0),
            failures_seen: 0,
        }
    }

    /// Counters so far.
    pub fn counters(&self) -> SlaveCounters {
        self.slave.counters()
    }
}

impl Handler for SlaveHandler {
    type Sample = SlaveSample;
    type Totals = SlaveTotals;

    fn totals(&self, c: &Counts) -> SlaveTotals {
        SlaveTotals {
            counters: self.slave.counters(),
            v_in: c.ports.forward_in,
            h_out: c.ports.backward_out,
            device: self.peripheral().map(|r| r.counters()).unwrap_or_default(),
        }
    }

    fn log_second(&mut self, t: &SlaveTotals) {
        let now = (t.counters.torque_clamps, t.counters.ik_clamped);
        if let Some((last, all)) = changed(&mut self.clamps_seen, now) {
            tracing::info!(
                "clamped: {} joint torques to the limit and {} IK targets to the workspace in the last second ({} and {} in all)",
                last.0, last.1, all.0, all.1
            );
        }
        let failures = t.counters.dynamics_failed;
        if failures > self.failures_seen {
            tracing::warn!(
                "slave.arm: the dynamics failed in {} periods in the last second ({failures} in all): the arm stood still in each",
                failures - self.failures_seen
            );
            self.failures_seen = failures;
        }
    }

    fn peripheral(&self) -> Option<&dyn Peripheral> {
        match &self.robot {
            Robots::None => None,
            Robots::Paper(h) => Some(h.robot.as_ref() as &dyn Peripheral),
            Robots::Arm(h) => Some(h.robot.as_ref() as &dyn Peripheral),
        }
    }

    fn release(&mut self) -> Option<String> {
        match &mut self.robot {
            Robots::None => None,
            Robots::Paper(h) => Some(h.release()),
            Robots::Arm(h) => Some(h.release()),
        }
    }

    fn live(&self) -> Option<SampleView> {
        let s = self.last_view?;
        if let (Some(arm), Some((base, names))) = (self.slave.arm(), &self.arm_names) {
            let a = arm.state();
            return Some(SampleView {
                arm: Some(ArmSample {
                    base: Arc::clone(base),
                    names: Arc::clone(names),
                    q: a.q.clone(),
                    effort: a.tau.clone(),
                    tool: arm.tool_in_base(),
                    force: s.force,
                }),
                ..SampleView::default()
            });
        }
        Some(SampleView {
            slave: Some(s),
            ..SampleView::default()
        })
    }
}

impl Follower for SlaveHandler {
    fn forward(
        &mut self,
        v: &Forward,
        out: &mut Reply<SlaveSample>,
        io: &mut Io,
    ) -> Result<(), Failure> {
        if self.holding {
            self.holding = false;
            io.event(v.seq, "input back: following the master again")?;
        }
        match &mut self.robot {
            Robots::None => {}
            Robots::Paper(hw) => {
                let (theta, force, _) = hw.read(v.seq, io)?;
                self.slave.measure(Measured { theta, force });
            }
            Robots::Arm(hw) => {
                let (q, force, torque) = hw.read(v.seq, io)?;
                self.slave.measure_arm(q, force, torque);
            }
        }
        let step = self.slave.step(v, &mut out.backward);
        match &mut self.robot {
            Robots::None => {}
            Robots::Paper(hw) => hw.due = Some(step.theta_ref),
            Robots::Arm(hw) => hw.due = self.slave.arm_state().map(|a| a.q_ref.clone()),
        }
        self.last_view = Some(SlaveView {
            theta: step.theta,
            velocity: None,
            torque: step.torque,
            tool: step.tool,
            force: step.force,
        });
        let torque = out.backward.as_ref().map_or([0.0; 3], |h| h.torque);
        out.record = Some(match self.slave.arm() {
            Some(a) => {
                SlaveSample::ArmStep(step, Box::new(joints(a, torque, self.slave.rotation())))
            }
            None => SlaveSample::Step(step),
        });
        Ok(())
    }

    /// Nothing comes backward to the slave: a backward sample is another node's.
    fn backward(
        &mut self,
        _: &Backward,
        _: &mut Reply<SlaveSample>,
        _: &mut Io,
    ) -> Result<(), Failure> {
        Ok(())
    }

    fn after(&mut self, _: &mut Io) {
        match &mut self.robot {
            Robots::None => {}
            Robots::Paper(hw) => {
                if let Some(r) = hw.due.take() {
                    hw.command(r);
                }
            }
            Robots::Arm(hw) => {
                if let Some(r) = hw.due.take() {
                    hw.command(r);
                }
            }
        }
    }

    fn idle_timing(&self) -> Option<(Duration, Duration)> {
        Some(self.idle)
    }

    /// Input went silent: hold, one step per t_s, until it returns.
    fn idle(&mut self, last: u64, io: &mut Io) -> Result<Option<SlaveSample>, Failure> {
        if !self.holding {
            self.holding = true;
            tracing::warn!("input silent for {:?}: holding position", self.idle.0);
            io.event(last, "input silent: holding position")?;
        }
        let held = match &mut self.robot {
            Robots::None => self.slave.hold(),
            Robots::Paper(hw) => {
                let (theta, ..) = hw.read(last, io)?;
                let held = self.slave.hold_measured(theta);
                hw.command(held.theta_ref);
                held
            }
            Robots::Arm(hw) => {
                let (q, ..) = hw.read(last, io)?;
                let held = self.slave.hold_measured_arm(&q);
                if let Some(a) = self.slave.arm_state() {
                    hw.command(a.q_ref.clone());
                }
                held
            }
        };
        Ok(Some(match self.slave.arm() {
            Some(a) => {
                SlaveSample::ArmHold(held, Box::new(joints(a, [0.0; 3], self.slave.rotation())))
            }
            None => SlaveSample::Hold(held),
        }))
    }
}

/// A URDF arm's joints and tool orientation as its record holds them.
fn joints(arm: &UrdfArm, torque: [f64; 3], master: Option<[f64; 4]>) -> ArmJoints {
    let a = arm.state();
    let (offset, offset_rotation) = arm.offsets();
    ArmJoints {
        q_ref: a.q_ref.clone(),
        q: a.q.clone(),
        tau: a.tau.clone(),
        torque,
        target_rotation: arm.target_rotation(),
        tool_rotation: arm.tool_rotation(),
        target_position: arm.target_position(),
        tool_position: arm.tool_in_base(),
        released: arm.released(),
        master_rotation: master.unwrap_or([0.0, 0.0, 0.0, 1.0]),
        offset,
        offset_rotation,
    }
}
