//! A node's ends as its driver uses them: the inputs polled (backward first: it
//! completes a round trip someone waits for) and waited on, every wait bounded and
//! broken by a stop request; the pacer's sleep before a sample is due; the outputs.

use crate::pace::{deadline_ns, was_waiting, Pacer};
use std::time::{Duration, Instant};
use tactile_messages::samples::{Backward, Forward};
use tactile_transport::{LinkError, PortStats, Ports};

/// A sample arriving at a node.
// Lives on the stack for one sample; boxing the larger variant would allocate per sample.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
pub enum Arrival {
    /// c(n) or v(n).
    Forward(Forward),
    /// h(n) or q(n).
    Backward(Backward),
}

impl Arrival {
    /// The run token and sample number it carries.
    pub fn run_and_seq(&self) -> (u64, u64) {
        match self {
            Arrival::Forward(f) => (f.run, f.seq),
            Arrival::Backward(b) => (b.run, b.seq),
        }
    }
}

/// Why a wait returned without a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Idle {
    /// The deadline passed (or, in one process, nothing more can come).
    Timeout,
    /// SIGINT or SIGTERM arrived.
    Stop,
}

/// How a node blocks when nothing waits in its inputs.
pub trait Block {
    /// Blocks until a sample may have come, or `until` (`None`: no deadline, the
    /// in-process runner's); false when nothing can come before `until` (in one
    /// process: every other node is idle), so the wait ends now.
    fn block(
        &mut self,
        wakes: &[Box<dyn tactile_transport::Wake>],
        until: Option<Instant>,
    ) -> Result<bool, super::Failure>;
}

/// Longest a blocking wait lasts before it looks at the stop flag again.
pub const STOP_POLL: Duration = Duration::from_millis(50);

/// How often a node that receives on two transports looks at the others while it
/// blocks on the first (only once the loop has been idle for the poll budget).
pub const MIXED_POLL: Duration = Duration::from_micros(200);

/// Blocking on the transports themselves, as a node program does.
#[derive(Debug, Clone, Copy, Default)]
pub struct OnTransports;

impl Block for OnTransports {
    fn block(
        &mut self,
        wakes: &[Box<dyn tactile_transport::Wake>],
        until: Option<Instant>,
    ) -> Result<bool, super::Failure> {
        let cap = if wakes.len() > 1 {
            MIXED_POLL
        } else {
            STOP_POLL
        };
        let capped = Instant::now() + cap;
        let until = until.map_or(capped, |u| u.min(capped));
        match wakes.first() {
            Some(w) => w.block(until)?,
            None => std::thread::sleep(until.saturating_duration_since(Instant::now())),
        }
        Ok(true)
    }
}

/// A node's ends and how long it polls before it blocks.
#[derive(Debug)]
pub struct Link {
    ports: Ports,
    spin: Duration,
}

impl Link {
    /// The ends `ports`, polled for `spin` before each block.
    pub fn new(ports: Ports, spin: Duration) -> Link {
        Link { ports, spin }
    }

    /// A sample if one waits, backward first (as [`Link::poll_into`]).
    pub fn poll(&mut self) -> Result<Option<Arrival>, LinkError> {
        let mut a = Arrival::Forward(Forward::default());
        Ok(self.poll_into(&mut a)?.then_some(a))
    }

    /// A sample if one waits, into `slot`, backward first: true if one came (then it
    /// is in `slot`), false if none (`slot` then holds no sample to handle). From an
    /// in-memory stream a sample is copied once, from its queue to `slot`. A slot of
    /// the other kind is first made a default one of the kind polled, even when the
    /// poll then finds nothing (only where `may_have` is a hint, not in memory):
    /// receiving and then moving the sample in instead measured 26.7 copies a sample
    /// against 20.7 in the in-process run, where the emulator's slot changes kind at
    /// every sample, and a node program's polls yield the CPU between them.
    pub fn poll_into(&mut self, slot: &mut Arrival) -> Result<bool, LinkError> {
        if let Some(b) = self.ports.backward_in.as_mut().filter(|b| b.may_have()) {
            if !matches!(slot, Arrival::Backward(_)) {
                *slot = Arrival::Backward(Backward::default());
            }
            if let Arrival::Backward(h) = slot {
                if b.recv_into(h)? {
                    return Ok(true);
                }
            }
        }
        if let Some(f) = self.ports.forward_in.as_mut().filter(|f| f.may_have()) {
            if !matches!(slot, Arrival::Forward(_)) {
                *slot = Arrival::Forward(Forward::default());
            }
            if let Arrival::Forward(c) = slot {
                return f.recv_into(c);
            }
        }
        Ok(false)
    }

    /// Waits for a sample until `deadline` (as [`Link::wait_into`]).
    pub fn wait(
        &mut self,
        deadline: Instant,
        block: &mut dyn Block,
    ) -> Result<Result<Arrival, Idle>, super::Failure> {
        let mut a = Arrival::Forward(Forward::default());
        Ok(self.wait_into(Some(deadline), block, &mut a)?.map(|()| a))
    }

    /// Waits for a sample until `deadline`, taken into `slot` (as
    /// [`Link::poll_into`]): polls (yielding the CPU) for the poll budget, then blocks
    /// with `block`; a stop request ends it. With no deadline (`None`, the in-process
    /// runner's) the wait has no timeout (a sample, a stop request or `block` saying
    /// nothing more can come ends it), and the clock is never read: the clock
    /// took 6 % of the in-process run's time, and this was one read a sample of five.
    pub fn wait_into(
        &mut self,
        deadline: Option<Instant>,
        block: &mut dyn Block,
        slot: &mut Arrival,
    ) -> Result<Result<(), Idle>, super::Failure> {
        // Without a poll budget (lockstep, one process) the start is never needed:
        // one clock read a wait saved.
        let start = (!self.spin.is_zero()).then(Instant::now);
        loop {
            if self.poll_into(slot)? {
                return Ok(Ok(()));
            }
            if crate::signals::stop_requested() {
                return Ok(Err(Idle::Stop));
            }
            if deadline.is_some() || start.is_some() {
                let now = Instant::now();
                if deadline.is_some_and(|d| now >= d) {
                    return Ok(Err(Idle::Timeout));
                }
                if start.is_some_and(|s| now.duration_since(s) < self.spin) {
                    // Yield rather than burn: on two cores three polling processes
                    // would otherwise hold the core the next stage of the chain needs.
                    std::thread::yield_now();
                    continue;
                }
            }
            if !block.block(&self.ports.wakes, deadline)? {
                return Ok(self.poll_into(slot)?.then_some(()).ok_or(Idle::Timeout));
            }
        }
    }

    /// Receives the next sample the tick-aware way: takes what is already there
    /// (after a stall several samples may be queued, and each must go at once, not one
    /// per period); else sleeps until the pacer's wake-up (never past `until`), then
    /// waits until `until`. Without a pacer (lockstep) it just waits. Also says
    /// whether a sample found at the first poll after the sleep was already waiting,
    /// for [`Pacer::arrived`].
    pub fn recv_paced(
        &mut self,
        pacer: Option<&Pacer>,
        until: Instant,
        block: &mut dyn Block,
    ) -> Result<(Result<Arrival, Idle>, bool), super::Failure> {
        let Some(p) = pacer else {
            return Ok((self.wait(until, block)?, false));
        };
        if let Some(a) = self.poll()? {
            return Ok((Ok(a), false));
        }
        let slept = p.sleep(deadline_ns(until));
        let called = tactile_messages::clock::now_ns();
        let got = self.wait(until, block)?;
        let waiting =
            slept && got.is_ok() && was_waiting(called, tactile_messages::clock::now_ns());
        Ok((got, waiting))
    }

    /// Publishes a forward sample, if the node has a forward output.
    pub fn send_forward(&mut self, v: &Forward, control: bool) -> Result<bool, LinkError> {
        match &mut self.ports.forward_out {
            Some(o) => o.publish(v, control).map(|()| true),
            None => Ok(false),
        }
    }

    /// Publishes a backward sample, if the node has a backward output.
    pub fn send_backward(&mut self, h: &Backward, control: bool) -> Result<bool, LinkError> {
        match &mut self.ports.backward_out {
            Some(o) => o.publish(h, control).map(|()| true),
            None => Ok(false),
        }
    }

    /// True if the node passes forward samples on (it is not the end of the chain).
    pub fn forwards(&self) -> bool {
        self.ports.forward_out.is_some()
    }

    /// What the ends counted.
    pub fn stats(&self) -> PortStats {
        self.ports.stats()
    }

    /// The ends back, for another wait policy.
    pub fn into_ports(self) -> Ports {
        self.ports
    }

    /// The peers known to have died.
    pub fn dead_peers(&self) -> Vec<String> {
        self.ports.dead_peers()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pace::Pacer;
    use tactile_messages::clock::now_ns;

    /// Blocks as if nothing came, counting the calls.
    struct Nothing(u32);

    impl Block for Nothing {
        fn block(
            &mut self,
            _: &[Box<dyn tactile_transport::Wake>],
            until: Option<Instant>,
        ) -> Result<bool, super::super::Failure> {
            self.0 += 1;
            let until = until.expect("these tests wait with a deadline");
            std::thread::sleep(until.saturating_duration_since(Instant::now()));
            Ok(true)
        }
    }

    const T: u64 = 1_000_000;

    /// c(seq) published at the master's end of in-memory ports.
    fn publish_c(master: &mut tactile_transport::Ports, seq: u64) {
        let c = Forward {
            seq,
            ..Forward::default()
        };
        let out = master.forward_out.as_mut().expect("c");
        out.publish(&c, false).expect("c");
    }

    /// h(seq) published at the slave's end of in-memory ports.
    fn publish_h(slave: &mut tactile_transport::Ports, seq: u64) {
        let h = Backward {
            seq,
            ..Backward::default()
        };
        let out = slave.backward_out.as_mut().expect("h");
        out.publish(&h, false).expect("h");
    }

    #[test]
    fn a_poll_into_a_slot_takes_each_sample_whole_backward_first() {
        let [mut master, emulator, mut slave] = tactile_transport::ports::in_memory();
        let mut link = Link::new(emulator, Duration::ZERO);
        let mut slot = Arrival::Backward(Backward::default());
        assert!(!link.poll_into(&mut slot).expect("poll"), "nothing yet");
        for seq in [3, 4] {
            publish_c(&mut master, seq);
        }
        publish_h(&mut slave, 9);
        // The slot's kind changes with what comes; each sample comes whole (its hop
        // counter stamped by the publisher), in order, backward first.
        let mut got = Vec::new();
        while link.poll_into(&mut slot).expect("poll") {
            got.push(match &slot {
                Arrival::Forward(f) => ('c', f.seq, f.hop_seq),
                Arrival::Backward(b) => ('h', b.seq, b.hop_seq),
            });
        }
        assert_eq!(got, [('h', 9, 0), ('c', 3, 0), ('c', 4, 1)]);
        let stats = link.stats();
        assert_eq!(
            (stats.forward_in.received, stats.backward_in.received),
            (2, 1)
        );
    }

    /// Says nothing more can come (the in-process runner's answer once its other
    /// nodes are idle), counting the calls.
    struct Settled(u32);

    impl Block for Settled {
        fn block(
            &mut self,
            _: &[Box<dyn tactile_transport::Wake>],
            _: Option<Instant>,
        ) -> Result<bool, super::super::Failure> {
            self.0 += 1;
            Ok(false)
        }
    }

    #[test]
    fn a_wait_into_a_slot_takes_what_came_then_times_out_when_nothing_can_come() {
        let [mut master, emulator, mut slave] = tactile_transport::ports::in_memory();
        let mut link = Link::new(emulator, Duration::ZERO);
        let far = Instant::now() + Duration::from_secs(3600);
        let mut block = Settled(0);
        let mut slot = Arrival::Forward(Forward::default());
        publish_h(&mut slave, 5);
        publish_c(&mut master, 6);
        let mut got = Vec::new();
        while let Ok(()) = link.wait_into(None, &mut block, &mut slot).expect("wait") {
            got.push(slot.run_and_seq().1);
        }
        // Backward first, each taken without blocking; then one block, which says
        // nothing can come, ends the wait, which has no deadline, at once.
        assert_eq!(got, [5, 6]);
        assert_eq!(block.0, 1);
        // `wait` is the same wait, returning the sample.
        publish_c(&mut master, 6);
        let got = link.wait(far, &mut block).expect("wait");
        assert!(matches!(got, Ok(Arrival::Forward(f)) if f.seq == 6));
        assert!(matches!(link.wait(far, &mut block), Ok(Err(Idle::Timeout))));
    }

    #[test]
    fn a_paced_receive_takes_what_is_waiting_before_it_sleeps() {
        let [mut master, emulator, _] = tactile_transport::ports::in_memory();
        let mut link = Link::new(emulator, Duration::ZERO);
        // A pacer whose next wake-up is a second away: a queued sample must still be
        // taken at once, without sleeping or blocking.
        let mut p = Pacer::new(T, 200_000);
        p.arrived(0, now_ns() + 1_000_000_000, false);
        let c = Forward {
            seq: 7,
            ..Forward::default()
        };
        master
            .forward_out
            .as_mut()
            .expect("c")
            .publish(&c, false)
            .expect("c");
        let start = Instant::now();
        let mut block = Nothing(0);
        let (got, waiting) = link
            .recv_paced(Some(&p), start + Duration::from_secs(5), &mut block)
            .expect("recv");
        assert!(matches!(got, Ok(Arrival::Forward(f)) if f.seq == 7));
        assert!(
            !waiting,
            "nothing slept, so nothing is known to have waited"
        );
        assert_eq!(block.0, 0);
        assert!(start.elapsed() < Duration::from_millis(100));
        // Nothing there: it sleeps (never more than two periods), then waits until
        // the caller's deadline.
        let start = Instant::now();
        let until = start + Duration::from_millis(30);
        let (got, _) = link.recv_paced(Some(&p), until, &mut block).expect("recv");
        assert!(matches!(got, Err(Idle::Timeout)));
        assert!(block.0 >= 1);
        let waited = start.elapsed();
        assert!(waited >= Duration::from_millis(30), "{waited:?}");
        assert!(waited < Duration::from_millis(500), "{waited:?}");
    }
}
