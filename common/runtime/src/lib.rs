//! The process runtime of Tactile's node programs: the loop's driver ([`driver`]:
//! pacing, the run's protocol, every wait, counters, stop requests, the record's
//! lifecycle, the live view), a node program from its checks to its exit
//! ([`program`], [`start`]), whether it needs ROS 2 ([`outside`]), the command line
//! and exit statuses ([`args`], [`exit`]), and what it asks of the operating system:
//! pacing ([`pace`]), scheduling ([`sched`]), locks that keep runs apart ([`lock`]),
//! stop requests ([`signals`]), the log ([`logging`]), the files a user names
//! ([`files`]). The links are `tactile-transport`'s, the records `tactile-records`';
//! a node's device, robot and live view are the node's own, opened by it and driven
//! here through `tactile-peripheral`'s traits (the runtime knows no arm or gimbal);
//! what each node does with a sample is its own crate's.

pub mod args;
pub mod driver;
pub mod exit;
pub mod files;
pub mod lock;
pub mod logging;
pub mod outside;
pub mod pace;
pub mod program;
pub mod sched;
pub mod signals;
pub mod start;
mod sys;
