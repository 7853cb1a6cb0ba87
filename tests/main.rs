//! The workspace's integration tests, as one test binary. Each module is one subject;
//! one binary means one link of the whole stack (Zenoh included) instead of one per
//! subject, which kept CI's disk and time in bounds. Every test makes its own temp
//! folder, iceoryx2 prefix, ports and namespaces (util), so they run in parallel.
//! Run one subject with `cargo test --all-features --test main faults::`.

mod util;

mod arm;
mod bad_input;
mod bench;
mod bilateral;
mod bodies;
mod chain;
mod channels;
mod cli;
mod crafted;
mod dependencies;
mod docs_tables;
mod faults;
mod formats;
mod hand;
mod hdl;
mod hdl_modules;
mod histograms;
mod hosts;
mod human;
mod layout;
mod lerobot;
mod lifecycle;
mod links;
mod logs;
mod loop_processes;
mod nodes;
mod physics;
mod pose;
mod recordings;
mod records;
mod ros2;
mod ros2_inputs;
mod ros2_tls;
mod scheduling;
mod signals;
mod slurm;
mod summaries;
mod sweep;
mod task_space;
mod trajectories;
