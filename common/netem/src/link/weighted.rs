//! Weighted classes: deficit round robin (Shreedhar and Varghese) between classes,
//! each class a FIFO with its own bound, a class's quantum its weight times a base
//! quantum: over a busy period each class gets its weight's share of the bytes.

use super::priority::{ClassMap, ClassSpec};
use super::queue::{Bound, DropCause, Packet, Queue, Sub};
use std::collections::VecDeque;

#[derive(Debug, Default)]
struct Class {
    q: Sub,
    bound: Bound,
    quantum: u64,
    deficit: u64,
    active: bool,
}

/// DRR between weighted classes.
#[derive(Debug)]
pub struct Weighted {
    map: ClassMap,
    classes: Vec<Class>,
    /// The classes with packets, in round order.
    active: VecDeque<usize>,
    packets: usize,
    bytes: u64,
}

impl Weighted {
    /// DRR between `classes` (weights at least 1), a weight of 1 sending `quantum`
    /// bytes a round (at least 1).
    pub fn new(classes: &[ClassSpec], quantum: u32) -> Weighted {
        let flows: Vec<Vec<u32>> = classes.iter().map(|c| c.flows.clone()).collect();
        let mut cs: Vec<Class> = classes
            .iter()
            .map(|c| Class {
                bound: c.bound,
                quantum: u64::from(c.weight.max(1)) * u64::from(quantum.max(1)),
                ..Class::default()
            })
            .collect();
        if cs.is_empty() {
            cs.push(Class {
                quantum: u64::from(quantum.max(1)),
                ..Class::default()
            });
        }
        let n = cs.len();
        Weighted {
            map: ClassMap::new(&flows),
            classes: cs,
            active: VecDeque::with_capacity(n),
            packets: 0,
            bytes: 0,
        }
    }
}

impl Queue for Weighted {
    fn enqueue(&mut self, p: Packet, drops: &mut Vec<(Packet, DropCause)>) {
        let k = self.map.class(p.flow);
        let c = &mut self.classes[k];
        let n = c.q.q.len();
        c.q.push_bounded(p, c.bound, drops);
        if c.q.q.len() == n {
            return;
        }
        self.packets += 1;
        self.bytes += u64::from(p.bytes);
        if !c.active {
            c.active = true;
            c.deficit = c.quantum;
            self.active.push_back(k);
        }
    }

    fn dequeue(&mut self, _now_ns: u64, _drops: &mut Vec<(Packet, DropCause)>) -> Option<Packet> {
        loop {
            let k = *self.active.front()?;
            let c = &mut self.classes[k];
            let head = c.q.q.front().map_or(0, |p| u64::from(p.bytes));
            if head > c.deficit {
                // Its turn is over: the next round gives it another quantum.
                c.deficit += c.quantum;
                self.active.rotate_left(1);
                continue;
            }
            let p = c.q.pop()?;
            c.deficit -= head;
            if c.q.q.is_empty() {
                c.active = false;
                c.deficit = 0;
                self.active.pop_front();
            }
            self.packets -= 1;
            self.bytes -= head;
            return Some(p);
        }
    }

    fn len_packets(&self) -> usize {
        self.packets
    }

    fn len_bytes(&self) -> u64 {
        self.bytes
    }
}
