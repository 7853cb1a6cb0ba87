//! The follower's loop, the emulator's and the slave's: take what comes (paced in
//! realtime: asleep until just before a sample is due, learned from the arrivals, but
//! never while an answer it passed on is still due back), keep only this run's
//! samples, pass probes and the end of the run on (or echo a probe back, at the end of
//! the chain), stamp each stage, hand data to the handler and send its reply on, and
//! call the handler's idle tick when input goes silent.

use super::link::{Arrival, Block, Idle, Link};
use super::{Counts, Failure, Follower, Io, Reply, Timing};
use crate::pace::Pacer;
use std::time::{Duration, Instant};
use tactile_messages::samples::{stage, Backward, Control, Forward};
use tactile_peripheral::{DeviceCounters, LiveSink};
use tactile_records::{Events, Recorder};

/// The run this node serves: learned from the master's first sample (probe or data);
/// samples of another run are dropped and counted.
#[derive(Debug, Default)]
pub struct RunFilter {
    run: u64,
    /// Samples of another run dropped.
    pub foreign: u64,
}

impl RunFilter {
    /// True if a sample of run `token` belongs to this run; the first token seen is
    /// adopted (and returned in `joined`).
    pub fn admit(&mut self, token: u64, joined: &mut Option<u64>) -> bool {
        if self.run == 0 && token != 0 {
            self.run = token;
            *joined = Some(token);
        }
        let ok = token == self.run && token != 0;
        if !ok {
            self.foreign += 1;
        }
        ok
    }
}

/// Where a follower sits in the chain, which says which stage each stamp is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    /// Between master and slave (the emulator): passes both ways on.
    Middle,
    /// At the end (the slave): answers each forward sample.
    End,
}

impl Place {
    /// Stages stamped when a forward sample arrives, its forward reply leaves, its
    /// backward reply leaves.
    fn forward_stages(self) -> (usize, usize, usize) {
        match self {
            Place::Middle => (
                stage::EMU_FWD_RECV,
                stage::EMU_FWD_SEND,
                stage::EMU_BWD_SEND,
            ),
            Place::End => (stage::SLAVE_RECV, stage::SLAVE_SEND, stage::SLAVE_SEND),
        }
    }
}

/// The pacer to sleep with before the next sample: none while an answer the node
/// passed on is still due back (it comes within microseconds).
fn pacing(pacer: &Option<Pacer>, awaiting: Option<u64>) -> Option<&Pacer> {
    pacer.as_ref().filter(|_| awaiting.is_none())
}

/// How a sample left the loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Go on.
    Continue,
    /// The master's end of the run came.
    End,
}

/// A follower's loop and what it keeps between samples.
pub struct Follow<H: Follower> {
    handler: H,
    link: Link,
    rec: Recorder<H::Sample, H::Totals>,
    timing: Timing,
    live: Option<Box<dyn LiveSink<tactile_ros::view::SampleView>>>,
    place: Place,
    filter: RunFilter,
    pacer: Option<Pacer>,
    /// The last forward sample passed on whose answer has not come back: after a stall
    /// several are in flight, and the node sleeps only once the last is answered.
    awaiting: Option<u64>,
    seen_first: bool,
    last_seq: u64,
    /// When the idle tick is due (None: no input yet, or no idle tick).
    idle_at: Option<Instant>,
    device_seen: DeviceCounters,
    /// Where [`Follow::step`] takes each sample and handles it, kept from step to step
    /// (None before the first step, while a step holds it, and after one failed).
    slot: Option<Box<Arrival>>,
    /// What the handler made of the sample in hand, emptied before each.
    reply: Reply<H::Sample>,
}

impl<H: Follower> std::fmt::Debug for Follow<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Follow")
            .field("place", &self.place)
            .field("last_seq", &self.last_seq)
            .finish_non_exhaustive()
    }
}

impl<H: Follower> Follow<H> {
    /// A follower with its ends, record (started), timing and live view.
    pub fn new(
        handler: H,
        link: Link,
        rec: Recorder<H::Sample, H::Totals>,
        timing: Timing,
        live: Option<Box<dyn LiveSink<tactile_ros::view::SampleView>>>,
    ) -> Self {
        let pacer = match timing {
            Timing::Realtime {
                t_s_ns,
                wake_early_ns,
            } => Some(Pacer::new(t_s_ns, wake_early_ns)),
            _ => None,
        };
        let place = if link.forwards() {
            Place::Middle
        } else {
            Place::End
        };
        Follow {
            handler,
            link,
            rec,
            timing,
            live,
            place,
            filter: RunFilter::default(),
            pacer,
            awaiting: None,
            seen_first: false,
            last_seq: 0,
            idle_at: None,
            device_seen: DeviceCounters::default(),
            slot: None,
            reply: Reply::default(),
        }
    }

    /// Runs until the master's end of the run (true) or a stop request (false): waits
    /// for the node's device first, if it has one. Every way it ends is in the record.
    pub fn run(mut self, block: &mut dyn Block) -> Result<bool, Failure> {
        let ended = self.run_loop(block);
        let counts = self.counts();
        super::close(
            &mut self.rec,
            &mut self.handler,
            &counts,
            self.last_seq,
            &ended,
        )?;
        ended
    }

    fn run_loop(&mut self, block: &mut dyn Block) -> Result<bool, Failure> {
        if !self.wait_for_device()? {
            return Ok(false);
        }
        tracing::info!("waiting for the master");
        loop {
            let until = self
                .idle_at
                .unwrap_or_else(|| Instant::now() + Duration::from_secs(3600));
            let paced = pacing(&self.pacer, self.awaiting);
            let (got, waiting) = self.link.recv_paced(paced, until, block)?;
            match got {
                Ok(mut a) => {
                    if self.handle(&mut a, waiting)? == Flow::End {
                        // The master's end came, but if this node was asked to stop
                        // too (SIGTERM to the whole run, its launcher gone), it was
                        // interrupted like the master: one ending for one cause.
                        return Ok(!crate::signals::stop_requested());
                    }
                }
                Err(Idle::Timeout) => self.idle()?,
                Err(Idle::Stop) => return Ok(false),
            }
            self.counters_if_due()?;
        }
    }

    /// Handles every sample already waiting, without waiting for more (the
    /// in-process runner's step): whether any came, and whether the run ended.
    pub fn step(&mut self) -> Result<(bool, Flow), Failure> {
        let mut slot = self
            .slot
            .take()
            .unwrap_or_else(|| Box::new(Arrival::Forward(Forward::default())));
        let mut any = false;
        let mut flow = Flow::Continue;
        while flow == Flow::Continue && self.link.poll_into(&mut slot)? {
            any = true;
            flow = self.handle(&mut slot, false)?;
        }
        self.slot = Some(slot);
        Ok((any, flow))
    }

    fn wait_for_device(&mut self) -> Result<bool, Failure> {
        let Some(p) = self.handler.peripheral() else {
            return Ok(true);
        };
        let (kind, who) = (p.kind(), p.describe());
        // Meanwhile the master's probes are answered "waiting", so it says what the
        // run waits for rather than blaming the prefix or the link.
        let (link, filter, place) = (&mut self.link, &mut self.filter, self.place);
        let mut joined = None;
        let mut delivered = super::waits::Delivered::default();
        let mut answer = || {
            delivered.tick(p);
            answer_waiting(link, filter, place, &mut joined)
        };
        let waited = super::waits::until_doing(&who, None, &|| p.heard(), &mut answer)?;
        if let Some(t) = joined {
            self.rec.run(t)?;
        }
        match waited {
            super::waits::Waited::Ready => {
                let what = format!("{kind} found: {who}");
                Events::event(&mut self.rec, 0, &what)?;
                Ok(true)
            }
            _ => Ok(false),
        }
    }

    /// One arrival: this run's or dropped, control or data. Stamped where it is: a
    /// sample is hundreds of bytes.
    fn handle(&mut self, a: &mut Arrival, waiting: bool) -> Result<Flow, Failure> {
        let (token, _) = a.run_and_seq();
        let mut joined = None;
        if !self.filter.admit(token, &mut joined) {
            return Ok(Flow::Continue);
        }
        if let Some(t) = joined {
            self.rec.run(t)?;
        }
        match a {
            Arrival::Forward(c) => match c.control_kind() {
                None | Some(Control::Dropped) => self.forward(c, waiting).map(|()| Flow::Continue),
                Some(_) => self.control(c),
            },
            Arrival::Backward(h) if h.control_kind().is_some_and(Control::is_probe) => {
                self.link.send_backward(h, true)?;
                Ok(Flow::Continue)
            }
            Arrival::Backward(h) => self.backward(h).map(|()| Flow::Continue),
        }
    }

    /// A probe or the end of the run: passed on forward, or at the end of the chain a
    /// probe echoed back.
    fn control(&mut self, c: &Forward) -> Result<Flow, Failure> {
        if self.place == Place::Middle {
            self.link.send_forward(c, true)?;
        } else if c.control_kind().is_some_and(Control::is_probe) {
            let echo = Backward::control(Control::Probe, c.run, c.seq);
            self.link.send_backward(&echo, true)?;
        }
        if c.control_kind() == Some(Control::End) {
            Events::event(&mut self.rec, self.last_seq, "end of run from the master")?;
            return Ok(Flow::End);
        }
        Ok(Flow::Continue)
    }

    /// A forward data sample: stamped, handed to the handler, its reply sent on,
    /// then recorded.
    fn forward(&mut self, c: &mut Forward, waiting: bool) -> Result<(), Failure> {
        if !self.seen_first {
            self.seen_first = true;
            Events::event(&mut self.rec, c.seq, "first sample from the master")?;
        }
        self.last_seq = c.seq;
        let (recv, fwd_send, bwd_send) = self.place.forward_stages();
        c.stamps[recv] = self.timing.stamp();
        if let Some(p) = &mut self.pacer {
            p.arrived(c.seq, c.stamps[recv], waiting);
        }
        let none = || Vec::new();
        let mut io = Io::new(
            &mut self.rec,
            c.stamps[stage::MASTER_TICK],
            &self.timing,
            &none,
        );
        let reply = &mut self.reply;
        *reply = Reply::default();
        self.handler.forward(c, reply, &mut io)?;
        let mut sent = false;
        if let Some(v) = &mut reply.forward {
            self.awaiting = Some(v.seq);
            v.stamps[fwd_send] = self.timing.stamp();
            sent |= self.link.send_forward(v, false)?;
        } else if self.place == Place::Middle {
            Self::dropped(&mut self.link, self.timing, c.seq, c.run)?;
        }
        if let Some(h) = &mut reply.backward {
            // The envelope is the driver's: an answer to c carries its number, run
            // and stamps so far; the handler wrote the payload.
            (h.seq, h.run, h.stamps) = (c.seq, c.run, c.stamps);
            h.stamps[bwd_send] = self.timing.stamp();
            sent |= self.link.send_backward(h, false)?;
        }
        // The next node usually shares this CPU, polling for what was just sent: let
        // it take it on now, and write the record after (measured at 1 kHz under
        // SCHED_FIFO: the slave's hop p50 from 10.3 us to 1.4 us, the emulator's from
        // 3.0 to 1.6 us).
        if sent && !matches!(self.timing, Timing::Simulated { .. }) {
            std::thread::yield_now();
        }
        let mut io = Io::new(
            &mut self.rec,
            c.stamps[stage::MASTER_TICK],
            &self.timing,
            &none,
        );
        self.handler.after(&mut io);
        self.finish(c.seq)?;
        // Lockstep has no clock: silence is slowness, not a lost master, and a held
        // step would change the signals with the machine's load. Simulated, the
        // in-process runner steps the node and never idles it (and a clock read a
        // sample is saved).
        self.idle_at = self
            .handler
            .idle_timing()
            .filter(|_| matches!(self.timing, Timing::Realtime { .. }))
            .map(|(after, _)| Instant::now() + after);
        Ok(())
    }

    /// Lockstep: tells the master that sample `seq` was dropped here, so it counts the
    /// miss at once (in realtime the tick's deadline does; in one process, the
    /// runner sees nothing more can come).
    fn dropped(link: &mut Link, timing: Timing, seq: u64, run: u64) -> Result<(), Failure> {
        if timing != Timing::Lockstep {
            return Ok(());
        }
        link.send_backward(&Backward::control(Control::Dropped, run, seq), true)?;
        Ok(())
    }

    /// A backward data sample (at the emulator): stamped, handed over, its reply sent
    /// back, recorded.
    fn backward(&mut self, h: &mut Backward) -> Result<(), Failure> {
        h.stamps[stage::EMU_BWD_RECV] = self.timing.stamp();
        if self.awaiting.is_some_and(|s| h.seq >= s) {
            self.awaiting = None;
        }
        let none = || Vec::new();
        let mut io = Io::new(&mut self.rec, 0, &self.timing, &none);
        let reply = &mut self.reply;
        *reply = Reply::default();
        self.handler.backward(h, reply, &mut io)?;
        if let Some(q) = &mut reply.backward {
            q.stamps[stage::EMU_BWD_SEND] = self.timing.stamp();
            self.link.send_backward(q, false)?;
        } else {
            Self::dropped(&mut self.link, self.timing, h.seq, h.run)?;
        }
        self.finish(h.seq)
    }

    /// The live view's state of sample `n`, and the record of the reply.
    fn finish(&mut self, n: u64) -> Result<(), Failure> {
        if let Some(l) = &mut self.live {
            if l.due(n) {
                if let Some(state) = self.handler.live() {
                    l.offer(state);
                }
            }
        }
        if let Some(r) = &self.reply.record {
            self.rec.sample(r)?;
        }
        Ok(())
    }

    /// No input by the idle tick's time: the handler's idle tick, then one a period.
    fn idle(&mut self) -> Result<(), Failure> {
        let (Some(_), Some((_, every))) = (self.idle_at, self.handler.idle_timing()) else {
            return Ok(());
        };
        let none = || Vec::new();
        let mut io = Io::new(&mut self.rec, 0, &self.timing, &none);
        if let Some(r) = self.handler.idle(self.last_seq, &mut io)? {
            self.rec.sample(&r)?;
        }
        self.idle_at = Some(Instant::now() + every);
        Ok(())
    }

    fn counts(&self) -> Counts {
        let mut ports = self.link.stats();
        ports.forward_in.foreign += self.filter.foreign;
        Counts {
            ports,
            ..Counts::default()
        }
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

    /// The handler, for the in-process runner's totals.
    pub fn handler(&self) -> &H {
        &self.handler
    }

    /// Ends the record as the master's loop ended (the in-process runner's end).
    pub fn close(mut self, ended: &Result<bool, Failure>) -> Result<(), Failure> {
        let counts = self.counts();
        super::close(
            &mut self.rec,
            &mut self.handler,
            &counts,
            self.last_seq,
            ended,
        )
    }
}

/// While the end of the chain waits for its robot: each probe of a run it may join
/// is echoed with [`Control::Waiting`]; anything else is left (no data comes before the
/// master has its answer).
fn answer_waiting(
    link: &mut Link,
    filter: &mut RunFilter,
    place: Place,
    joined: &mut Option<u64>,
) -> Result<(), Failure> {
    while let Some(a) = link.poll()? {
        if let Arrival::Forward(c) = a {
            if place == Place::End
                && c.control_kind() == Some(Control::Probe)
                && filter.admit(c.run, joined)
            {
                let echo = Backward::control(Control::Waiting, c.run, c.seq);
                link.send_backward(&echo, true)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::driver::{Counts, Handler, Io, Reply};
    use tactile_messages::Role;
    use tactile_transport::ports::in_memory;

    /// Passes everything on as it came.
    struct Pass;

    impl Handler for Pass {
        type Sample = u64;
        type Totals = u64;
        fn totals(&self, _: &Counts) -> u64 {
            0
        }
    }

    impl Follower for Pass {
        fn forward(
            &mut self,
            c: &Forward,
            out: &mut Reply<u64>,
            _: &mut Io,
        ) -> Result<(), Failure> {
            out.forward = Some(*c);
            out.record = Some(c.seq);
            Ok(())
        }
        fn backward(
            &mut self,
            h: &Backward,
            out: &mut Reply<u64>,
            _: &mut Io,
        ) -> Result<(), Failure> {
            out.backward = Some(*h);
            out.record = Some(h.seq);
            Ok(())
        }
    }

    #[test]
    fn after_a_burst_it_paces_only_once_every_answer_is_back() {
        let [mut master, emulator, mut slave] = in_memory();
        let dir = tempfile::tempdir().expect("tmp");
        let rec = Recorder::open(dir.path(), Role::Emulator, false).expect("rec");
        let timing = Timing::Realtime {
            t_s_ns: 1_000_000,
            wake_early_ns: 200_000,
        };
        let link = Link::new(emulator, Duration::ZERO);
        let mut f = Follow::new(Pass, link, rec, timing, None);
        let mut c = |seq| {
            let s = Forward {
                run: 5,
                seq,
                ..Forward::default()
            };
            master
                .forward_out
                .as_mut()
                .expect("c")
                .publish(&s, false)
                .expect("c");
        };
        let mut paced_after = Vec::new();
        let step = |f: &mut Follow<Pass>| {
            let mut a = f.link.poll().expect("poll").expect("a sample");
            f.handle(&mut a, false).expect("handle");
            pacing(&f.pacer, f.awaiting).is_some()
        };
        c(0);
        paced_after.push(step(&mut f));
        let mut h = |seq| {
            let s = Backward {
                run: 5,
                seq,
                ..Backward::default()
            };
            slave
                .backward_out
                .as_mut()
                .expect("h")
                .publish(&s, false)
                .expect("h");
        };
        h(0);
        paced_after.push(step(&mut f));
        // c(1) and c(2) queued after a stall: v(1) and v(2) go out back to back and two
        // answers are due; after h(1) one still is.
        c(1);
        c(2);
        paced_after.push(step(&mut f));
        paced_after.push(step(&mut f));
        h(1);
        paced_after.push(step(&mut f));
        h(2);
        paced_after.push(step(&mut f));
        assert_eq!(paced_after, [false, true, false, false, false, true]);
    }
}
