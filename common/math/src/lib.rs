//! The paper's math, pure: device geometry, the kernels (FK, IK, Jacobian, KFF, FBF)
//! written once over three arithmetics, the bit-accurate CORDIC model of the FPGA's
//! trigonometric block, the engine that picks an arithmetic at run time, and the
//! paper's validation run. Nothing here performs I/O or links a transport, so the
//! math builds, tests and benchmarks on its own and can be reused anywhere.
//!
//! The README follows; its examples run as doctests.
#![doc = include_str!("../README.md")]

pub mod arith;
pub mod cordic;
pub mod engine;
pub mod geometry;
pub mod hardware;
pub mod joints;
pub mod kernels;
pub mod shown;
pub mod validation;
pub mod vec3;
