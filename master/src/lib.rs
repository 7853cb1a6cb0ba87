//! The master side of the loop (the paper's OP, MD and HMD): the operator's hand and
//! its trajectories ([`operator`], [`trajectory`]), the person holding it ([`human`]), the simulated master device
//! ([`simulated`]), the HMD kernels as a pure state machine ([`hmd`]), what the master
//! does with each sample the loop's driver hands it ([`handler`]), the real device and
//! live view it opens for its driver ([`peripherals`]), and its program ([`node`]). The same handler runs in the `tactile-master` program and in the
//! in-process simulation.

pub mod handler;
pub mod hmd;
pub mod human;
pub mod node;
pub mod operator;
pub mod peripherals;
pub mod simulated;
pub mod trajectory;
pub mod trajectory_rows;
