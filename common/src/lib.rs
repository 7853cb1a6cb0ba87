//! Pure code shared by every Tactile process: device geometry, the paper's kernels in
//! three arithmetics, the CORDIC model of the FPGA's trigonometric block, and the
//! statistics used by reports. Nothing here performs I/O, so every function can be
//! called from a process, a test or a benchmark alike; the edges (links, records,
//! logging) are in `tactile-node`.

pub mod arith;
pub mod bilateral;
pub mod channel;
pub mod clock;
pub mod codec;
pub mod control;
pub mod cordic;
pub mod csv;
pub mod engine;
pub mod geometry;
pub mod kernels;
pub mod netem;
pub mod overrides;
pub mod samples;
pub mod scenario;
pub mod trace;
pub mod validation;
pub mod vec3;
