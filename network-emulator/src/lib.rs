//! The network emulator (the paper's NW subsystem), as a library so the same code runs
//! in the `tactile emulator` process and in the in-process simulation.

pub mod emulator;
pub mod process;
