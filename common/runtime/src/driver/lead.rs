//! The leader's loop, the master's: wait for the device and for the peers (probes
//! until one comes back), then for each sample n at its instant (realtime: its tick,
//! slept to; lockstep: now; simulated: n t_s) send c(n) and wait for q(n) until the
//! next tick (lockstep: a timeout); an answer that has not come by then is a miss, and
//! a late one is still recorded. At the end: collect stragglers, send the end of the
//! run.

use super::link::{Arrival, Block, Idle, Link};
use super::waits::{Notes, Waited};
use super::{Counts, Failure, Io, Leader, Timing};
use std::time::{Duration, Instant};
use tactile_messages::clock::{now_ns, sleep_until_ns};
use tactile_messages::samples::{stage, Backward, Control, Forward, LATE_WINDOW};
use tactile_peripheral::{DeviceCounters, LiveSink};
use tactile_records::{Events, Recorder};

/// Samples waiting for their answer: the last [`LATE_WINDOW`] sent, each answered or
/// not. Bounded, so a run of any length keeps the same memory.
#[derive(Debug)]
pub struct Window {
    answered: Vec<bool>,
    sent: u64,
}

impl Default for Window {
    fn default() -> Self {
        Window {
            answered: vec![true; LATE_WINDOW as usize],
            sent: 0,
        }
    }
}

impl Window {
    fn slot(n: u64) -> usize {
        (n % LATE_WINDOW) as usize
    }

    /// Sample n went out.
    pub fn send(&mut self, n: u64) {
        self.answered[Self::slot(n)] = false;
        self.sent = n + 1;
    }

    /// Marks `n` answered; false if it was never sent, already answered, or too old.
    pub fn answer(&mut self, n: u64) -> bool {
        let fresh = n < self.sent && n + LATE_WINDOW >= self.sent && !self.answered[Self::slot(n)];
        if fresh {
            self.answered[Self::slot(n)] = true;
        }
        fresh
    }

    /// Samples of the window still without an answer.
    pub fn unanswered(&self) -> u64 {
        let from = self.sent.saturating_sub(LATE_WINDOW);
        (from..self.sent)
            .filter(|&n| !self.answered[Self::slot(n)])
            .count() as u64
    }
}

/// What the leader needs besides its handler and ends.
#[derive(Debug, Clone, Copy)]
pub struct LeadOptions {
    /// The run token every sample carries.
    pub run: u64,
    /// Samples to send.
    pub samples: u64,
    /// How long to wait for the device and for the peers to answer at start-up.
    pub startup_timeout: Duration,
    /// Lockstep: how long to wait for an answer before counting it missing.
    pub answer_timeout: Duration,
    /// How the loop keeps time.
    pub timing: Timing,
}

/// The leader's loop and what it keeps between samples.
pub struct Lead<H: Leader> {
    handler: H,
    link: Link,
    rec: Recorder<H::Sample, H::Totals>,
    opts: LeadOptions,
    live: Option<Box<dyn LiveSink<tactile_ros::view::SampleView>>>,
    window: Window,
    counts: Counts,
    foreign: u64,
    started: Option<Instant>,
    device_seen: DeviceCounters,
    /// The sample in hand, c(n), kept from sample to sample.
    forward: Forward,
    /// Where each arrival is taken while an answer is awaited, kept from sample to
    /// sample (None before the first).
    slot: Option<Box<Arrival>>,
    /// The record of the answer in hand, kept from answer to answer.
    record: Option<H::Sample>,
    /// This run's own stop request, beside the process's (see [`Lead::halt_on`]).
    halt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Asked between samples whether to stop (see [`Lead::watch_with`]).
    watch: Option<Box<dyn FnMut() -> bool + Send>>,
}

impl<H: Leader> std::fmt::Debug for Lead<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lead")
            .field("sent", &self.window.sent)
            .finish_non_exhaustive()
    }
}

impl<H: Leader> Lead<H> {
    /// A leader with its ends, record (started) and live view.
    pub fn new(
        handler: H,
        link: Link,
        rec: Recorder<H::Sample, H::Totals>,
        opts: LeadOptions,
        live: Option<Box<dyn LiveSink<tactile_ros::view::SampleView>>>,
    ) -> Self {
        Lead {
            handler,
            link,
            rec,
            opts,
            live,
            window: Window::default(),
            counts: Counts::default(),
            foreign: 0,
            started: None,
            device_seen: DeviceCounters::default(),
            forward: Forward::default(),
            slot: None,
            record: None,
            halt: None,
            watch: None,
        }
    }

    /// True once this run's own stop request is set.
    fn halted(&self) -> bool {
        self.halt
            .as_ref()
            .is_some_and(|h| h.load(std::sync::atomic::Ordering::SeqCst))
    }

    /// Also stops after the sample in hand once `halt` is set: a stop request of this
    /// run alone (a Python callable in its loop that failed), where the process's
    /// (a signal) would stop every run and every report of the process.
    pub fn halt_on(mut self, halt: std::sync::Arc<std::sync::atomic::AtomicBool>) -> Self {
        self.halt = Some(halt);
        self
    }

    /// Also asks `watch` between samples, and stops after the sample in hand as a stop
    /// request does when it says true: for a caller that handles the signals itself
    /// and can look at them only from the loop's own thread (the Python package runs
    /// a run's loop on the caller's thread, and Python runs its signal handlers on
    /// the main thread alone).
    pub fn watch_with(mut self, watch: Box<dyn FnMut() -> bool + Send>) -> Self {
        self.watch = Some(watch);
        self
    }

    /// True if the caller's `watch` asks the run to stop.
    fn watched(&mut self) -> bool {
        self.watch.as_mut().is_some_and(|w| w())
    }

    /// Runs until every sample was sent (true) or a stop request (false); every way it
    /// ends is in the record, a failure as its `failed` event and stop reason.
    pub fn run(mut self, block: &mut dyn Block) -> Result<bool, Failure> {
        let ended = self.run_loop(block);
        let at = self.window.sent;
        let counts = self.counts();
        super::close(&mut self.rec, &mut self.handler, &counts, at, &ended)?;
        ended
    }

    fn run_loop(&mut self, block: &mut dyn Block) -> Result<bool, Failure> {
        self.rec.run(self.opts.run)?;
        if !self.wait_for_device()? || !self.find_peers(block)? {
            return Ok(false);
        }
        let t0 = now_ns() + 2_000_000;
        self.started = Some(Instant::now());
        let mut completed = true;
        for n in 0..self.opts.samples {
            if !self.sample(n, t0, block)? {
                completed = false;
                break;
            }
            self.counters_if_due()?;
        }
        // A halt asked for during the last sample: that sample was not the run's own
        // either, so the records must not say it completed.
        completed &= !self.halted();
        self.end(block, completed)?;
        Ok(completed)
    }

    /// The device's first good message, if the node drives one.
    fn wait_for_device(&mut self) -> Result<bool, Failure> {
        let Some(p) = self.handler.peripheral() else {
            return Ok(true);
        };
        let (kind, who) = (p.kind(), p.describe());
        let mut delivered = super::waits::Delivered::default();
        let limit = Some(self.opts.startup_timeout);
        let mut note = || {
            delivered.tick(p);
            Ok(())
        };
        match super::waits::until_doing(&who, limit, &|| p.heard(), &mut note)? {
            Waited::Ready => {
                self.rec.event(0, &format!("{kind} found: {who}"))?;
                Ok(true)
            }
            Waited::Stopped => Ok(false),
            Waited::TimedOut => {
                let c = p.counters();
                let hint = if c.messages == 0 {
                    delivered.nothing_came(p)
                } else {
                    delivered.why()
                };
                Err(Failure::NoAnswer(format!(
                    "no usable message from {who} within {:.1} s ({} received, {} rejected){hint}",
                    self.opts.startup_timeout.as_secs_f64(),
                    c.messages,
                    c.rejected
                )))
            }
        }
    }

    /// Probes until one comes back through the emulator and the slave (false: a stop
    /// request came first), then lets the echoes still in flight pass.
    fn find_peers(&mut self, block: &mut dyn Block) -> Result<bool, Failure> {
        let limit = self.opts.startup_timeout;
        let mut notes = Notes::new("the emulator and slave", Some(limit));
        let mut k = 0u64;
        let mut robot_wait = false;
        loop {
            if notes.timed_out() {
                return Err(Failure::NoAnswer(if robot_wait {
                    format!(
                        "the emulator and slave answer, but the slave still waits for its robot after {:.1} s: see the slave's log for the robot's topic and what it received",
                        limit.as_secs_f64()
                    )
                } else {
                    format!(
                        "no answer from the emulator and slave within {:.1} s: are both running with the same prefix and link?",
                        limit.as_secs_f64()
                    )
                }));
            }
            let p = Forward::control(Control::Probe, self.opts.run, k);
            self.link.send_forward(&p, true)?;
            k += 1;
            let deadline = Instant::now() + Duration::from_millis(20);
            loop {
                match self.link.wait(deadline, block)? {
                    Ok(super::Arrival::Backward(b))
                        if b.control_kind() == Some(Control::Waiting) && b.run == self.opts.run =>
                    {
                        if !robot_wait {
                            robot_wait = true;
                            tracing::info!(
                                "the emulator and slave answer; the slave waits for its robot"
                            );
                            self.rec
                                .event(0, "peers answer: the slave waits for its robot")?;
                        }
                    }
                    Ok(super::Arrival::Backward(b))
                        if b.control_kind() == Some(Control::Probe) && b.run == self.opts.run =>
                    {
                        self.rec
                            .event(0, "peers found: the emulator and slave answer")?;
                        let drain = Instant::now() + Duration::from_millis(5);
                        while self.link.wait(drain, block)?.is_ok() {}
                        return Ok(true);
                    }
                    Ok(_) => {}
                    Err(Idle::Stop) => return Ok(false),
                    Err(Idle::Timeout) => break,
                }
            }
            notes.tick();
        }
    }

    /// Sample `n`'s instant and the deadline of its answer: realtime sleeps to its
    /// tick (the origin is the tick, not the moment the master woke: a late wake-up is
    /// overhead the loop adds and must show in the round trip). Simulated, there is
    /// no deadline: the in-process runner ends the wait once nothing more can come.
    fn instant(&self, n: u64, t0: u64) -> (u64, Option<Instant>) {
        match self.opts.timing {
            Timing::Realtime {
                t_s_ns,
                wake_early_ns,
            } => {
                let tick = t0 + n * t_s_ns;
                // Timer wake-ups here are late by ~100 us (timer slack plus the VM's
                // wake cost): sleep until shortly before the tick and spin the rest;
                // the other two processes are idle then, so the spin steals nothing.
                sleep_until_ns(tick.saturating_sub(wake_early_ns));
                while now_ns() < tick {
                    std::thread::yield_now();
                }
                (tick, Some(instant_at(t0 + (n + 1) * t_s_ns)))
            }
            Timing::Lockstep => (now_ns(), Some(Instant::now() + self.opts.answer_timeout)),
            Timing::Simulated { t_s_ns } => (n * t_s_ns, None),
        }
    }

    /// Sends sample n and waits for its answer until its deadline; false if a stop
    /// request came.
    fn sample(&mut self, n: u64, t0: u64, block: &mut dyn Block) -> Result<bool, Failure> {
        if self.halted() || self.watched() || crate::signals::stop_requested() {
            return Ok(false);
        }
        let (origin, deadline) = self.instant(n, t0);
        let timing = self.opts.timing;
        let link = &self.link;
        let dead = || link.dead_peers();
        let mut io = Io::new(&mut self.rec, origin, &timing, &dead);
        let c = &mut self.forward;
        self.handler.tick(n, origin, &mut io, c)?;
        // The envelope is the driver's: the handler wrote the payload.
        (c.seq, c.run) = (n, self.opts.run);
        c.stamps = [0; stage::COUNT];
        c.stamps[stage::MASTER_TICK] = origin;
        c.stamps[stage::MASTER_SEND] = timing.stamp();
        self.link.send_forward(c, false)?;
        self.window.send(n);
        let sent = self.handler.sent(c);
        self.rec.sample(&sent)?;
        let mut slot = self
            .slot
            .take()
            .unwrap_or_else(|| Box::new(Arrival::Backward(Backward::default())));
        let went_on = self.await_answer(&mut slot, n, origin, deadline, block);
        self.slot = Some(slot);
        if !went_on? {
            return Ok(false);
        }
        self.handler.after(n);
        if let Some(l) = &mut self.live {
            if l.due(n) {
                if let Some(state) = self.handler.live() {
                    l.offer(state);
                }
            }
        }
        Ok(true)
    }

    /// Waits until sample n is answered, missed (dropped on the way, or no answer by
    /// `deadline`) or a stop request comes (false), taking each arrival into `slot`.
    fn await_answer(
        &mut self,
        slot: &mut Arrival,
        n: u64,
        origin: u64,
        deadline: Option<Instant>,
        block: &mut dyn Block,
    ) -> Result<bool, Failure> {
        loop {
            match self.link.wait_into(deadline, block, slot)? {
                Ok(()) => {
                    let Arrival::Backward(q) = slot else {
                        continue;
                    };
                    if q.control_kind() == Some(Control::Dropped) {
                        // The emulator dropped sample n: no answer comes.
                        if q.run == self.opts.run && q.seq == n {
                            self.miss(n, origin)?;
                            return Ok(true);
                        }
                        continue;
                    }
                    if self.absorb(q, n, origin)? == Some(n) {
                        return Ok(true);
                    }
                }
                Err(Idle::Timeout) => {
                    self.miss(n, origin)?;
                    return Ok(true);
                }
                Err(Idle::Stop) => return Ok(false),
            }
        }
    }

    /// Stamps q's arrival and hands it to the handler if it answers a sample awaiting
    /// it. Returns the sample it answers, or None for one that answers nothing (a
    /// probe, another run, a duplicate, a number never sent or too old).
    fn absorb(
        &mut self,
        q: &mut Backward,
        current: u64,
        origin: u64,
    ) -> Result<Option<u64>, Failure> {
        q.stamps[stage::MASTER_RECV] = self.opts.timing.stamp();
        if q.control_kind().is_some() {
            return Ok(None);
        }
        if q.run != self.opts.run {
            self.foreign += 1;
            return Ok(None);
        }
        if !self.window.answer(q.seq) {
            self.counts.unexpected += 1;
            return Ok(None);
        }
        let late = q.seq != current;
        self.counts.late += u64::from(late);
        let timing = self.opts.timing;
        let link = &self.link;
        let dead = || link.dead_peers();
        let mut io = Io::new(&mut self.rec, origin, &timing, &dead);
        let record = &mut self.record;
        *record = None;
        self.handler.answer(q, late, &mut io, record)?;
        if let Some(a) = record {
            self.rec.sample(a)?;
        }
        Ok(Some(q.seq))
    }

    /// Sample n had no answer by its deadline.
    fn miss(&mut self, n: u64, origin: u64) -> Result<(), Failure> {
        if matches!(self.opts.timing, Timing::Realtime { .. }) {
            self.counts.deadline_misses += 1;
        }
        let timing = self.opts.timing;
        let link = &self.link;
        let dead = || link.dead_peers();
        let mut io = Io::new(&mut self.rec, origin, &timing, &dead);
        let m = self.handler.miss(n, &mut io)?;
        self.rec.sample(&m)?;
        Ok(())
    }

    /// Collects stragglers, tells the others to stop, says how it ended.
    fn end(&mut self, block: &mut dyn Block, completed: bool) -> Result<(), Failure> {
        let last = self.window.sent;
        let grace = Instant::now() + Duration::from_millis(50);
        while let Ok(Arrival::Backward(mut q)) = self.link.wait(grace, block)? {
            self.absorb(&mut q, last, 0)?;
        }
        let end = Forward::control(Control::End, self.opts.run, 0);
        self.link.send_forward(&end, true)?;
        let reason = if completed {
            "completed"
        } else {
            "interrupted"
        };
        let unanswered = self.window.unanswered();
        self.rec.event(
            last,
            &format!("{reason}: {last} samples sent, {unanswered} of the last {LATE_WINDOW} without an answer"),
        )?;
        Ok(())
    }

    fn counts(&self) -> Counts {
        let mut c = self.counts;
        c.ports = self.link.stats();
        c.ports.backward_in.foreign += self.foreign;
        c.elapsed_ns = self.started.map_or(0, |s| s.elapsed().as_nanos() as u64);
        c
    }

    fn counters_if_due(&mut self) -> Result<(), Failure> {
        if !self.rec.counters_due() {
            return Ok(());
        }
        let counts = self.counts();
        super::each_second(
            &mut self.rec,
            &mut self.handler,
            &counts,
            &mut self.device_seen,
        )
    }
}

/// The `Instant` of a CLOCK_MONOTONIC time (both are monotonic clocks).
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
