//! The slave side of the loop (the paper's HSD, SD and ENV): the slave's arm as one
//! trait ([`slave_arm`]) that the paper's arm ([`paper_arm`]: its controller and joint
//! dynamics in [`arm`]) and any arm from its URDF ([`urdf_arm`]) implement, its
//! environment: the analytic scene ([`environment`]) or a physics world, as the arm
//! touches either ([`world`]), the step as a pure state machine ([`hsd`]), what the slave does with each sample the
//! loop's driver hands it ([`handler`]), the arm's URDF read once and the real robot
//! and live view it opens for its driver ([`peripherals`]), and its program
//! ([`node`]). The same handler
//! runs in the `tactile-slave` program and in the in-process simulation.

pub mod arm;
pub mod environment;
pub mod handler;
pub mod hsd;
pub mod node;
pub mod paper_arm;
pub mod peripherals;
pub mod slave_arm;
pub mod urdf_arm;
pub mod world;
