//! What each end of a stream counts: the sending end its publishes, the receiving end
//! what it took, what it lost in between and what it refused. Every transport stamps
//! and counts the same way, through these, so a node's record reads alike whatever
//! carried its samples.
//!
//! A sending end stamps each sample with its own publish counter (`hop_seq`); the
//! receiving end sees a gap in the counter as samples lost on the hop and a counter
//! that starts again as a restarted sender. Control samples (a start-up probe, the end
//! of a run) carry [`CONTROL_HOP_SEQ`] and are counted by neither end.

use crate::samples::Sequenced;
use serde::{Deserialize, Serialize};

/// `hop_seq` of control samples, which no counter sees.
pub const CONTROL_HOP_SEQ: u64 = u64::MAX;

/// What a sending end counted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct OutboxStats {
    /// Samples published.
    pub published: u64,
    /// Published while no subscriber was connected (the receiver was dead): lost.
    pub no_receiver: u64,
}

/// What a receiving end counted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct InboxStats {
    /// Samples taken.
    pub received: u64,
    /// Samples overwritten in the full buffer before they were taken (gaps in the
    /// publisher's counter; the buffer's overflow policy is safe overflow).
    pub overwritten: u64,
    /// Times the publisher's counter started again (the sender was restarted).
    pub publisher_restarts: u64,
    /// Payloads that were not a whole sample (garbage, truncated), dropped.
    #[serde(default)]
    pub malformed: u64,
    /// Samples of another run (a different run token), dropped.
    #[serde(default)]
    pub foreign: u64,
    /// Frames of another wire-format version (another build), dropped.
    #[serde(default)]
    pub wrong_version: u64,
}

impl OutboxStats {
    /// Stamps `value` with this hop's next publish counter (or the control marker).
    pub fn stamp<T: Sequenced>(&mut self, value: &mut T, control: bool) {
        if control {
            value.set_hop_seq(CONTROL_HOP_SEQ);
        } else {
            value.set_hop_seq(self.published);
        }
    }

    /// Counts a publish of a counted sample that reached `receivers` subscribers.
    pub fn count(&mut self, receivers: usize, control: bool) {
        if !control {
            self.published += 1;
            if receivers == 0 {
                self.no_receiver += 1;
            }
        }
    }
}

impl InboxStats {
    /// Counts a received sample and any overwritten before it; `next` is the publish
    /// counter expected next from this stream's sender.
    pub fn count<T: Sequenced>(&mut self, value: &T, next: &mut Option<u64>) {
        let h = value.hop_seq();
        if h == CONTROL_HOP_SEQ {
            return;
        }
        self.received += 1;
        match *next {
            Some(n) if h >= n => self.overwritten += h - n,
            Some(_) => self.publisher_restarts += 1,
            None => {}
        }
        *next = Some(h + 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samples::Forward;

    #[test]
    fn gaps_restarts_and_control_samples_are_told_apart() {
        let mut out = OutboxStats::default();
        let mut inn = InboxStats::default();
        let mut next = None;
        let mut sent = Vec::new();
        for control in [false, false, true, false, false] {
            let mut f = Forward::default();
            out.stamp(&mut f, control);
            out.count(1, control);
            sent.push(f);
        }
        assert_eq!(out.published, 4);
        // The third counted sample is lost on the hop.
        for f in [sent[0], sent[1], sent[2], sent[4]] {
            inn.count(&f, &mut next);
        }
        assert_eq!((inn.received, inn.overwritten), (3, 1));
        // A restarted sender counts from zero again.
        inn.count(&sent[0], &mut next);
        assert_eq!(inn.publisher_restarts, 1);
    }
}
