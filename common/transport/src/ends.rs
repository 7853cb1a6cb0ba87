//! What a node asks of a stream's two ends, whatever carries it: a publisher that
//! stamps and counts what it sends, a subscriber that counts what it takes and what
//! it refuses, and the wait on a transport until something may have come. The loop's
//! driver (in `tactile-runtime`) composes a node's ends; the transports implement them.

use std::time::Instant;
use tactile_messages::stream::{InboxStats, OutboxStats};

/// A link failure (iceoryx2, UDP, Zenoh), with what was being done.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{context}: {detail}")]
pub struct LinkError {
    /// What was being done.
    pub context: String,
    /// The transport's description.
    pub detail: String,
}

impl LinkError {
    /// The error of `context`, from anything that says why.
    pub fn new(context: &str, e: impl std::fmt::Display) -> LinkError {
        LinkError {
            context: context.to_string(),
            detail: e.to_string(),
        }
    }
}

/// The sending end of a stream.
pub trait Publish<T> {
    /// Publishes a copy of `value`, stamped with this hop's publish counter and
    /// counted, or, with `control` (a start-up probe, the end of a run), marked so
    /// neither end counts it. By reference: a sample is hundreds of bytes, and the
    /// in-memory queue copies it once, into its slot (the other transports copy it to
    /// stamp it, then into shared memory or an encoding).
    fn publish(&mut self, value: &T, control: bool) -> Result<(), LinkError>;
    /// What it counted.
    fn stats(&self) -> OutboxStats;
}

/// The receiving end of a stream.
pub trait Subscribe<T> {
    /// A sample if one waits, counted (with any lost before it); what is not a whole
    /// sample of this run's format is counted and passed over.
    fn try_recv(&mut self) -> Result<Option<T>, LinkError>;
    /// [`Self::try_recv`] into `slot`: true if a sample came (then it is in `slot`),
    /// false if none (`slot` is left as it was). The in-process runner polls this
    /// way, so a sample is copied once, from the queue to where it is handled, not
    /// out through each `Option` and `Result` in between.
    fn recv_into(&mut self, slot: &mut T) -> Result<bool, LinkError> {
        match self.try_recv()? {
            Some(v) => {
                *slot = v;
                Ok(true)
            }
            None => Ok(false),
        }
    }
    /// False when nothing can be waiting (a queue in memory that is empty), so a poll
    /// skips [`Self::try_recv`] (or [`Self::recv_into`]): in one process the loop
    /// polls its empty inputs ten times a sample, and each miss would still copy a
    /// whole sample's slot.
    fn may_have(&self) -> bool {
        true
    }
    /// What it counted.
    fn stats(&self) -> InboxStats;
}

/// How a node waits on one transport until a sample may have come for one of its
/// subscribers there.
pub trait Wake {
    /// Blocks until something may have arrived, or `until`; it may return early.
    fn block(&self, until: Instant) -> Result<(), LinkError>;
}
