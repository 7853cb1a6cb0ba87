//! The Tactile launcher as a library: the `tactile` binary is a thin wrapper around
//! [`cli::main`], so every subcommand can also be driven in-process.
//!
//! The README follows; its Rust examples run as doctests.
#![doc = include_str!("../../README.md")]

pub mod bench_cmd;
pub mod cli;
pub mod error;
pub mod join;
pub mod kernels_cmd;
pub mod metrics;
pub mod netns;
pub mod nodes;
pub mod paper_cmd;
pub mod plots;
pub mod report;
pub mod report_cmd;
pub mod run_cmd;
pub mod sim;
pub mod stalls;
pub mod summary;
pub mod sweep_cmd;
