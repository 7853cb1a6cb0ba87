//! The slave process's edge: takes v(n), runs one step of [`Slave`], publishes h(n) and
//! records the step. When v(n) stops coming for the peer timeout, the slave holds its
//! position, one step per t_s, until input returns.

use crate::hsd::{Measured, Slave};
use crate::live::SlaveLive;
use crate::record::{SlaveSample, SlaveTotals};
use std::time::{Duration, Instant};
use tactile_messages::clock::now_ns;
use tactile_messages::samples::{stage, Backward, FLAG_END, FLAG_PROBE};
use tactile_node::args::NodeError;
use tactile_node::device::{LiveSink, Robot};
use tactile_node::held::{wait_heard, Held, Waited};
use tactile_node::link::{Idle, LinkError};
use tactile_node::link::{RunFilter, SlaveLink};
use tactile_node::pace::{recv_paced, Pacer};
use tactile_node::recorder::Recorder;
use tactile_scenario::{Mode, Scenario, ScenarioError};
use thiserror::Error;

/// What went wrong in the slave process.
#[derive(Debug, Error)]
pub enum SlaveError {
    /// The scenario is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The link failed.
    #[error(transparent)]
    Ipc(#[from] LinkError),
    /// The record could not be written.
    #[error("{0}")]
    Record(String),
}

impl From<NodeError> for SlaveError {
    fn from(e: NodeError) -> Self {
        SlaveError::Record(e.to_string())
    }
}

/// What the slave loop touches besides its link: a real robot in place of the
/// simulated arm, and the live view. Neither by default.
#[derive(Default)]
pub struct Outside<'a> {
    /// The robot through ros2_control.
    pub robot: Option<&'a mut dyn Robot>,
    /// Where each k-th step goes for the live view.
    pub live: Option<&'a mut dyn LiveSink<SlaveLive>>,
}

impl std::fmt::Debug for Outside<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Outside")
            .field("robot", &self.robot.as_ref().map(|d| d.describe()))
            .field("live", &self.live.is_some())
            .finish()
    }
}

/// The real robot as the loop keeps it: its angles as held and what it was last
/// commanded (held while it is lost).
struct RobotEdge<'a> {
    robot: &'a mut dyn Robot,
    held: Held,
    commanded: Option<[f64; 3]>,
}

impl RobotEdge<'_> {
    /// Reads the robot for this tick; says so in the record when it is lost or back.
    fn read(&mut self, rec: &mut SlaveRecorder, n: u64) -> Result<Measured, SlaveError> {
        let who = self.robot.describe();
        let meanwhile = "holding its last safe reference";
        let seen = self
            .held
            .take(self.robot.read(now_ns()), ("robot", &who), meanwhile);
        if let Some(what) = seen {
            rec.event(n, what)?;
        }
        Ok(Measured {
            theta: self.held.theta,
            force: self.robot.force(now_ns()),
        })
    }

    /// Commands `theta_ref`, or, while the robot is lost, the last reference it had.
    fn command(&mut self, theta_ref: [f64; 3]) {
        if !self.held.lost {
            self.commanded = Some(theta_ref);
        }
        if let Some(r) = self.commanded {
            self.robot.command(r, now_ns());
        }
    }
}

/// Waits (as long as it takes) until the robot has sent a good message; false if a
/// stop request came.
fn wait_for_robot(robot: &dyn Robot) -> Result<bool, SlaveError> {
    let waited = wait_heard(&|| robot.heard(), &robot.describe(), None)
        .map_err(|e| SlaveError::Record(e.to_string()))?;
    Ok(waited == Waited::Heard)
}

/// The slave's recorder.
pub type SlaveRecorder = Recorder<SlaveSample, SlaveTotals>;

/// How long without input before the slave holds: the scenario's peer timeout in
/// samples, but never under 50 ms (a lockstep master may pause that long for its own
/// reasons).
pub fn hold_timeout(scenario: &Scenario) -> Duration {
    let t = Duration::from_nanos(scenario.faults.peer_timeout_samples * scenario.t_s_ns());
    t.max(Duration::from_millis(50))
}

/// Runs the slave loop over any link until the end-of-run sample (true) or a stop
/// request (false).
pub fn run_with<L: SlaveLink + ?Sized>(
    scenario: &Scenario,
    link: &L,
    rec: &mut SlaveRecorder,
    wake_early: Duration,
    outside: Outside<'_>,
) -> Result<bool, SlaveError> {
    let mut slave = Slave::new(scenario)?;
    let Outside { robot, mut live } = outside;
    let mut robot = match robot {
        Some(r) => {
            if !wait_for_robot(&*r)? {
                rec.stop(SlaveTotals::default(), "interrupted")?;
                return Ok(false);
            }
            rec.event(0, format!("robot found: {}", r.describe()))?;
            Some(RobotEdge {
                robot: r,
                held: Held::default(),
                commanded: None,
            })
        }
        None => None,
    };
    let timeout = hold_timeout(scenario);
    let t_s = Duration::from_nanos(scenario.t_s_ns());
    // Realtime: sleep until just before v(n) is due, learned from its arrivals.
    let mut pacer = (scenario.mode == Mode::Realtime)
        .then(|| Pacer::new(scenario.t_s_ns(), wake_early.as_nanos() as u64));
    let mut filter = RunFilter::default();
    let mut last_seq = 0;
    let totals = |slave: &Slave, filter: &RunFilter, robot: &Option<RobotEdge>| {
        let (mut v_in, h_out) = link.stats();
        v_in.foreign += filter.foreign;
        SlaveTotals {
            counters: slave.counters(),
            v_in,
            h_out,
            device: robot
                .as_ref()
                .map(|r| r.robot.counters())
                .unwrap_or_default(),
        }
    };
    // No input yet: wait as long as it takes for the first sample.
    let mut deadline: Option<Instant> = None;
    let mut holding = false;
    let mut clamps = (0, 0);
    let mut robot_seen = tactile_node::device::DeviceCounters::default();
    let completed = loop {
        let until = deadline.unwrap_or_else(|| Instant::now() + Duration::from_secs(3600));
        let (got, waiting) = recv_paced(pacer.as_ref(), until, |d| link.recv(d))?;
        match got {
            Ok(mut v) => {
                let mut joined = None;
                if !filter.admit(v.run, &mut joined) {
                    continue;
                }
                if let Some(t) = joined {
                    rec.run(t)?;
                }
                let flags = v.signal.flags;
                if flags & FLAG_END != 0 {
                    rec.event(last_seq, "end of run from the master")?;
                    break true;
                }
                if flags & FLAG_PROBE != 0 {
                    let mut echo = Backward {
                        seq: v.seq,
                        run: v.run,
                        ..Backward::default()
                    };
                    echo.signal.flags = FLAG_PROBE;
                    link.send_h(echo, true)?;
                    continue;
                }
                if deadline.is_none() {
                    rec.event(v.seq, "first sample: following the master")?;
                } else if holding {
                    rec.event(v.seq, "input back: following the master again")?;
                }
                holding = false;
                last_seq = v.seq;
                v.stamps[stage::SLAVE_RECV] = now_ns();
                if let Some(p) = &mut pacer {
                    let t = v.stamps[stage::SLAVE_RECV];
                    p.arrived(v.seq, t, waiting);
                }
                if let Some(r) = &mut robot {
                    let m = r.read(rec, v.seq)?;
                    slave.measure(m);
                }
                let (mut h, step) = slave.step(&v);
                h.run = v.run;
                h.stamps[stage::SLAVE_SEND] = now_ns();
                link.send_h(h, false)?;
                // The emulator usually shares this CPU, waiting for h(n): let it take
                // h(n) on to the master now, and write the record after (measured:
                // the hop's p50 from 10.3 us to 1.4 us at 1 kHz under SCHED_FIFO).
                std::thread::yield_now();
                if let Some(r) = &mut robot {
                    r.command(step.theta_ref);
                }
                if let Some(l) = live.as_deref_mut() {
                    if l.due(step.n) {
                        l.offer(SlaveLive { step });
                    }
                }
                rec.sample(SlaveSample::Step(step))?;
                deadline = Some(Instant::now() + timeout);
            }
            Err(Idle::Timeout) => {
                if deadline.is_some() {
                    // Input went silent: hold, one step per t_s, until it returns.
                    if !holding {
                        holding = true;
                        tracing::warn!("input silent for {timeout:?}: holding position");
                        rec.event(last_seq, "input silent: holding position")?;
                    }
                    let held = match &mut robot {
                        None => slave.hold(),
                        Some(r) => {
                            let m = r.read(rec, last_seq)?;
                            let held = slave.hold_measured(m.theta);
                            r.command(held.theta_ref);
                            held
                        }
                    };
                    rec.sample(SlaveSample::Hold(held))?;
                    deadline = Some(Instant::now() + t_s);
                }
            }
            Err(Idle::Terminate) => break false,
        }
        if rec.counters_due() {
            let t = totals(&slave, &filter, &robot);
            if let Some(r) = &robot {
                tactile_node::held::log_second(
                    "robot",
                    &mut robot_seen,
                    &t.device,
                    r.robot.take_reject(),
                );
            }
            let now = (t.counters.torque_clamps, t.counters.ik_clamped);
            if now != clamps {
                tracing::info!(
                    "clamped: {} joint torques to the limit and {} IK targets to the workspace in the last second ({} and {} in all)",
                    now.0 - clamps.0,
                    now.1 - clamps.1,
                    now.0,
                    now.1
                );
                clamps = now;
            }
            rec.counters(t)?;
        }
    };
    let reason = if completed {
        "completed"
    } else {
        "interrupted"
    };
    rec.stop(totals(&slave, &filter, &robot), reason)?;
    Ok(completed)
}
