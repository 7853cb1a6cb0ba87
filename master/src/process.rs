//! The master process's edge: paces the loop, moves samples over its link, stamps
//! times, and writes its record as it goes (what it sent, what came back, what it
//! commanded). All signal computation is in [`Master`]; memory is bounded: only the
//! last [`LATE_WINDOW`] samples are remembered, to match late answers.
//!
//! Realtime: sample n starts at t0 + n t_s (absolute sleep, so no drift), c(n) goes
//! out, and the master waits for q(n) until the next tick; a q(n) that has not come by
//! then is a deadline miss (if it comes later its round trip is still recorded).
//! Lockstep: c(n + 1) goes out as soon as q(n) is back.

use crate::hmd::Master;
use crate::live::MasterLive;
use crate::operator::{OperatorError, OperatorSource};
use crate::record::{MasterSample, MasterTotals, Sent};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use tactile_messages::clock::{now_ns, sleep_until_ns};
use tactile_messages::samples::{stage, Backward, Forward, FLAG_END, FLAG_PROBE, LATE_WINDOW};
use tactile_node::args::NodeError;
use tactile_node::device::{HapticDevice, LiveSink};
use tactile_node::held::{wait_heard, Held, Waited};
use tactile_node::link::MasterLink;
use tactile_node::link::{Idle, LinkError};
use tactile_node::recorder::Recorder;
use tactile_scenario::{Mode, Scenario, ScenarioError};
use thiserror::Error;

/// What the master process needs to run.
#[derive(Debug, Clone)]
pub struct MasterOptions {
    /// The scenario.
    pub scenario: Scenario,
    /// Folder the scenario's relative paths are resolved against.
    pub base_dir: PathBuf,
    /// How long to wait for the other two processes to answer at start-up.
    pub startup_timeout: Duration,
    /// In lockstep, how long to wait for an answer before counting it missing.
    pub answer_timeout: Duration,
    /// Realtime: wake this long before each tick and spin to it, ns.
    pub wake_early_ns: u64,
    /// The run token this master puts on every sample.
    pub run: u64,
}

/// What went wrong in the master process.
#[derive(Debug, Error)]
pub enum MasterError {
    /// The scenario is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The trajectory file is unusable.
    #[error(transparent)]
    Operator(#[from] OperatorError),
    /// The link failed.
    #[error(transparent)]
    Ipc(#[from] LinkError),
    /// The other processes did not answer.
    #[error("{0}")]
    NoAnswer(String),
    /// The record could not be written.
    #[error("{0}")]
    Record(String),
}

impl From<NodeError> for MasterError {
    fn from(e: NodeError) -> Self {
        MasterError::Record(e.to_string())
    }
}

/// What the master loop touches besides its link: a real device in place of the
/// simulated hand and device, and the live view. Neither by default.
#[derive(Default)]
pub struct Outside<'a> {
    /// The master device through its ROS 2 driver.
    pub device: Option<&'a mut dyn HapticDevice>,
    /// Where each k-th sample's state goes for the live view.
    pub live: Option<&'a mut dyn LiveSink<MasterLive>>,
}

impl std::fmt::Debug for Outside<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Outside")
            .field("device", &self.device.as_ref().map(|d| d.describe()))
            .field("live", &self.live.is_some())
            .finish()
    }
}

/// The master's recorder.
pub type MasterRecorder = Recorder<MasterSample, MasterTotals>;

/// Samples waiting for their answer: the last [`LATE_WINDOW`] sent, each answered or
/// not. Bounded, so a run of any length keeps the same memory.
#[derive(Debug)]
struct Window {
    answered: Vec<bool>,
    sent: u64,
}

impl Window {
    fn new() -> Self {
        Window {
            answered: vec![true; LATE_WINDOW as usize],
            sent: 0,
        }
    }

    fn slot(n: u64) -> usize {
        (n % LATE_WINDOW) as usize
    }

    fn send(&mut self, n: u64) {
        self.answered[Self::slot(n)] = false;
        self.sent = n + 1;
    }

    /// Marks `n` answered; false if it was never sent, already answered, or too old.
    fn answer(&mut self, n: u64) -> bool {
        let fresh = n < self.sent && n + LATE_WINDOW >= self.sent && !self.answered[Self::slot(n)];
        if fresh {
            self.answered[Self::slot(n)] = true;
        }
        fresh
    }

    fn unanswered(&self) -> u64 {
        let from = self.sent.saturating_sub(LATE_WINDOW);
        (from..self.sent)
            .filter(|&n| !self.answered[Self::slot(n)])
            .count() as u64
    }
}

/// How the master loop ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ending {
    /// Every sample was sent.
    Completed,
    /// SIGINT or SIGTERM stopped it.
    Interrupted,
}

fn probe<L: MasterLink + ?Sized>(
    link: &L,
    run: u64,
    timeout: Duration,
) -> Result<bool, MasterError> {
    let start = Instant::now();
    let mut k = 0u64;
    let mut next_note = Duration::from_secs(5);
    while start.elapsed() < timeout {
        let mut p = Forward {
            seq: k,
            run,
            ..Forward::default()
        };
        p.signal.flags = FLAG_PROBE;
        link.send_control(p)?;
        k += 1;
        let deadline = Instant::now() + Duration::from_millis(20);
        loop {
            match link.recv(deadline)? {
                Ok(b) if b.signal.flags & FLAG_PROBE != 0 && b.run == run => return Ok(true),
                Ok(_) => {}
                Err(Idle::Terminate) => return Ok(false),
                Err(Idle::Timeout) => break,
            }
        }
        if start.elapsed() > next_note {
            tracing::info!(
                "still waiting for the emulator and slave ({:.0} s of {:.0} s)",
                start.elapsed().as_secs_f64(),
                timeout.as_secs_f64()
            );
            next_note += Duration::from_secs(5);
        }
    }
    Err(MasterError::NoAnswer(format!(
        "no answer from the emulator and slave within {:.1} s: are both running with the same prefix and link?",
        timeout.as_secs_f64()
    )))
}

/// The master loop and what it keeps between samples.
struct Loop<'a, L: MasterLink + ?Sized> {
    master: Master,
    link: &'a L,
    rec: &'a mut MasterRecorder,
    totals: MasterTotals,
    window: Window,
    run: u64,
    peer_timeout: u64,
    t0: u64,
    outside: Outside<'a>,
    /// The real device's angles as the loop holds them.
    device: Held,
    last_answer: Option<crate::record::Answer>,
}

impl<L: MasterLink + ?Sized> Loop<'_, L> {
    fn totals(&self) -> MasterTotals {
        let mut t = self.totals;
        t.counters = self.master.counters();
        (t.c_out, t.q_in) = self.link.stats();
        t.q_in.foreign += self.totals.q_in.foreign;
        t.elapsed_ns = now_ns().saturating_sub(self.t0);
        if let Some(d) = &self.outside.device {
            t.device = d.counters();
        }
        t
    }

    /// b(n): the simulated hand and device, or the real device's newest angles (held
    /// while stale or lost; lost renders zero force).
    fn forward(&mut self, n: u64, origin: u64) -> Result<(Forward, Sent), MasterError> {
        let Some(d) = self.outside.device.as_deref_mut() else {
            return Ok(self.master.forward(n, origin));
        };
        let who = d.describe();
        let seen = self
            .device
            .take(d.read(now_ns()), ("device", &who), "rendering zero force");
        if let Some(what) = seen {
            self.rec.event(n, what)?;
        }
        Ok(self.master.forward_measured(n, origin, self.device.theta))
    }

    /// After sample n: the force to the real device (zero while it is lost), and the
    /// live view.
    fn after(&mut self, sent: Sent) {
        let felt = if self.device.lost {
            [0.0; 3]
        } else {
            self.master.felt()
        };
        if let Some(d) = self.outside.device.as_deref_mut() {
            d.render(felt, now_ns());
        }
        if let Some(live) = self.outside.live.as_deref_mut() {
            if live.due(sent.n) {
                let answer = self.last_answer.filter(|a| a.n == sent.n);
                live.offer(MasterLive {
                    sent,
                    answer,
                    tau: self.master.tau(),
                    felt,
                });
            }
        }
    }

    /// Stamps q's arrival, applies KFF-HMD and records the answer. Returns the sample
    /// it answers, or None for one that answers nothing (a probe, another run, a
    /// duplicate, a number never sent or too old).
    fn absorb(&mut self, mut q: Backward, current: u64) -> Result<Option<u64>, MasterError> {
        q.stamps[stage::MASTER_RECV] = now_ns();
        if q.signal.flags & FLAG_PROBE != 0 {
            return Ok(None);
        }
        if q.run != self.run {
            self.totals.q_in.foreign += 1;
            return Ok(None);
        }
        if !self.window.answer(q.seq) {
            self.totals.unexpected += 1;
            return Ok(None);
        }
        if self.master.peer_lost() {
            self.rec.event(current, "loop resumed: answers are back")?;
        }
        let mut a = self.master.backward(&q);
        a.stamps[stage::MASTER_DONE] = now_ns();
        self.master.account(&mut a);
        a.late = q.seq != current;
        if a.late {
            self.totals.late += 1;
        }
        self.rec.sample(MasterSample::Answer(a))?;
        self.last_answer = Some(a);
        Ok(Some(q.seq))
    }

    /// Sample n had no answer by its deadline: hold or zero the torque, and say so
    /// when the loop breaks.
    fn miss(&mut self, n: u64, realtime: bool) -> Result<(), MasterError> {
        let was_lost = self.master.peer_lost();
        let m = self.master.missing(n);
        self.rec.sample(MasterSample::Miss(m))?;
        if realtime {
            self.totals.deadline_misses += 1;
        }
        if self.master.peer_lost() && !was_lost {
            let dead = self.link.dead_peers();
            let what = if dead.is_empty() {
                format!(
                    "loop broken: no answer for {} samples; zero torque",
                    self.peer_timeout
                )
            } else {
                format!(
                    "loop broken: no answer for {} samples, dead: {}; zero torque",
                    self.peer_timeout,
                    dead.join(", ")
                )
            };
            tracing::warn!("{what}");
            self.rec.event(n, what)?;
        }
        Ok(())
    }

    /// Sends sample n and waits for its answer until `deadline`; false if a stop
    /// request came.
    fn sample(
        &mut self,
        n: u64,
        origin: u64,
        deadline: Instant,
        realtime: bool,
    ) -> Result<bool, MasterError> {
        let (mut c, mut sent) = self.forward(n, origin)?;
        c.run = self.run;
        c.stamps[stage::MASTER_SEND] = now_ns();
        sent.send_ns = c.stamps[stage::MASTER_SEND];
        self.link.send(c)?;
        self.window.send(n);
        self.rec.sample(MasterSample::Sent(sent))?;
        loop {
            match self.link.recv(deadline)? {
                Ok(q) => {
                    if self.absorb(q, n)? == Some(n) {
                        break;
                    }
                }
                Err(Idle::Timeout) => {
                    self.miss(n, realtime)?;
                    break;
                }
                Err(Idle::Terminate) => return Ok(false),
            }
        }
        self.after(sent);
        Ok(true)
    }
}

/// Runs the master loop over any link until the scenario's samples are sent (or a stop
/// request), writing its record as it goes.
pub fn run_with<'a, L: MasterLink + ?Sized>(
    opts: &MasterOptions,
    link: &'a L,
    rec: &'a mut MasterRecorder,
    outside: Outside<'a>,
) -> Result<Ending, MasterError> {
    let sc = &opts.scenario;
    let source = OperatorSource::load(&sc.operator, &opts.base_dir)?;
    let master = Master::new(sc, source)?;
    rec.run(opts.run)?;
    if let Some(d) = &outside.device {
        if !wait_for_device(&**d, opts.startup_timeout)? {
            rec.stop(MasterTotals::default(), "interrupted")?;
            return Ok(Ending::Interrupted);
        }
        rec.event(0, format!("device found: {}", d.describe()))?;
    }
    tracing::info!("waiting for the emulator and slave");
    if !probe(link, opts.run, opts.startup_timeout)? {
        rec.stop(MasterTotals::default(), "interrupted")?;
        return Ok(Ending::Interrupted);
    }
    rec.event(0, "peers found: the emulator and slave answer")?;
    // Drain probe echoes still in flight.
    let drain = Instant::now() + Duration::from_millis(5);
    while link.recv(drain)?.is_ok() {}

    let t_s = sc.t_s_ns();
    let realtime = sc.mode == Mode::Realtime;
    // First tick a little ahead so every process is settled.
    let t0 = now_ns() + 2_000_000;
    let mut lp = Loop {
        master,
        link,
        rec,
        totals: MasterTotals::default(),
        window: Window::new(),
        run: opts.run,
        peer_timeout: sc.faults.peer_timeout_samples,
        t0,
        outside,
        device: Held::default(),
        last_answer: None,
    };
    let mut ending = Ending::Completed;
    let mut clamps = (0, 0);
    let mut device_seen = tactile_node::device::DeviceCounters::default();
    for n in 0..sc.samples {
        // The sample's origin is its scheduled instant, not the moment the master woke:
        // a late wake-up is overhead the loop adds and must show in the round trip.
        let (origin, deadline) = if realtime {
            let tick = t0 + n * t_s;
            // Timer wake-ups here are late by ~100 us (timer slack plus the VM's wake
            // cost), so sleep until shortly before the tick and spin the rest; the
            // other two processes are idle at that moment, so the spin steals nothing.
            sleep_until_ns(tick.saturating_sub(opts.wake_early_ns));
            while now_ns() < tick {
                std::thread::yield_now();
            }
            (tick, instant_at(t0 + (n + 1) * t_s))
        } else {
            (now_ns(), Instant::now() + opts.answer_timeout)
        };
        if !lp.sample(n, origin, deadline, realtime)? {
            ending = Ending::Interrupted;
            break;
        }
        if lp.rec.counters_due() {
            let t = lp.totals();
            log_clamps(&mut clamps, &t.counters);
            if let Some(d) = &lp.outside.device {
                tactile_node::held::log_second(
                    "device",
                    &mut device_seen,
                    &t.device,
                    d.take_reject(),
                );
            }
            lp.rec.counters(t)?;
        }
    }
    // Collect stragglers, then tell the others to stop.
    let last = lp.window.sent;
    let grace = Instant::now() + Duration::from_millis(50);
    while let Ok(Ok(q)) = link.recv(grace) {
        lp.absorb(q, last)?;
    }
    let mut end = Forward {
        run: opts.run,
        ..Forward::default()
    };
    end.signal.flags = FLAG_END;
    link.send_control(end)?;
    let unanswered = lp.window.unanswered();
    let totals = lp.totals();
    let reason = match ending {
        Ending::Completed => "completed",
        Ending::Interrupted => "interrupted",
    };
    lp.rec.event(
        last,
        format!("{reason}: {last} samples sent, {unanswered} of the last {LATE_WINDOW} without an answer"),
    )?;
    lp.rec.stop(totals, reason)?;
    Ok(ending)
}

/// Waits until the device has sent a good message; false if a stop request came.
fn wait_for_device(d: &dyn HapticDevice, timeout: Duration) -> Result<bool, MasterError> {
    let waited = wait_heard(&|| d.heard(), &d.describe(), Some(timeout))
        .map_err(|e| MasterError::Record(e.to_string()))?;
    if waited == Waited::TimedOut {
        let (messages, rejected) = (d.counters().messages, d.counters().rejected);
        return Err(MasterError::NoAnswer(format!(
            "no usable message from {} within {:.1} s ({messages} received, {rejected} rejected): is its driver running, with the same ROS_DOMAIN_ID, reaching the same Zenoh router?",
            d.describe(),
            timeout.as_secs_f64()
        )));
    }
    Ok(waited == Waited::Heard)
}

/// Logs the force and torque clamps of the last second, if any (at most one line a
/// second, however often the device saturates).
fn log_clamps(seen: &mut (u64, u64), c: &crate::record::MasterCounters) {
    let now = (c.force_clamps, c.torque_clamps);
    if now != *seen {
        tracing::info!(
            "clamped to the device limits: {} force and {} torque components in the last second ({} and {} in all)",
            now.0 - seen.0,
            now.1 - seen.1,
            now.0,
            now.1
        );
        *seen = now;
    }
}

/// The `Instant` corresponding to a CLOCK_MONOTONIC time (both are monotonic clocks).
fn instant_at(t_ns: u64) -> Instant {
    let now_i = Instant::now();
    let now = now_ns();
    if t_ns >= now {
        now_i + Duration::from_nanos(t_ns - now)
    } else {
        now_i
            .checked_sub(Duration::from_nanos(now - t_ns))
            .unwrap_or(now_i)
    }
}
