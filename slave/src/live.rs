//! The slave's live view: one step as ROS 2 messages (the recording's topics,
//! `tactile_ros::topics`, from the slave's side).

use crate::record::Step;
use tactile_ros::live::LiveState;
use tactile_ros::msg::{Header, JointState, Message, PoseStamped, WrenchStamped, IDENTITY};

/// One step as the slave took it.
#[derive(Debug, Clone, Copy)]
pub struct SlaveLive {
    /// The step.
    pub step: Step,
}

const BASE: &str = "slave_base";

impl LiveState for SlaveLive {
    const TOPICS: &'static [(&'static str, &'static str)] = &[
        ("/slave/joint_states", JointState::TYPE),
        ("/slave/tool", PoseStamped::TYPE),
        ("/slave/force", WrenchStamped::TYPE),
    ];

    fn encode(&self, stamp: u64) -> Vec<Vec<u8>> {
        let s = &self.step;
        let joints = JointState {
            header: Header::at(stamp, ""),
            name: tactile_ros::arm::joint_names("slave"),
            position: s.theta.to_vec(),
            velocity: Vec::new(),
            effort: s.torque.to_vec(),
        };
        let tool = PoseStamped {
            header: Header::at(stamp, BASE),
            position: s.tool,
            orientation: IDENTITY,
        };
        let force = WrenchStamped {
            header: Header::at(stamp, BASE),
            force: s.force,
            torque: [0.0; 3],
        };
        vec![joints.to_cdr(), tool.to_cdr(), force.to_cdr()]
    }
}
