//! What the slave does with its samples, as the loop's driver hands them over
//! (`tactile_runtime::driver`): one step of [`Slave`] on each v(n), with the real
//! robot's angles and force in place of the simulated arm where there is one, and
//! its position held while input is silent. The driver owns the pacing, the waits and
//! the protocol.

use crate::hsd::{Measured, Slave};
use std::time::Duration;
use tactile_devices::held::Held;
use tactile_devices::{Peripheral, Robot};
use tactile_math::joints::Joints;
use tactile_messages::samples::{Backward, Forward};
use tactile_records::slave::{SlaveCounters, SlaveSample, SlaveTotals};
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

/// A real robot as the loop holds it.
struct Hardware {
    robot: Box<dyn Robot>,
    /// Its joints as the loop holds them.
    held: Held<Joints>,
    /// What it was last commanded (held while it is lost).
    commanded: Option<Joints>,
    /// The reference of the step just taken, commanded once h(n) is on its way.
    due: Option<Joints>,
}

impl Hardware {
    fn new(robot: Box<dyn Robot>) -> Self {
        Hardware {
            robot,
            held: Held::default(),
            commanded: None,
            due: None,
        }
    }

    /// Reads the robot for this tick (its joints, its force sensor's force and
    /// torque); says so in the record when it is lost or back.
    fn read(&mut self, n: u64, io: &mut Io) -> Result<Measured, Failure> {
        let who = self.robot.describe();
        let judged = self.robot.read(io.now());
        let meanwhile = "holding its last safe reference";
        if let Some(what) = self.held.take(judged, ("robot", &who), meanwhile) {
            io.event(n, &what)?;
        }
        let measured = Measured {
            joints: self.held.theta,
            force: self.robot.force(io.now()),
            torque: self.robot.torque(),
        };
        Ok(measured)
    }

    /// Commands `reference`, or, while the robot is lost, the last reference it had.
    fn command(&mut self, reference: Joints) {
        if !self.held.lost {
            self.commanded = Some(reference);
        }
        if let Some(c) = self.commanded {
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

/// The slave's handler: its state machine, the real robot if there is one, and what
/// it keeps between the driver's calls.
pub struct SlaveHandler {
    slave: Slave,
    /// The real robot, if there is one (else the arm is simulated).
    robot: Option<Hardware>,
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
    pub fn new(slave: Slave, scenario: &Scenario, robot: Option<Box<dyn Robot>>) -> Self {
        SlaveHandler {
            slave,
            robot: robot.map(Hardware::new),
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
            world: self.slave.world_counters(),
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
        let h = self.robot.as_ref()?;
        Some(h.robot.as_ref() as &dyn Peripheral)
    }

    fn release(&mut self) -> Option<String> {
        self.robot.as_mut().map(Hardware::release)
    }

    fn live(&self) -> Option<SampleView> {
        Some(self.slave.arm().live(self.last_view?))
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
        if let Some(hw) = &mut self.robot {
            let measured = hw.read(v.seq, io)?;
            self.slave.measure(measured);
        }
        let step = self.slave.step(v, &mut out.backward);
        for e in self.slave.take_events() {
            io.event(v.seq, &e)?;
        }
        if let Some(hw) = &mut self.robot {
            hw.due = Some(self.slave.arm().reference());
        }
        let torque = out.backward.as_ref().map_or([0.0; 3], |h| h.torque);
        let joints = self.slave.arm().joints(torque, self.slave.rotation());
        // The live view's three angles are the paper arm's (a URDF arm shows its own).
        self.last_view = Some(SlaveView {
            theta: joints.q.to_array3(),
            velocity: None,
            torque: joints.tau.to_array3(),
            tool: step.tool,
            force: step.force,
        });
        out.record = Some(SlaveSample::Step(step, joints, self.slave.world_sample()));
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
        if let Some(hw) = &mut self.robot {
            if let Some(r) = hw.due.take() {
                hw.command(r);
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
            None => self.slave.hold(None),
            Some(hw) => {
                let measured = hw.read(last, io)?;
                let held = self.slave.hold(Some(&measured.joints));
                hw.command(self.slave.arm().reference());
                held
            }
        };
        for e in self.slave.take_events() {
            io.event(last, &e)?;
        }
        let joints = self.slave.arm().joints([0.0; 3], self.slave.rotation());
        Ok(Some(SlaveSample::Hold(
            held,
            joints,
            self.slave.world_sample(),
        )))
    }
}
