//! The network emulator (the paper's NW subsystem): both channels as pure logic
//! ([`emulator`]), the recorded networks it replays ([`replay`]) and the delay
//! histograms it draws from ([`histogram`]), what it does with
//! each sample the loop's driver hands it ([`handler`]), and its program ([`node`]).
//! The same handler runs in the `tactile-emulator` program and in the in-process
//! simulation.

pub mod emulator;
pub mod handler;
pub mod histogram;
pub mod node;
pub mod replay;
