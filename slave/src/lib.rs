//! The slave side of the loop (the paper's HSD, SD and ENV), as a library so the same
//! code runs in the `tactile-slave` program and in the in-process simulation.

pub mod device;
pub mod environment;
pub mod hsd;
pub mod live;
pub mod node;
pub mod outside;
pub mod process;
pub mod record;
