//! The slave side of the loop (the paper's HSD, SD and ENV): the simulated arm's
//! controller and joint dynamics ([`arm`]), its environment ([`environment`]), the HSD
//! kernels as a pure state machine ([`hsd`]), any arm from its URDF in place of the
//! paper's ([`urdf_arm`]), what the slave does with each sample the
//! loop's driver hands it ([`handler`]), the arm's URDF read once and the real robot
//! and live view it opens for its driver ([`peripherals`]), and its program
//! ([`node`]). The same handler
//! runs in the `tactile-slave` program and in the in-process simulation.

pub mod arm;
pub mod environment;
pub mod handler;
pub mod hsd;
pub mod node;
pub mod peripherals;
pub mod urdf_arm;
