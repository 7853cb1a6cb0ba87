//! The master side of the loop (the paper's OP, MD and HMD), as a library so the same
//! code runs in the `tactile-master` program and in the in-process simulation.

pub mod device;
pub mod hmd;
pub mod live;
pub mod node;
pub mod operator;
pub mod outside;
pub mod process;
pub mod record;
pub mod trajectory;
