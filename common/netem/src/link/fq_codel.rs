//! FQ-CoDel (RFC 8290): a queue per flow, served by deficit round robin in quanta of
//! bytes with new flows (just active) before old ones, each flow's queue under its own
//! CoDel ([`super::codel`]); at the total limit the fattest flow (most bytes) loses
//! packets from its head, up to half its bytes or a batch (Linux's and ns-3's
//! `drop_batch_size`).
//!
//! Flows are keyed directly, `flow % flows`, not hashed: Tactile numbers its flows
//! (0 the haptic one, the cross flows after it), so a flow id is already what the
//! RFC's hash of the 5-tuple stands for, and keying directly leaves no collision to
//! a hash function's luck (two of a few flows sharing a queue is what FQ is there to
//! prevent). The ns-3 check gives its items the same key as their hash.

use super::codel::{CodelParams, CodelState};
use super::queue::{DropCause, Packet, Queue, Sub};
use std::collections::VecDeque;

/// FQ-CoDel's parameters, RFC 8290's (and Linux's) defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FqCodelParams {
    /// Each flow's CoDel.
    pub codel: CodelParams,
    /// Bytes a flow may send each round [1514].
    pub quantum: u32,
    /// Flow queues [1024].
    pub flows: u32,
    /// Most packets held in all [10240].
    pub limit: u32,
    /// Most packets dropped from the fattest flow at once [64].
    pub drop_batch: u32,
}

impl Default for FqCodelParams {
    fn default() -> FqCodelParams {
        FqCodelParams {
            codel: CodelParams::default(),
            quantum: 1514,
            flows: 1024,
            limit: 10_240,
            drop_batch: 64,
        }
    }
}

/// Which list a flow is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum List {
    #[default]
    Idle,
    New,
    Old,
}

#[derive(Debug, Default)]
struct Flow {
    q: Sub,
    codel: CodelState,
    deficit: i64,
    list: List,
}

/// FQ-CoDel. The flows' queues and the lists are made once; a queue allocates only
/// while it grows to its longest.
#[derive(Debug)]
pub struct FqCodel {
    flows: Vec<Flow>,
    new: VecDeque<u32>,
    old: VecDeque<u32>,
    packets: usize,
    bytes: u64,
    params: FqCodelParams,
}

impl FqCodel {
    /// FQ-CoDel with `params` (`flows`, `quantum`, `limit` and `drop_batch` at least 1).
    pub fn new(params: FqCodelParams) -> FqCodel {
        let n = params.flows.max(1) as usize;
        FqCodel {
            flows: (0..n).map(|_| Flow::default()).collect(),
            new: VecDeque::with_capacity(n),
            old: VecDeque::with_capacity(n),
            packets: 0,
            bytes: 0,
            params,
        }
    }

    /// The limit is passed: the flow of most bytes (the first of them) drops from its
    /// head until half its bytes are gone or a batch is.
    fn drop_fattest(&mut self, drops: &mut Vec<(Packet, DropCause)>) {
        let mut fat = 0;
        for (i, f) in self.flows.iter().enumerate() {
            if f.q.bytes > self.flows[fat].q.bytes {
                fat = i;
            }
        }
        let f = &mut self.flows[fat];
        let threshold = f.q.bytes >> 1;
        let (mut len, mut count) = (0u64, 0u32);
        while let Some(p) = f.q.pop() {
            self.packets -= 1;
            self.bytes -= u64::from(p.bytes);
            len += u64::from(p.bytes);
            count += 1;
            drops.push((p, DropCause::Head));
            if count >= self.params.drop_batch || len >= threshold {
                break;
            }
        }
    }
}

impl Queue for FqCodel {
    fn enqueue(&mut self, p: Packet, drops: &mut Vec<(Packet, DropCause)>) {
        let i = p.flow % self.flows.len() as u32;
        let f = &mut self.flows[i as usize];
        f.q.push(p);
        if f.list == List::Idle {
            f.list = List::New;
            f.deficit = i64::from(self.params.quantum);
            self.new.push_back(i);
        }
        self.packets += 1;
        self.bytes += u64::from(p.bytes);
        if self.packets > self.params.limit as usize {
            self.drop_fattest(drops);
        }
    }

    fn dequeue(&mut self, now_ns: u64, drops: &mut Vec<(Packet, DropCause)>) -> Option<Packet> {
        loop {
            let (i, from_new) = match (self.new.front(), self.old.front()) {
                (Some(&i), _) => (i, true),
                (None, Some(&i)) => (i, false),
                (None, None) => return None,
            };
            let f = &mut self.flows[i as usize];
            let pop = |fq: &mut FqCodel| {
                if from_new {
                    fq.new.pop_front();
                } else {
                    fq.old.pop_front();
                }
            };
            if f.deficit <= 0 {
                f.deficit += i64::from(self.params.quantum);
                f.list = List::Old;
                pop(self);
                self.old.push_back(i);
                continue;
            }
            let (n0, b0) = (f.q.q.len(), f.q.bytes);
            let got = f.codel.dequeue(&self.params.codel, &mut f.q, now_ns, drops);
            self.packets -= n0 - f.q.q.len();
            self.bytes -= b0 - f.q.bytes;
            match got {
                Some(p) => {
                    f.deficit -= i64::from(p.bytes);
                    return Some(p);
                }
                None => {
                    // RFC 8290 §4.2 (and ns-3): an empty new flow goes to the end of
                    // the old list, an empty old one leaves (Linux moves a new one only
                    // if the old list has others).
                    f.list = if from_new { List::Old } else { List::Idle };
                    pop(self);
                    if from_new {
                        self.old.push_back(i);
                    }
                }
            }
        }
    }

    fn len_packets(&self) -> usize {
        self.packets
    }

    fn len_bytes(&self) -> u64 {
        self.bytes
    }
}
