//! The network between the master and the slave, as the emulator runs it: netem-class
//! models (delay [`jitter`] with correlation, [`loss`] models, duplication) with
//! netem's meanings, delays drawn from measured [`histogram`]s, recorded networks
//! [`replay`]ed packet by packet, a [`link`] with a rate and a queue (Mahimahi's
//! `mm-link` exactly), and the
//! [`channel`] that puts a sample through them. Seeded and pure: the same scenario and
//! seed give the same packets. Only the emulator links this crate; the settings are
//! `tactile-scenario`'s.
//!
//! Where netem's own implementation is known to be wrong we keep its meaning and not
//! its flaw: see [`jitter`].

pub mod channel;
pub mod histogram;
pub mod jitter;
pub mod link;
pub mod loss;
pub mod replay;
#[cfg(test)]
mod tests;

pub use histogram::{DelayHistogram, HistogramDelay, HistogramError};
pub use jitter::Jitter;
pub use loss::{loss_rate, Loss};
pub use replay::{LinkSpec, Replay, ReplayError};
