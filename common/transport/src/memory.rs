//! The in-process transport: a stream as a queue in memory, for the loop run in one
//! process (`tactile run --in-process`, sweeps). Its ends stamp and count exactly as
//! the other transports' do, so a node's record reads the same; nothing is ever lost
//! on it and it never blocks: the in-process runner steps each node while another
//! waits.

use crate::ends::{LinkError, Publish, Subscribe};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;
use tactile_messages::samples::Sequenced;
use tactile_messages::stream::{InboxStats, OutboxStats};

type Queue<T> = Rc<RefCell<VecDeque<T>>>;

/// Sending end of an in-memory stream.
#[derive(Debug)]
pub struct MemoryPublisher<T> {
    queue: Queue<T>,
    stats: OutboxStats,
}

/// Receiving end of an in-memory stream.
#[derive(Debug)]
pub struct MemorySubscriber<T> {
    queue: Queue<T>,
    stats: InboxStats,
    next: Option<u64>,
}

/// A stream in memory: its two ends.
pub fn stream<T>() -> (MemoryPublisher<T>, MemorySubscriber<T>) {
    let queue: Queue<T> = Rc::new(RefCell::new(VecDeque::new()));
    (
        MemoryPublisher {
            queue: Rc::clone(&queue),
            stats: OutboxStats::default(),
        },
        MemorySubscriber {
            queue,
            stats: InboxStats::default(),
            next: None,
        },
    )
}

impl<T: Sequenced + Clone> Publish<T> for MemoryPublisher<T> {
    fn publish(&mut self, value: &T, control: bool) -> Result<(), LinkError> {
        let mut queue = self.queue.borrow_mut();
        queue.push_back(value.clone());
        // Always there: it was just pushed.
        if let Some(v) = queue.back_mut() {
            self.stats.stamp(v, control);
        }
        self.stats.count(1, control);
        Ok(())
    }

    fn stats(&self) -> OutboxStats {
        self.stats
    }
}

impl<T: Sequenced + Clone> Subscribe<T> for MemorySubscriber<T> {
    fn try_recv(&mut self) -> Result<Option<T>, LinkError> {
        let got = self.queue.borrow_mut().pop_front();
        if let Some(v) = &got {
            self.stats.count(v, &mut self.next);
        }
        Ok(got)
    }

    fn recv_into(&mut self, slot: &mut T) -> Result<bool, LinkError> {
        let mut queue = self.queue.borrow_mut();
        let Some(v) = queue.front() else {
            return Ok(false);
        };
        slot.clone_from(v);
        queue.pop_front();
        self.stats.count(slot, &mut self.next);
        Ok(true)
    }

    fn may_have(&self) -> bool {
        !self.queue.borrow().is_empty()
    }

    fn stats(&self) -> InboxStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_messages::samples::Forward;

    #[test]
    fn samples_come_out_in_order_counted_and_control_ones_uncounted() {
        let (mut tx, mut rx) = stream::<Forward>();
        for (seq, control) in [(0, false), (1, true), (2, false)] {
            tx.publish(
                &Forward {
                    seq,
                    ..Forward::default()
                },
                control,
            )
            .expect("publish");
        }
        let got: Vec<u64> = std::iter::from_fn(|| rx.try_recv().expect("recv"))
            .map(|f| f.seq)
            .collect();
        assert_eq!(got, [0, 1, 2]);
        assert_eq!(tx.stats().published, 2);
        assert_eq!((rx.stats().received, rx.stats().overwritten), (2, 0));
    }

    #[test]
    fn receiving_into_a_slot_takes_and_counts_as_try_recv_does() {
        let (mut tx, mut rx) = stream::<Forward>();
        let mut slot = Forward {
            seq: 99,
            ..Forward::default()
        };
        assert!(!rx.recv_into(&mut slot).expect("recv"));
        assert_eq!(slot.seq, 99, "an empty stream leaves the slot as it was");
        for (seq, control) in [(0, false), (1, true), (2, false)] {
            let f = Forward {
                seq,
                ..Forward::default()
            };
            tx.publish(&f, control).expect("publish");
        }
        let mut got = Vec::new();
        while rx.recv_into(&mut slot).expect("recv") {
            got.push(slot.seq);
        }
        assert_eq!(got, [0, 1, 2]);
        assert_eq!((rx.stats().received, rx.stats().overwritten), (2, 0));
    }
}
