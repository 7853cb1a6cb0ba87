//! ROS 2 messages as Tactile publishes and records them, described once: the CDR
//! encoding (XCDR1, little endian, what rmw implementations and rosbag2 use), each
//! message type with its ros2msg schema, the topics and frames a run is seen through,
//! the arms' URDF and their link transforms from the paper's kinematics, and a sample
//! as messages on typed topics ([`view`]). Recordings (`run.mcap`) and the live view
//! use these, so a recording and a live run look the same to a viewer. Pure: no I/O.

pub mod arm;
pub mod cdr;
pub mod hand_msg;
pub mod msg;
pub mod rmw;
pub mod schema;
pub mod topics;
pub mod urdf;
pub mod view;

pub use cdr::{CdrError, CdrReader, CdrWriter};
pub use msg::{Decode, Message};
