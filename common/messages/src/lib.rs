//! What crosses a link between Tactile's nodes: the forward and backward samples with
//! their provenance, stages and flags, laid out for iceoryx2's zero-copy shared memory
//! (this is the one crate that derives iceoryx2's types); what each end of a stream
//! counts; the three roles; and the monotonic clock every stamp is read from.

pub mod clock;
pub mod flags;
pub mod role;
pub mod samples;
pub mod stream;

pub use role::Role;
