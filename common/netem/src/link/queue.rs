//! Queue disciplines of a [`Link`](super::Link): mm-link's three (`droptail`,
//! `drophead`, `infinite`, `src/packet/` of Mahimahi), behind one [`Queue`] trait that
//! a discipline deciding at dequeue (CoDel, PIE: the packet's sojourn is `now -
//! arrival_ns`) or per flow (FQ-CoDel, priority classes: [`Packet::flow`]) fits
//! without change.

use std::collections::VecDeque;

/// One packet on a link. Plain data, copied: a queue holds these and nothing else,
/// so a queue allocates only while it grows to its longest.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Packet {
    /// Its flow (0: the haptic flow; a scheduler maps flows to classes).
    pub flow: u32,
    /// The sender's number for it (the channel's sample number), handed back with its
    /// fate.
    pub tag: u64,
    /// Its size on the wire, bytes (payload and headers: what the link carries).
    pub bytes: u32,
    /// When it reached the link, ns.
    pub arrival_ns: u64,
}

/// Why a packet was dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DropCause {
    /// Refused on arrival: the queue was at its bound (drop-tail).
    Tail,
    /// Pushed out of the head by a later arrival (drop-head).
    Head,
    /// Refused on arrival because the queue held the link's hard memory cap
    /// ([`super::MAX_QUEUE_PACKETS`]), whatever the discipline.
    Cap,
    /// Dropped by an active queue management decision (CoDel, PIE).
    Aqm,
}

/// A queue discipline. The link calls [`Queue::enqueue`] at each arrival and
/// [`Queue::dequeue`] each time it can send (a Mahimahi opportunity, a rate server
/// free); both may drop packets, which they push into `drops` (the link's buffer,
/// reused) with their cause. The link applies the memory cap before `enqueue`.
pub trait Queue: std::fmt::Debug + Send {
    /// Takes `p` in at time `p.arrival_ns`; refused or evicted packets into `drops`.
    fn enqueue(&mut self, p: Packet, drops: &mut Vec<(Packet, DropCause)>);
    /// The next packet to send at `now_ns`, if any; packets dropped on the way into
    /// `drops`.
    fn dequeue(&mut self, now_ns: u64, drops: &mut Vec<(Packet, DropCause)>) -> Option<Packet>;
    /// Packets held.
    fn len_packets(&self) -> usize;
    /// Bytes held.
    fn len_bytes(&self) -> u64;
    /// True when it holds no packet.
    fn is_empty(&self) -> bool {
        self.len_packets() == 0
    }
}

/// mm-link's `DroppingPacketQueue` bound: `packets` and/or `bytes` (0: no bound on
/// that measure; mm-link refuses both 0, and so does the scenario).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Bound {
    /// Most packets held, 0 for none.
    pub packets: u32,
    /// Most bytes held, 0 for none.
    pub bytes: u64,
}

impl Bound {
    /// mm-link's `good_with`: within every bound that is set.
    pub(super) fn holds(&self, bytes: u64, packets: usize) -> bool {
        (self.bytes == 0 || bytes <= self.bytes)
            && (self.packets == 0 || packets <= self.packets as usize)
    }
}

/// Which end a full [`Fifo`] drops from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    /// The arrival (drop-tail).
    Tail,
    /// The oldest packets (drop-head).
    Head,
}

/// mm-link's three disciplines, one FIFO as its `DroppingPacketQueue` and
/// `InfinitePacketQueue` are: `--uplink-queue=droptail` refuses an arrival that would
/// break the bound; `drophead` takes every arrival, then drops from the head until
/// the bound holds again (the arrival itself, if it alone breaks it); `infinite`
/// (mm-link's default) takes everything, only the link's memory cap
/// ([`super::MAX_QUEUE_PACKETS`]) refusing, counted as [`DropCause::Cap`].
#[derive(Debug)]
pub struct Fifo {
    q: VecDeque<Packet>,
    bytes: u64,
    bound: Bound,
    end: End,
}

impl Fifo {
    /// A drop-tail queue bounded by `bound`.
    pub fn drop_tail(bound: Bound) -> Fifo {
        Fifo::with(bound, End::Tail)
    }

    /// A drop-head queue bounded by `bound`.
    pub fn drop_head(bound: Bound) -> Fifo {
        Fifo::with(bound, End::Head)
    }

    /// An infinite queue: a drop-tail queue with no bound.
    pub fn infinite() -> Fifo {
        Fifo::with(Bound::default(), End::Tail)
    }

    fn with(bound: Bound, end: End) -> Fifo {
        Fifo {
            q: VecDeque::new(),
            bytes: 0,
            bound,
            end,
        }
    }

    fn push(&mut self, p: Packet) {
        self.bytes += u64::from(p.bytes);
        self.q.push_back(p);
    }

    fn pop(&mut self) -> Option<Packet> {
        let p = self.q.pop_front()?;
        self.bytes -= u64::from(p.bytes);
        Some(p)
    }
}

impl Queue for Fifo {
    fn enqueue(&mut self, p: Packet, drops: &mut Vec<(Packet, DropCause)>) {
        match self.end {
            End::Tail => {
                let (bytes, packets) = (self.bytes + u64::from(p.bytes), self.q.len() + 1);
                if self.bound.holds(bytes, packets) {
                    self.push(p);
                } else {
                    drops.push((p, DropCause::Tail));
                }
            }
            End::Head => {
                self.push(p);
                while !self.bound.holds(self.bytes, self.q.len()) {
                    match self.pop() {
                        Some(d) => drops.push((d, DropCause::Head)),
                        None => break,
                    }
                }
            }
        }
    }

    fn dequeue(&mut self, _now_ns: u64, _drops: &mut Vec<(Packet, DropCause)>) -> Option<Packet> {
        self.pop()
    }

    fn len_packets(&self) -> usize {
        self.q.len()
    }

    fn len_bytes(&self) -> u64 {
        self.bytes
    }
}

/// A FIFO and its bytes: the queue of one CoDel, one flow of FQ-CoDel, one class.
#[derive(Debug, Default)]
pub(super) struct Sub {
    pub(super) q: VecDeque<Packet>,
    pub(super) bytes: u64,
}

impl Sub {
    pub(super) fn push(&mut self, p: Packet) {
        self.bytes += u64::from(p.bytes);
        self.q.push_back(p);
    }

    /// Takes `p` if `bound` still holds with it (drop-tail), else drops it.
    pub(super) fn push_bounded(
        &mut self,
        p: Packet,
        bound: Bound,
        drops: &mut Vec<(Packet, DropCause)>,
    ) {
        if bound.holds(self.bytes + u64::from(p.bytes), self.q.len() + 1) {
            self.push(p);
        } else {
            drops.push((p, DropCause::Tail));
        }
    }

    pub(super) fn pop(&mut self) -> Option<Packet> {
        let p = self.q.pop_front()?;
        self.bytes -= u64::from(p.bytes);
        Some(p)
    }
}
