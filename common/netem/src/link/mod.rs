//! A link with a rate and a queue, event-driven: packets (a flow, a size on the wire,
//! an arrival time in ns) enter a [`Queue`] discipline; a server takes them out,
//! either a Mahimahi trace of delivery opportunities with `mm-link`'s semantics
//! exactly (`src/frontend/link_queue.cc`: each opportunity carries
//! [`OPPORTUNITY_BYTES`], the bytes a packet leaves unsent carry it into the next one,
//! and the opportunities at or before an arrival are burned before it is queued) or a
//! fixed rate in bit/s (a packet of B bytes takes 8 B / rate), or a rate over time
//! ([`RateSteps`]). The result is each
//! packet's departure time or its drop, as [`Event`]s.
//!
//! Time only moves forward: [`Link::advance`] runs the server up to a time and
//! [`Link::enqueue`] advances to the packet's arrival first, as mm-link's
//! `read_packet` calls `rationalize`. A packet's fate may depend on later arrivals
//! (drop-head pushes it out, an AQM drops it at dequeue): it is known only from the
//! event, never at send.

mod codel;
mod codel_linux;
mod fq_codel;
mod pie;
mod priority;
mod queue;
mod steps;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_aqm;
mod trace;
mod weighted;

pub use codel::{Arithmetic, Codel, CodelParams};
pub use fq_codel::{FqCodel, FqCodelParams};
pub use pie::{Pie, PieParams};
pub use priority::{ClassSpec, Priority};
pub use queue::{Bound, DropCause, Fifo, Packet, Queue};
pub use steps::{RateSteps, MAX_STEPS};
pub use trace::{Opportunities, MAX_OPPORTUNITIES, OPPORTUNITY_BYTES};
pub use weighted::Weighted;

/// Most packets a link's queue holds whatever its discipline (an `infinite` queue at
/// overload too): an arrival beyond it is dropped and counted as
/// [`DropCause::Cap`]. 100,000 packets: 100 s of a 1 kHz flow, 2.4 MB of queue
/// (and 24 MB of the channel's copies of the samples, 240 bytes each).
pub const MAX_QUEUE_PACKETS: usize = 100_000;

/// What takes packets out of the queue.
#[derive(Debug, Clone, PartialEq)]
pub enum Server {
    /// A Mahimahi trace, looped.
    Trace(Opportunities),
    /// A fixed rate, bit/s (positive, finite).
    Rate(f64),
    /// A rate over time.
    Steps(RateSteps),
}

/// What became of a packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// Its last byte left at this time, ns.
    Departed(u64),
    /// Dropped, and why.
    Dropped(DropCause),
}

/// A packet and its fate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Event {
    /// The packet as it entered.
    pub packet: Packet,
    /// What became of it.
    pub fate: Fate,
}

/// What a link counted for one flow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FlowStats {
    /// Packets that reached the link.
    pub offered: u64,
    /// Packets that left it.
    pub departed: u64,
    /// Packets its discipline dropped (tail, head or AQM).
    pub dropped: u64,
    /// Packets refused at the memory cap ([`MAX_QUEUE_PACKETS`]).
    pub dropped_cap: u64,
    /// Sum of the departed packets' time on the link (arrival to last byte out:
    /// mm-link's logged delay), ns.
    pub delay_ns_sum: u64,
    /// The longest of them, ns.
    pub delay_ns_max: u64,
}

/// The link: a queue discipline and a server.
#[derive(Debug)]
pub struct Link {
    queue: Box<dyn Queue>,
    server: Server,
    /// A trace's next opportunity (counted over its loops); a rate over time's step.
    next: u64,
    /// A rate server's time when it is free (the packet in transit's last byte).
    free_at: u64,
    /// The packet being sent and its bytes not sent yet (mm-link's
    /// `packet_in_transit_`): out of the queue, so no discipline can drop it.
    transit: Option<(Packet, u32)>,
    drops: Vec<(Packet, DropCause)>,
    stats: Vec<FlowStats>,
}

impl Link {
    /// A link of `flows` flows (numbered from 0), serving `queue` with `server`.
    pub fn new(server: Server, queue: Box<dyn Queue>, flows: usize) -> Link {
        Link {
            queue,
            server,
            next: 0,
            free_at: 0,
            transit: None,
            drops: Vec::new(),
            stats: vec![FlowStats::default(); flows.max(1)],
        }
    }

    /// Packet `p` reaches the link at `p.arrival_ns` (not before the last time the
    /// link was advanced to): the server runs up to then, then the discipline takes
    /// it. Fates decided meanwhile are pushed onto `out`.
    pub fn enqueue(&mut self, p: Packet, out: &mut Vec<Event>) {
        let now = p.arrival_ns;
        self.advance(now, out);
        let idle = self.transit.is_none() && self.queue.is_empty();
        if let Some(s) = self.stats.get_mut(p.flow as usize) {
            s.offered += 1;
        }
        if self.queue.len_packets() >= MAX_QUEUE_PACKETS {
            self.drop(p, DropCause::Cap, out);
            return;
        }
        self.queue.enqueue(p, &mut self.drops);
        self.flush_drops(out);
        if idle {
            // A rate server idle since its last packet starts this one on arrival.
            self.free_at = self.free_at.max(now);
            self.advance(now, out);
        }
    }

    /// Runs the server up to `now_ns`: the packets whose last byte has left by then
    /// depart, and whatever the discipline drops on the way is dropped.
    pub fn advance(&mut self, now_ns: u64, out: &mut Vec<Event>) {
        match &self.server {
            Server::Trace(_) => self.advance_trace(now_ns, out),
            Server::Rate(_) | Server::Steps(_) => self.advance_rate(now_ns, out),
        }
    }

    /// What the link counted for `flow`.
    pub fn stats(&self, flow: u32) -> FlowStats {
        self.stats.get(flow as usize).copied().unwrap_or_default()
    }

    /// The queue (its lengths).
    pub fn queue(&self) -> &dyn Queue {
        self.queue.as_ref()
    }

    /// mm-link's `rationalize`: each opportunity at or before `now` is burned in turn,
    /// [`OPPORTUNITY_BYTES`] of it spent on the packet in transit and then on packets
    /// taken from the queue, a packet departing at the opportunity that sends its last
    /// byte; the bytes left when the queue is empty are lost.
    fn advance_trace(&mut self, now_ns: u64, out: &mut Vec<Event>) {
        let now_ms = now_ns / 1_000_000;
        loop {
            let Server::Trace(ops) = &self.server else {
                return;
            };
            let t_ms = ops.time_ms(self.next);
            if t_ms > now_ms {
                return;
            }
            if self.transit.is_none() && self.queue.is_empty() {
                // Nothing to send: every opportunity up to now would be burned empty.
                self.next = ops.first_after(now_ms).max(self.next + 1);
                continue;
            }
            self.next += 1;
            self.burn(t_ms.saturating_mul(1_000_000), out);
        }
    }

    /// One opportunity at `at` ns: mm-link's inner loop of `rationalize`.
    fn burn(&mut self, at: u64, out: &mut Vec<Event>) {
        let mut budget = OPPORTUNITY_BYTES;
        while budget > 0 {
            let (p, left) = match self.transit {
                Some(t) => t,
                None => match self.queue.dequeue(at, &mut self.drops) {
                    Some(p) => (p, p.bytes),
                    None => break,
                },
            };
            self.flush_drops(out);
            let send = budget.min(left);
            budget -= send;
            if left == send {
                self.transit = None;
                self.depart(p, at, out);
            } else {
                self.transit = Some((p, left - send));
            }
        }
        self.flush_drops(out);
    }

    /// A server of a rate (fixed, or over time): the packet in transit departs when
    /// its last bit is out; the next one is taken from the queue then.
    fn advance_rate(&mut self, now_ns: u64, out: &mut Vec<Event>) {
        loop {
            if let Some((p, _)) = self.transit {
                if self.free_at > now_ns {
                    return;
                }
                self.transit = None;
                self.depart(p, self.free_at, out);
            }
            let start = self.free_at;
            let next = self.queue.dequeue(start, &mut self.drops);
            self.flush_drops(out);
            let Some(p) = next else {
                return;
            };
            let bits = f64::from(p.bytes) * 8.0;
            self.free_at = match &self.server {
                Server::Steps(steps) => steps.finish(&mut self.next, start, bits),
                Server::Rate(rate) => start.saturating_add((bits * 1e9 / rate).ceil() as u64),
                Server::Trace(_) => start,
            };
            self.transit = Some((p, 0));
        }
    }

    fn depart(&mut self, p: Packet, at: u64, out: &mut Vec<Event>) {
        if let Some(s) = self.stats.get_mut(p.flow as usize) {
            let d = at.saturating_sub(p.arrival_ns);
            s.departed += 1;
            s.delay_ns_sum = s.delay_ns_sum.saturating_add(d);
            s.delay_ns_max = s.delay_ns_max.max(d);
        }
        out.push(Event {
            packet: p,
            fate: Fate::Departed(at),
        });
    }

    fn drop(&mut self, p: Packet, cause: DropCause, out: &mut Vec<Event>) {
        if let Some(s) = self.stats.get_mut(p.flow as usize) {
            match cause {
                DropCause::Cap => s.dropped_cap += 1,
                _ => s.dropped += 1,
            }
        }
        out.push(Event {
            packet: p,
            fate: Fate::Dropped(cause),
        });
    }

    fn flush_drops(&mut self, out: &mut Vec<Event>) {
        let mut drops = std::mem::take(&mut self.drops);
        for (p, cause) in drops.drain(..) {
            self.drop(p, cause, out);
        }
        self.drops = drops;
    }
}
