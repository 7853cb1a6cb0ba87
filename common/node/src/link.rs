//! What each process needs from its transport, as one trait per role.
//!
//! The process loops (in the master, emulator and slave crates) are written against
//! these traits, so the same loop runs over iceoryx2 shared memory (the product,
//! `ipc`), UDP (the reference a user would pick instead, measured beside it by
//! `tactile bench`) or Zenoh (across hosts). This module owns what they share: the
//! error, why a wait ended, the counters; every implementation stamps the per-hop
//! publish counter and counts what it sends and receives the same way.

use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_messages::samples::{Backward, Forward, Sequenced};
use thiserror::Error;

/// How a process waits for its next sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WaitPolicy {
    /// Busy-poll this long before blocking on the wake-up event.
    pub spin: Duration,
}

/// A link failure (iceoryx2, UDP, Zenoh), with what was being done.
#[derive(Debug, Error)]
#[error("{context}: {detail}")]
pub struct LinkError {
    /// What was being done.
    pub context: String,
    /// The transport's description.
    pub detail: String,
}

/// Why a wait returned without a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Idle {
    /// The deadline passed.
    Timeout,
    /// SIGINT or SIGTERM arrived.
    Terminate,
}

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

/// The outcome of a wait: a value, or why none came.
pub type Wait<T> = Result<Result<T, Idle>, LinkError>;

/// The master's view: c(n) out, q(n) in.
pub trait MasterLink {
    /// Publishes c(n).
    fn send(&self, c: Forward) -> Result<(), LinkError>;
    /// Publishes a control sample (probe, end of run), uncounted.
    fn send_control(&self, c: Forward) -> Result<(), LinkError>;
    /// Waits for the next q until `deadline`.
    fn recv(&self, deadline: Instant) -> Wait<Backward>;
    /// Names of peers known to have died (and cleans up after them).
    fn dead_peers(&self) -> Vec<String>;
    /// What c-out and q-in counted.
    fn stats(&self) -> (OutboxStats, InboxStats);
}

/// A sample arriving at the emulator.
// Lives on the stack for one sample; boxing the larger variant would allocate per sample.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
pub enum Arrival {
    /// c(n) from the master.
    Forward(Forward),
    /// h(n) from the slave.
    Backward(Backward),
}

/// What the emulator's four stream ends counted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EmulatorStats {
    /// c(n) received.
    pub c_in: InboxStats,
    /// v(n) published.
    pub v_out: OutboxStats,
    /// h(n) received.
    pub h_in: InboxStats,
    /// q(n) published.
    pub q_out: OutboxStats,
}

/// The emulator's view: c and h in, v and q out.
pub trait EmulatorLink {
    /// Waits for the next c or h until `deadline` (h first when both wait).
    fn recv(&self, deadline: Instant) -> Wait<Arrival>;
    /// Publishes v(n); `control` leaves it uncounted.
    fn send_v(&self, v: Forward, control: bool) -> Result<(), LinkError>;
    /// Publishes q(n); `control` leaves it uncounted.
    fn send_q(&self, q: Backward, control: bool) -> Result<(), LinkError>;
    /// What the four ends counted.
    fn stats(&self) -> EmulatorStats;
}

/// The slave's view: v(n) in, h(n) out.
pub trait SlaveLink {
    /// Waits for the next v until `deadline`.
    fn recv(&self, deadline: Instant) -> Wait<Forward>;
    /// Publishes h(n); `control` leaves it uncounted.
    fn send_h(&self, h: Backward, control: bool) -> Result<(), LinkError>;
    /// What v-in and h-out counted.
    fn stats(&self) -> (InboxStats, OutboxStats);
}

/// `hop_seq` of control samples, which no counter sees.
pub const CONTROL_HOP_SEQ: u64 = u64::MAX;

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
