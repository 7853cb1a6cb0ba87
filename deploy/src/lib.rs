//! The `tactile` command as a library: the binary is a thin wrapper around
//! [`cli::main`], so every subcommand can also be driven in-process. [`cmd`] holds one
//! module per subcommand, each owning its arguments; [`launch`] starts and supervises
//! runs (the node programs, or the loop in this process); the report itself is the
//! `tactile-report` crate.
#![doc = include_str!("../../README.md")]

pub mod cli;
pub mod cmd;
pub mod error;
pub mod launch;
