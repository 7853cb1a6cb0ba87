//! What every Tactile node program shares, and the only place that touches the world:
//! the links between nodes (traits, iceoryx2 shared memory, UDP), each node's record,
//! its log, the locks that keep runs apart, and the command line of the three node
//! programs. The loops themselves are in the master, emulator and slave crates.

pub mod args;
pub mod device;
pub mod exit;
pub mod files;
pub mod frames;
pub mod held;
pub mod ipc;
pub mod link;
#[cfg(feature = "zenoh")]
pub mod live;
pub mod lock;
pub mod logging;
pub mod open;
pub mod pace;
pub mod record;
pub mod recorder;
#[cfg(feature = "zenoh")]
pub mod ros2;
#[cfg(feature = "zenoh")]
pub mod ros2_devices;
pub mod runtime;
pub mod sched;
pub mod signals;
mod sys;
pub mod udp;
pub mod wire;
#[cfg(feature = "zenoh")]
mod zconfig;
#[cfg(feature = "zenoh")]
pub mod zlink;
