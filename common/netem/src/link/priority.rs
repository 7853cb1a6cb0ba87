//! Strict priority between classes: each class a FIFO with its own bound (drop-tail),
//! the first non-empty class in order always served first. A flow's class is given by
//! the configuration (the haptic flow in a class of its own); a flow no class names
//! goes to the last class.

use super::queue::{Bound, DropCause, Packet, Queue, Sub};

/// Which class each flow is in: `flows[k]` the flows of class k; others the last.
#[derive(Debug, Clone, Default)]
pub(super) struct ClassMap {
    of_flow: Vec<u16>,
    last: u16,
}

impl ClassMap {
    pub(super) fn new(classes: &[Vec<u32>]) -> ClassMap {
        let last = classes.len().saturating_sub(1) as u16;
        let top = classes
            .iter()
            .flatten()
            .max()
            .map_or(0, |m| *m as usize + 1);
        let mut of_flow = vec![last; top];
        // The first class naming a flow has it.
        for (k, flows) in classes.iter().enumerate().rev() {
            for &f in flows {
                of_flow[f as usize] = k as u16;
            }
        }
        ClassMap { of_flow, last }
    }

    pub(super) fn class(&self, flow: u32) -> usize {
        usize::from(
            self.of_flow
                .get(flow as usize)
                .copied()
                .unwrap_or(self.last),
        )
    }
}

/// One class of a scheduler: the flows it takes, its bound.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ClassSpec {
    /// The flows it takes.
    pub flows: Vec<u32>,
    /// Its bound (none: only the link's cap).
    pub bound: Bound,
    /// Its weight (a weighted scheduler's share; strict priority ignores it).
    pub weight: u32,
}

/// Strict priority: class 0 first.
#[derive(Debug)]
pub struct Priority {
    map: ClassMap,
    classes: Vec<(Sub, Bound)>,
    packets: usize,
    bytes: u64,
}

impl Priority {
    /// Strict priority between `classes`, the first the highest (at least one).
    pub fn new(classes: &[ClassSpec]) -> Priority {
        let flows: Vec<Vec<u32>> = classes.iter().map(|c| c.flows.clone()).collect();
        let mut subs: Vec<(Sub, Bound)> =
            classes.iter().map(|c| (Sub::default(), c.bound)).collect();
        if subs.is_empty() {
            subs.push((Sub::default(), Bound::default()));
        }
        Priority {
            map: ClassMap::new(&flows),
            classes: subs,
            packets: 0,
            bytes: 0,
        }
    }
}

impl Queue for Priority {
    fn enqueue(&mut self, p: Packet, drops: &mut Vec<(Packet, DropCause)>) {
        let (q, bound) = &mut self.classes[self.map.class(p.flow)];
        let n = q.q.len();
        q.push_bounded(p, *bound, drops);
        if q.q.len() > n {
            self.packets += 1;
            self.bytes += u64::from(p.bytes);
        }
    }

    fn dequeue(&mut self, _now_ns: u64, _drops: &mut Vec<(Packet, DropCause)>) -> Option<Packet> {
        let p = self.classes.iter_mut().find_map(|(q, _)| q.pop())?;
        self.packets -= 1;
        self.bytes -= u64::from(p.bytes);
        Some(p)
    }

    fn len_packets(&self) -> usize {
        self.packets
    }

    fn len_bytes(&self) -> u64 {
        self.bytes
    }
}
