//! What a node publishes in the live view: a state type that names its topics and
//! encodes itself, one CDR message per topic. The loop hands the state over; a
//! publisher thread encodes and sends it, so the loop never waits on the network.

/// A node's state as the live view publishes it.
pub trait LiveState: Send + 'static {
    /// `(topic, type)` of each message, relative to the node's namespace.
    const TOPICS: &'static [(&'static str, &'static str)];
    /// One CDR message per topic, in [`Self::TOPICS`]' order, stamped `stamp_ns` (ns
    /// since the Unix epoch).
    fn encode(&self, stamp_ns: u64) -> Vec<Vec<u8>>;
}
