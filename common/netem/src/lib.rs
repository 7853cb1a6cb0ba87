//! The network between the master and the slave, as the emulator runs it: netem-class
//! models (delay jitter with correlation, loss models, duplication) with netem's
//! meanings, recorded networks replayed packet by packet, and the channel that puts a
//! sample through them. Seeded and pure: the same scenario and seed give the same
//! packets. Only the emulator links this crate; the settings are `tactile-scenario`'s.

pub mod channel;
pub mod models;

pub use models::{loss_rate, Jitter, Loss, Mahimahi, Replay};
