//! What the slave does with its samples, as the loop's driver hands them over
//! (`tactile_runtime::driver`): one step of [`Slave`] on each v(n), with the real
//! robot's angles and force in place of the simulated arm where there is one, and
//! its position held while input is silent. The driver owns the pacing, the waits and
//! the protocol.

use crate::hsd::{Measured, Slave};
use crate::urdf_arm::ArmState;
use std::time::Duration;
use tactile_devices::held::Held;
use tactile_devices::{Peripheral, Robot};
use tactile_messages::samples::{Backward, Forward};
use tactile_records::slave::{ArmJoints, SlaveCounters, SlaveSample, SlaveTotals, Step};
use tactile_ros::view::{SampleView, SlaveView};
use tactile_runtime::driver::{changed, Counts, Failure, Follower, Handler, Io, Reply};
use tactile_scenario::Scenario;

/// How long without input before the slave holds: the scenario's peer timeout in
/// samples, but never under 50 ms (a lockstep master may pause that long for its own
/// reasons).
pub fn hold_timeout(scenario: &Scenario) -> Duration {
    let t = Duration::from_nanos(scenario.faults.peer_timeout_samples * scenario.t_s_ns());
    t.max(Duration::from_millis(50))
}

/// The slave's handler: its state machine, the real robot if there is one, and what
/// it keeps between the driver's calls.
pub struct SlaveHandler {
    slave: Slave,
    robot: Option<Box<dyn Robot>>,
    /// The robot's angles as the loop holds them.
    held: Held,
    /// What the robot was last commanded (held while it is lost).
    commanded: Option<[f64; 3]>,
    /// The reference of the step just taken, commanded once h(n) is on its way.
    due: Option<[f64; 3]>,
    holding: bool,
    idle: (Duration, Duration),
    last_step: Option<Step>,
    clamps_seen: (u64, u64),
}

impl std::fmt::Debug for SlaveHandler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SlaveHandler")
            .field("robot", &self.robot.as_ref().map(|r| r.describe()))
            .field("holding", &self.holding)
            .finish_non_exhaustive()
    }
}

impl SlaveHandler {
    /// The handler of `slave` for `scenario`, with a real robot (`None`: the
    /// simulated arm).
    pub fn new(slave: Slave, scenario: &Scenario, robot: Option<Box<dyn Robot>>) -> Self {
        SlaveHandler {
            slave,
            robot,
            held: Held::default(),
            commanded: None,
            due: None,
            holding: false,
            idle: (
                hold_timeout(scenario),
                Duration::from_nanos(scenario.t_s_ns()),
            ),
            last_step: None,
            clamps_seen: (0, 0),
        }
    }

    /// Counters so far.
    pub fn counters(&self) -> SlaveCounters {
        self.slave.counters()
    }

    /// Reads the robot for this tick; says so in the record when it is lost or back.
    fn read(&mut self, n: u64, io: &mut Io) -> Result<Option<Measured>, Failure> {
        let Some(r) = self.robot.as_deref_mut() else {
            return Ok(None);
        };
        let who = r.describe();
        let judged = r.read(io.now());
        let meanwhile = "holding its last safe reference";
        if let Some(what) = self.held.take(judged, ("robot", &who), meanwhile) {
            io.event(n, &what)?;
        }
        Ok(Some(Measured {
            theta: self.held.theta,
            force: r.force(io.now()),
        }))
    }

    /// Commands `theta_ref`, or, while the robot is lost, the last reference it had.
    fn command(&mut self, theta_ref: [f64; 3]) {
        let Some(r) = self.robot.as_deref_mut() else {
            return;
        };
        if !self.held.lost {
            self.commanded = Some(theta_ref);
        }
        if let Some(c) = self.commanded {
            r.command(c, tactile_messages::clock::now_ns());
        }
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
            device: self
                .robot
                .as_ref()
                .map(|r| r.counters())
                .unwrap_or_default(),
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
    }

    fn peripheral(&self) -> Option<&dyn Peripheral> {
        self.robot.as_deref().map(|r| r as &dyn Peripheral)
    }

    fn release(&mut self) -> Option<String> {
        let r = self.robot.as_deref_mut()?;
        let heard = r.release();
        Some(format!(
            "{} commanded to hold where it is{}",
            r.describe(),
            if heard {
                ""
            } else {
                " (not heard from, or no controller listening: it holds its last command)"
            }
        ))
    }

    fn live(&self) -> Option<SampleView> {
        let s = self.last_step?;
        Some(SampleView {
            slave: Some(SlaveView {
                theta: s.theta,
                velocity: None,
                torque: s.torque,
                tool: s.tool,
                force: s.force,
            }),
            ..SampleView::default()
        })
    }
}

impl Follower for SlaveHandler {
    fn forward(&mut self, v: &Forward, io: &mut Io) -> Result<Reply<SlaveSample>, Failure> {
        if self.holding {
            self.holding = false;
            io.event(v.seq, "input back: following the master again")?;
        }
        if let Some(m) = self.read(v.seq, io)? {
            self.slave.measure(m);
        }
        let (h, step) = self.slave.step(v);
        self.due = Some(step.theta_ref);
        self.last_step = Some(step);
        let record = match self.slave.arm_state() {
            Some(a) => SlaveSample::ArmStep(step, joints(a)),
            None => SlaveSample::Step(step),
        };
        Ok(Reply {
            forward: None,
            backward: Some(h),
            record: Some(record),
        })
    }

    /// Nothing comes backward to the slave: a backward sample is another node's.
    fn backward(&mut self, _: &Backward, _: &mut Io) -> Result<Reply<SlaveSample>, Failure> {
        Ok(Reply {
            forward: None,
            backward: None,
            record: None,
        })
    }

    fn after(&mut self, _: &mut Io) {
        if let Some(r) = self.due.take() {
            self.command(r);
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
        let held = match self.read(last, io)? {
            None => self.slave.hold(),
            Some(m) => {
                let held = self.slave.hold_measured(m.theta);
                self.command(held.theta_ref);
                held
            }
        };
        Ok(Some(match self.slave.arm_state() {
            Some(a) => SlaveSample::ArmHold(held, joints(a)),
            None => SlaveSample::Hold(held),
        }))
    }
}

/// A URDF arm's joints as its record holds them.
fn joints(a: &ArmState) -> ArmJoints {
    ArmJoints {
        q_ref: a.q_ref.clone(),
        q: a.q.clone(),
        tau: a.tau.clone(),
    }
}
