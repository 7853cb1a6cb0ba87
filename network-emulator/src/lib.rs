//! The network emulator (the paper's NW subsystem), as a library so the same code runs
//! in the `tactile-emulator` program and in the in-process simulation.

pub mod emulator;
pub mod node;
pub mod process;
pub mod replay;
