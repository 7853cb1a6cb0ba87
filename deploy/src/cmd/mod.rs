//! One module per `tactile` subcommand, each owning its arguments and its `main`.

pub mod bench;
pub mod check;
pub mod datapath;
pub mod export;
pub mod formats;
pub mod fuzz;
pub mod hdl;
pub mod kernels;
pub mod node_options;
pub mod paper;
pub mod report;
pub mod run;
pub mod sweep;
