//! The master's live view: what one sample was, as ROS 2 messages (the recording's
//! topics, `tactile_ros::topics`, from the master's side).

use crate::record::{Answer, Sent};
use tactile_ros::live::LiveState;
use tactile_ros::msg::{
    Header, JointState, Message, PoseStamped, SampleTiming, WrenchStamped, IDENTITY,
};

/// One sample as the master saw it.
#[derive(Debug, Clone, Copy)]
pub struct MasterLive {
    /// What went out.
    pub sent: Sent,
    /// What came back, if it did.
    pub answer: Option<Answer>,
    /// The torques commanded, N m.
    pub tau: [f64; 3],
    /// The force the operator feels, N.
    pub felt: [f64; 3],
}

const BASE: &str = "master_base";

fn pose(stamp: u64, p: [f64; 3]) -> Vec<u8> {
    PoseStamped {
        header: Header::at(stamp, BASE),
        position: p,
        orientation: IDENTITY,
    }
    .to_cdr()
}

fn wrench(stamp: u64, f: [f64; 3]) -> Vec<u8> {
    WrenchStamped {
        header: Header::at(stamp, BASE),
        force: f,
        torque: [0.0; 3],
    }
    .to_cdr()
}

impl LiveState for MasterLive {
    const TOPICS: &'static [(&'static str, &'static str)] = &[
        ("/master/joint_states", JointState::TYPE),
        ("/master/target", PoseStamped::TYPE),
        ("/master/handle", PoseStamped::TYPE),
        ("/master/force", WrenchStamped::TYPE),
        ("/master/felt", WrenchStamped::TYPE),
        ("/tactile/timing", SampleTiming::TYPE),
    ];

    fn encode(&self, stamp: u64) -> Vec<Vec<u8>> {
        let s = &self.sent;
        let joints = JointState {
            header: Header::at(stamp, ""),
            name: tactile_ros::arm::joint_names("master"),
            position: s.theta_md.to_vec(),
            velocity: Vec::new(),
            effort: self.tau.to_vec(),
        };
        let q = self.answer.map_or([0.0; 3], |a| a.q.value);
        let timing = SampleTiming {
            sample: s.n,
            answered: self.answer.is_some(),
            round_trip_ns: self.answer.map_or(0, |a| a.round_trip_ns as i64),
            overhead_ns: self.answer.map_or(0, |a| a.overhead_ns),
            delay_backward: self.answer.map_or([0; 3], |a| a.q.delay_samples),
            flags_backward: self.answer.map_or(0, |a| a.q.flags),
            flags_master: self.answer.map_or(0, |a| a.flags),
            observer_master: self.answer.map_or([0.0; 3], |a| a.observer),
            ..SampleTiming::default()
        };
        vec![
            joints.to_cdr(),
            pose(stamp, s.target),
            pose(stamp, s.handle),
            wrench(stamp, q),
            wrench(stamp, self.felt),
            timing.to_cdr(),
        ]
    }
}
