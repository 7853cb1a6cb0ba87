//! The loop's driver: one for every node, as dora's and copper's runtimes own their
//! nodes' loops. It owns the protocol every node speaks (the run filter, start-up
//! probes and the end-of-run sample, passed on or echoed), pacing, the stamps of each
//! stage, the counters and their once-a-second record, stop requests, every wait
//! (peers, devices, robots: interruptible, with a deadline, saying what it waits for),
//! the record's lifecycle with its failure event, and the live view. A node is a
//! [`Handler`]: what to do with a sample, on an idle tick, and its totals.
//!
//! The master leads ([`lead`]): it makes sample n at each tick and waits for its
//! answer. The emulator and the slave follow ([`follow`]): they take what comes and
//! pass it on. In one process the same handlers run over in-memory streams
//! ([`in_process`]), stepped in turn while the master waits, so "in-process" and
//! "processes" differ only in the link.

pub mod follow;
pub mod in_process;
pub mod lead;
pub mod link;
pub mod waits;

pub use link::{Arrival, Block, Idle, Link, OnTransports};

use std::time::Duration;
use tactile_messages::clock::now_ns;
use tactile_messages::samples::{Backward, Forward};
use tactile_peripheral::Peripheral;
use tactile_records::{Events, Recorder, WriteError};
use tactile_transport::{LinkError, PortStats};

/// Why a loop could not go on.
#[derive(Debug, thiserror::Error)]
pub enum Failure {
    /// A link failed.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// The record could not be written.
    #[error(transparent)]
    Record(#[from] WriteError),
    /// A peer or a device did not answer in time.
    #[error("{0}")]
    NoAnswer(String),
    /// The node's own logic could not start or go on (its scenario, its inputs).
    #[error("{0}")]
    Node(String),
}

/// How the loop keeps time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Timing {
    /// Sample n is due at t0 + n t_s; each node sleeps until `wake_early_ns` before
    /// a sample is due, then polls.
    Realtime {
        /// The sampling period, ns.
        t_s_ns: u64,
        /// The wake-up margin, ns.
        wake_early_ns: u64,
    },
    /// Each sample goes as soon as the last one is answered.
    Lockstep,
    /// One process, no clock: sample n's instant is n t_s (the origin of c(n) and
    /// the done time of its answer, so a round trip is exactly the delay injected);
    /// the stages in between are not timed (zero).
    Simulated {
        /// The sampling period, ns.
        t_s_ns: u64,
    },
}

impl Timing {
    /// The timing a scenario asks for in a node program.
    pub fn of(scenario: &tactile_scenario::Scenario, wake_early: Duration) -> Timing {
        match scenario.mode {
            tactile_scenario::Mode::Realtime => Timing::Realtime {
                t_s_ns: scenario.t_s_ns(),
                wake_early_ns: wake_early.as_nanos() as u64,
            },
            tactile_scenario::Mode::Lockstep => Timing::Lockstep,
        }
    }

    /// A stage's stamp now (zero when simulated: stages are not timed).
    pub fn stamp(&self) -> u64 {
        match self {
            Timing::Simulated { .. } => 0,
            _ => now_ns(),
        }
    }
}

/// What a handler may do besides computing: say what happened (the record and the
/// log), read the loop's clock, ask which peers died.
pub struct Io<'a> {
    events: &'a mut dyn Events,
    now: u64,
    simulated: bool,
    dead: &'a dyn Fn() -> Vec<String>,
}

impl std::fmt::Debug for Io<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Io")
            .field("now", &self.now)
            .finish_non_exhaustive()
    }
}

impl<'a> Io<'a> {
    /// What a handler may do at a sample whose instant is `now` (used when simulated).
    pub fn new(
        events: &'a mut dyn Events,
        now: u64,
        timing: &Timing,
        dead: &'a dyn Fn() -> Vec<String>,
    ) -> Io<'a> {
        Io {
            events,
            now,
            simulated: matches!(timing, Timing::Simulated { .. }),
            dead,
        }
    }

    /// Records (and logs) that `what` happened at sample `n`.
    pub fn event(&mut self, n: u64, what: &str) -> Result<(), Failure> {
        Ok(self.events.event(n, what)?)
    }

    /// Now on the loop's clock, ns: CLOCK_MONOTONIC, or when simulated the instant of
    /// the sample in hand.
    pub fn now(&self) -> u64 {
        if self.simulated {
            self.now
        } else {
            now_ns()
        }
    }

    /// The peers known to have died (only iceoryx2 can tell).
    pub fn dead_peers(&self) -> Vec<String> {
        (self.dead)()
    }
}

/// What the driver counted for a node, for its totals.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// What the node's ends counted; samples of another run are in the `foreign` of
    /// the stream the node takes first (forward at a follower, backward at the master).
    pub ports: PortStats,
    /// Answers not back by the next tick (realtime master).
    pub deadline_misses: u64,
    /// Answers that came after their deadline.
    pub late: u64,
    /// Backward samples that answered nothing (a duplicate, a number never sent, or
    /// older than the late window).
    pub unexpected: u64,
    /// From the first tick to now, ns (the master).
    pub elapsed_ns: u64,
}

/// Ends a record however its loop ended (`ended`, after sample `at`): a failure is
/// its event and its stop reason, after the final counters.
pub(crate) fn close<H: Handler>(
    rec: &mut Recorder<H::Sample, H::Totals>,
    handler: &mut H,
    counts: &Counts,
    at: u64,
    ended: &Result<bool, Failure>,
) -> Result<(), Failure> {
    let reason = match ended {
        Ok(true) => "completed".to_string(),
        Ok(false) => "interrupted".to_string(),
        Err(e) => format!("failed: {e}"),
    };
    if ended.is_err() {
        let _ = rec.event(at, &reason);
    }
    // The device or robot left safe before anything else, however the loop ended.
    if let Some(what) = handler.release() {
        let _ = rec.event(at, &what);
    }
    rec.stop(handler.totals(counts), crate::sys::max_rss_kb(), &reason)?;
    Ok(())
}

/// Once a second (when the record says they are due, [`Recorder::counters_due`]): the
/// counters into the record, the handler's and the device's lines about the last
/// second into the log. The caller asks whether they are due before it gathers
/// `counts` (a copy of every port's counters and a clock read, a waste every sample).
pub(crate) fn each_second<H: Handler>(
    rec: &mut Recorder<H::Sample, H::Totals>,
    handler: &mut H,
    counts: &Counts,
    device_seen: &mut tactile_peripheral::DeviceCounters,
) -> Result<(), Failure> {
    let totals = handler.totals(counts);
    handler.log_second(&totals);
    if let Some(p) = handler.peripheral() {
        tactile_peripheral::log_second(p.kind(), device_seen, &p.counters(), p.take_reject());
    }
    rec.counters(totals, crate::sys::max_rss_kb())?;
    Ok(())
}

/// Two counters since the last call, if either changed: `(in the last second, in
/// all)`, for a handler's once-a-second log line.
pub fn changed(seen: &mut (u64, u64), now: (u64, u64)) -> Option<((u64, u64), (u64, u64))> {
    if now == *seen {
        return None;
    }
    let last = (now.0 - seen.0, now.1 - seen.1);
    *seen = now;
    Some((last, now))
}

/// What a node keeps for itself: its record of a sample, its totals, its device, the
/// state the live view shows.
pub trait Handler {
    /// The node's record of one sample.
    type Sample: serde::Serialize;
    /// The node's counters.
    type Totals: serde::Serialize + Default;

    /// The node's counters, with what the driver counted.
    fn totals(&self, counts: &Counts) -> Self::Totals;
    /// Once a second, with the totals just recorded: the node's lines about the last
    /// second (clamps and the like), at most one each.
    fn log_second(&mut self, _totals: &Self::Totals) {}
    /// The device or robot the node drives, if any: the driver waits for it, logs and
    /// counts it.
    fn peripheral(&self) -> Option<&dyn Peripheral> {
        None
    }
    /// The live view's state after the sample just handled.
    fn live(&self) -> Option<tactile_ros::view::SampleView> {
        None
    }
    /// At the end, however the loop ended: leaves the device rendering nothing and
    /// the robot holding; what was done, for the record.
    fn release(&mut self) -> Option<String> {
        None
    }
}

/// What a follower's handler made of a sample: what goes on each way, and its record.
/// The handler fills one its loop keeps (a reply is most of a kilobyte, and returning
/// it by value copied it through each `Result` on the way out).
#[derive(Debug)]
pub struct Reply<S> {
    /// Passed on forward (v(n) at the emulator).
    pub forward: Option<Forward>,
    /// Sent back (h(n) at the slave, q(n) at the emulator).
    pub backward: Option<Backward>,
    /// The node's record of it.
    pub record: Option<S>,
}

impl<S> Default for Reply<S> {
    fn default() -> Self {
        Reply {
            forward: None,
            backward: None,
            record: None,
        }
    }
}

/// A node that takes what comes and passes it on: the emulator, the slave.
pub trait Follower: Handler {
    /// A forward sample (c(n), v(n)), stamped at its arrival: what it makes of it
    /// into `out`, which comes empty. An answer in `out.backward` is the payload: the
    /// driver gives it the number, run and stamps of `s`.
    fn forward(
        &mut self,
        s: &Forward,
        out: &mut Reply<Self::Sample>,
        io: &mut Io,
    ) -> Result<(), Failure>;
    /// A backward sample (h(n) at the emulator), stamped at its arrival: what it
    /// makes of it into `out`, which comes empty.
    fn backward(
        &mut self,
        s: &Backward,
        out: &mut Reply<Self::Sample>,
        io: &mut Io,
    ) -> Result<(), Failure>;
    /// After the reply went out: what the node does outside the loop (the robot's
    /// command).
    fn after(&mut self, _io: &mut Io) {}
    /// How long without input before [`Follower::idle`] is called, and how often then
    /// until input returns (None: never).
    fn idle_timing(&self) -> Option<(Duration, Duration)> {
        None
    }
    /// No input for the idle timeout: the node's record of the idle tick (the slave
    /// holds its position).
    fn idle(&mut self, _last: u64, _io: &mut Io) -> Result<Option<Self::Sample>, Failure> {
        Ok(None)
    }
}

/// The node that makes the samples and waits for their answers: the master.
pub trait Leader: Handler {
    /// Sample n, at its instant `origin_ns`: c(n)'s payload, into `c`, which holds the
    /// sample before it and must be written whole (its loop keeps it: a sample is
    /// hundreds of bytes, copied through each `Result` when returned); the driver then
    /// writes the envelope (number n, run, stamps from `origin_ns`).
    fn tick(&mut self, n: u64, origin_ns: u64, io: &mut Io, c: &mut Forward)
        -> Result<(), Failure>;
    /// c(n) as it went out (stamped): the record of it.
    fn sent(&mut self, c: &Forward) -> Self::Sample;
    /// q(n) back for a sample awaiting it (`late`: after its deadline), stamped at
    /// its arrival: the record of it into `record`, which comes empty (its loop keeps
    /// it: a master's answer is 336 bytes, copied through each `Result` when returned);
    /// left empty, nothing is recorded.
    fn answer(
        &mut self,
        q: &Backward,
        late: bool,
        io: &mut Io,
        record: &mut Option<Self::Sample>,
    ) -> Result<(), Failure>;
    /// Sample n had no answer by its deadline: the record of it.
    fn miss(&mut self, n: u64, io: &mut Io) -> Result<Self::Sample, Failure>;
    /// After sample n: what the node does outside the loop (the device's force).
    fn after(&mut self, _n: u64) {}
}
