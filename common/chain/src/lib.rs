//! Any serial arm from its URDF: a chain from a base link to a tip link (revolute and
//! prismatic joints, fixed joints folded, mimic joints followed), its forward
//! kinematics and geometric Jacobian, a damped least-squares IK with joint and
//! velocity limits and a null-space posture term, and its rigid-body dynamics (the
//! recursive Newton-Euler and articulated-body algorithms). Pure math, but for one
//! function: [`file::read`], the one reading of a URDF file (a size cap, the file
//! named in every error), which every reader of an arm goes through.
//!
//! Vectors follow Pinocchio's order (`[linear; angular]`), so every figure compares
//! with it entry by entry; the tests do (tests/chain.rs of the workspace, against
//! `pin` on eight arms of example-robot-data: the Panda, the UR3, UR5 and UR10, the
//! xArm7, the Jaco2, the Z1 and the SO-101).
//!
//! The README follows; its examples run as doctests.
#![doc = include_str!("../README.md")]

pub mod chain;
pub mod dynamics;
mod error;
pub mod file;
pub mod ik;
pub mod kinematics;
pub mod matmul;
pub mod spatial;
pub mod topology;
pub mod tree;
pub mod urdf;

pub use chain::{Chain, Dof};
pub use dynamics::Dynamics;
pub use error::Error;
pub use file::{UrdfFile, MAX_URDF_BYTES};
pub use ik::{Ik, IkConfig, IkStats, IkStep, Pose};
pub use spatial::Frame;
pub use tree::Tree;
pub use urdf::Robot;
