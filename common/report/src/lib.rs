//! The report of a run as a library, so a notebook, a script or another tool can do
//! what `tactile report` does: [`join`] streams the nodes' records (one host's folder
//! or several) and joins them by sequence number into [`trace::TraceRow`]s;
//! [`analysis`] and [`metrics`] fold the rows into latency histograms and the loop's
//! figures, [`task_space`] a URDF arm's in its base frame; [`summary`] says it in JSON and [`text`] on the terminal; [`plots`] draws it; [`run_mcap`]
//! writes it as ROS 2 messages in MCAP ([`mcap`]) for the robotics viewers, a URDF slave drawn as [`arm_scene`] says; [`write`]
//! puts the report's files in a folder ([`out`]: one process at a time, each file whole); [`sweep`] tabulates many runs' summaries; [`lerobot`] writes runs and sweeps as a LeRobot v3.0 dataset for robot learning.

pub mod analysis;
pub mod arm_scene;
pub mod bodies;
pub mod body_scene;
pub mod columns;
pub mod error;
pub mod figures;
pub mod hardware;
pub mod join;
pub mod joints;
pub mod lerobot;
pub mod mcap;
pub mod metrics;
mod node_log;
pub mod ours;
pub mod out;
pub mod parquet_trace;
pub mod plots;
pub mod run_mcap;
mod source;
mod streams;
pub mod summary;
pub mod sweep;
pub mod sweep_grid;
pub mod sweep_map;
pub mod sweep_plots;
pub mod task;
pub mod task_space;
pub mod text;
pub mod trace;
pub mod transparency;
pub mod warnings;
pub mod write;

pub use error::Error;
