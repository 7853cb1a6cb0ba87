//! A channel whose packets cross a [`Link`]: the packet of sample n reaches the link
//! at n t_s; at each sample the link runs up to that time and what departed by then
//! arrives. A packet's fate is known when the link decides it (a drop-head queue may
//! push it out long after it was sent), so the sample waits, held here, until then.

use super::{Channel, Emitted, Rest, Slot, Value};
use crate::link::{Event, Fate, FlowStats, Link, Packet};
use crate::LinkSpec;
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

/// The link and the samples whose packets are on it.
#[derive(Debug)]
pub(super) struct OnLink {
    link: Link,
    /// The samples on the link, in sending order (a flow's packets leave a FIFO, and
    /// each flow of a fair or priority scheduler, in that order; a drop-tail refusal
    /// is the newest, at the back). At most the link's memory cap of them.
    held: VecDeque<Slot>,
    /// The link's events of one sample, the buffer reused.
    events: Vec<Event>,
    /// The sampling period, ns.
    t_s_ns: f64,
    /// Each packet's size on the wire.
    bytes: u32,
    /// The newest packet arrived.
    newest: Option<Slot>,
    /// The packet the last output came from.
    last_emitted: Option<u64>,
}

impl OnLink {
    pub(super) fn new(spec: &LinkSpec, t_s: f64, rng: ChaCha8Rng) -> OnLink {
        OnLink {
            link: spec.build(rng),
            held: VecDeque::new(),
            events: Vec::new(),
            t_s_ns: t_s * 1e9,
            bytes: spec.packet_bytes,
            newest: None,
            last_emitted: None,
        }
    }

    pub(super) fn stats(&self) -> FlowStats {
        self.link.stats(0)
    }

    /// Sample `slot` at its time: the link runs up to it, the packet (if `sent`) joins
    /// it, and the packets whose fate was decided meanwhile arrive or are lost.
    /// Returns whether one was lost, and the first sample sent if this is it.
    fn step(&mut self, slot: Slot, sent: bool) -> (bool, Option<Slot>) {
        // Saturating: a peer's absurd first number must not wrap time round.
        let now = (slot.seq as f64 * self.t_s_ns).round() as u64;
        self.events.clear();
        self.link.advance(now, &mut self.events);
        if sent {
            self.held.push_back(slot);
            let p = Packet {
                flow: 0,
                tag: slot.seq,
                bytes: self.bytes,
                arrival_ns: now,
            };
            self.link.enqueue(p, &mut self.events);
        }
        let mut lost = false;
        for k in 0..self.events.len() {
            let e = self.events[k];
            let Some(s) = self.take(e.packet.tag) else {
                continue;
            };
            match e.fate {
                Fate::Departed(_) => {
                    if self.newest.is_none_or(|n| s.seq > n.seq) {
                        self.newest = Some(s);
                    }
                }
                // One packet at most a sample for a flow of one size: the arrival
                // itself (tail, cap) or the one it pushes out of the head.
                Fate::Dropped(_) => lost = true,
            }
        }
        (lost, sent.then_some(slot))
    }

    /// The held sample of packet `tag`: at the front (departures, head drops), the
    /// back (a refused arrival), or, for a scheduler that reorders flows, searched.
    fn take(&mut self, tag: u64) -> Option<Slot> {
        if self.held.front().is_some_and(|s| s.seq == tag) {
            return self.held.pop_front();
        }
        if self.held.back().is_some_and(|s| s.seq == tag) {
            return self.held.pop_back();
        }
        let i = self.held.iter().position(|s| s.seq == tag)?;
        self.held.remove(i)
    }
}

impl Channel {
    /// [`Channel::push_packet`] over a link: the newest packet departed by this
    /// sample's time, its age added to its delay, or the last one again, flagged.
    /// `lost` says a packet of this channel was dropped at this sample (not
    /// necessarily this sample's: a drop-head queue drops an older one).
    pub(super) fn push_link(&mut self, slot: Slot, sent: bool) -> Emitted {
        let seq = slot.seq;
        let in_order = self.in_order(seq);
        let Some(l) = self.link.as_deref_mut() else {
            return self.push_direct(slot, sent);
        };
        // A number out of order (a peer's bug or forgery) moves no time on: the link
        // must not run ahead to an absurd number's time.
        let (lost, first) = if in_order {
            l.step(slot, sent)
        } else {
            (false, None)
        };
        if self.first.is_none() {
            self.first = first;
        }
        let newest = l.newest;
        let fresh = newest.is_some() && newest.map(|n| n.seq) != l.last_emitted;
        l.last_emitted = newest.map(|n| n.seq);
        let from = newest.or(self.first).unwrap_or(Slot {
            seq,
            values: [Value::default(); 3],
            extra: Rest::default(),
        });
        let (values, noise) = self.aged(&from, seq);
        Emitted {
            values,
            noise,
            extra: from.extra,
            jitter: 0.0,
            lost,
            duplicated: false,
            substituted: !fresh,
        }
    }
}
