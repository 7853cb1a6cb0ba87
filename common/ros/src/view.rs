//! A sample as ROS 2 messages, described once: the recording (`run.mcap`) and the live
//! view both map what a node did to messages here, on typed topics, so a message can
//! only go to a topic of its type and a recording and a live run look the same to a
//! viewer.

use crate::msg::{
    Header, JointState, Message, PoseStamped, SampleTiming, StringMsg, TfMessage, WrenchStamped,
    IDENTITY,
};
use crate::topics::{Topic, TOPICS};
use std::marker::PhantomData;
use tactile_math::joints::Joints;

/// A topic of [`TOPICS`] whose messages are `M`s.
#[derive(Debug)]
pub struct Typed<M> {
    index: usize,
    _m: PhantomData<fn(M)>,
}

impl<M> Clone for Typed<M> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<M> Copy for Typed<M> {}

const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

impl<M: Message> Typed<M> {
    /// Topic `index` of [`TOPICS`]; refused at compile time unless its type is `M`'s.
    const fn at(index: usize) -> Typed<M> {
        assert!(same(TOPICS[index].ty, M::TYPE), "a topic of another type");
        Typed {
            index,
            _m: PhantomData,
        }
    }

    /// Its place in [`TOPICS`]: the recording's channel, the live view's publisher.
    pub const fn index(self) -> usize {
        self.index
    }

    /// The topic.
    pub const fn topic(self) -> &'static Topic {
        &TOPICS[self.index]
    }
}

/// `/robot_description`.
pub const ROBOT_DESCRIPTION: Typed<StringMsg> = Typed::at(0);
/// `/tf_static`.
pub const TF_STATIC: Typed<TfMessage> = Typed::at(1);
/// `/tf`.
pub const TF: Typed<TfMessage> = Typed::at(2);
/// `/master/joint_states`.
pub const MASTER_JOINTS: Typed<JointState> = Typed::at(3);
/// `/slave/joint_states`.
pub const SLAVE_JOINTS: Typed<JointState> = Typed::at(4);
/// `/master/target`.
pub const MASTER_TARGET: Typed<PoseStamped> = Typed::at(5);
/// `/master/handle`.
pub const MASTER_HANDLE: Typed<PoseStamped> = Typed::at(6);
/// `/slave/tool`.
pub const SLAVE_TOOL: Typed<PoseStamped> = Typed::at(7);
/// `/slave/force`.
pub const SLAVE_FORCE: Typed<WrenchStamped> = Typed::at(8);
/// `/master/force`.
pub const MASTER_FORCE: Typed<WrenchStamped> = Typed::at(9);
/// `/master/felt`.
pub const MASTER_FELT: Typed<WrenchStamped> = Typed::at(10);
/// `/slave/environment`.
pub const SLAVE_ENVIRONMENT: Typed<crate::msg::MarkerArray> = Typed::at(11);
/// `/tactile/timing`.
pub const TIMING: Typed<SampleTiming> = Typed::at(12);
/// `/slave/bodies`.
pub const SLAVE_BODIES: Typed<crate::msg::MarkerArray> = Typed::at(13);

/// The topics the master's live view publishes.
pub const MASTER_LIVE: [usize; 6] = [
    MASTER_JOINTS.index(),
    MASTER_TARGET.index(),
    MASTER_HANDLE.index(),
    MASTER_FORCE.index(),
    MASTER_FELT.index(),
    TIMING.index(),
];

/// The topics the slave's live view publishes.
pub const SLAVE_LIVE: [usize; 3] = [
    SLAVE_JOINTS.index(),
    SLAVE_TOOL.index(),
    SLAVE_FORCE.index(),
];

/// Which stage's time a message reports: its publish time in a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum At {
    /// The master's tick (what the master had then).
    MasterTick,
    /// The slave's send (what the slave did with the sample).
    SlaveSend,
    /// The master's receive (what came back).
    MasterRecv,
    /// The master done with the answer.
    MasterDone,
}

/// Where a sample's messages go.
pub trait Sink {
    /// What putting a message can fail with.
    type Error;
    /// Puts `m` on `topic`; `at` says which stage's time it reports.
    fn put<M: Message>(&mut self, topic: Typed<M>, at: At, m: &M) -> Result<(), Self::Error>;
}

/// The master's part of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MasterView {
    /// Joint angles b(n), rad.
    pub theta: [f64; 3],
    /// Joint velocities, rad/s (the recording's; the live view has none).
    pub velocity: Option<[f64; 3]>,
    /// Torques p(n), N m.
    pub tau: [f64; 3],
    /// The operator's target a(n), m.
    pub target: [f64; 3],
    /// The handle's position, m.
    pub handle: [f64; 3],
    /// The handle's (and the target's) orientation relative to the operator's home, `[x,
    /// y, z, w]`: a 6-DoF master's; the identity for the paper's.
    pub rotation: [f64; 4],
    /// q(n) as received, N (zero without an answer).
    pub q: [f64; 3],
    /// The force the operator feels, N.
    pub felt: [f64; 3],
}

/// The slave's part of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SlaveView {
    /// Joint angles, rad.
    pub theta: [f64; 3],
    /// Joint velocities, rad/s (the recording's; the live view has none).
    pub velocity: Option<[f64; 3]>,
    /// Controller torques, N m.
    pub torque: [f64; 3],
    /// The tool l(n), m.
    pub tool: [f64; 3],
    /// The contact force h(n), N.
    pub force: [f64; 3],
}

/// A URDF arm's part of a sample (the slave as any robot): its joints by their own
/// names, the tool and the force in its base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmView<'a> {
    /// The base link: the frame of the tool and the force.
    pub base: &'a str,
    /// The joints' names, as the URDF and the robot's controllers call them.
    pub names: &'a [String],
    /// Joint values, rad or m.
    pub q: &'a [f64],
    /// Joint velocities (the recording's; none in the live view).
    pub velocity: Option<&'a [f64]>,
    /// Efforts the servo applied, N m or N.
    pub effort: &'a [f64],
    /// The tool, m, in `base`.
    pub tool: [f64; 3],
    /// The contact force on the tool, N, in `base`'s axes.
    pub force: [f64; 3],
}

impl ArmView<'_> {
    /// Puts the arm's messages, as [`SampleView::emit`] puts the paper slave's.
    pub fn emit<S: Sink>(&self, stamp: u64, sink: &mut S) -> Result<(), S::Error> {
        let js = JointState {
            header: Header::at(stamp, ""),
            name: self.names.to_vec(),
            position: self.q.to_vec(),
            velocity: self.velocity.map_or_else(Vec::new, <[f64]>::to_vec),
            effort: self.effort.to_vec(),
        };
        sink.put(SLAVE_JOINTS, At::SlaveSend, &js)?;
        sink.put(
            SLAVE_TOOL,
            At::SlaveSend,
            &pose(stamp, self.base, self.tool),
        )?;
        sink.put(
            SLAVE_FORCE,
            At::SlaveSend,
            &wrench(stamp, self.base, self.force),
        )
    }
}

/// A URDF arm's part of a sample, owned (the live view hands it to its thread): what
/// [`ArmView`] borrows.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmSample {
    /// The base link.
    pub base: std::sync::Arc<str>,
    /// The joints' names.
    pub names: std::sync::Arc<[String]>,
    /// Joint values, rad or m (inline: a sample for the view allocates nothing).
    pub q: Joints,
    /// Efforts, N m or N.
    pub effort: Joints,
    /// The tool in the base frame, m.
    pub tool: [f64; 3],
    /// The contact force, N, in the base's axes.
    pub force: [f64; 3],
}

impl ArmSample {
    /// The sample as an [`ArmView`] (no velocities: the live view has none).
    pub fn view(&self) -> ArmView<'_> {
        ArmView {
            base: &self.base,
            names: &self.names,
            q: &self.q,
            velocity: None,
            effort: &self.effort,
            tool: self.tool,
            force: self.force,
        }
    }
}

/// What a sample shows, from whichever nodes saw it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SampleView {
    /// The master's part.
    pub master: Option<MasterView>,
    /// The slave's part (the paper's arm).
    pub slave: Option<SlaveView>,
    /// The slave's part when it is an arm from its URDF.
    pub arm: Option<ArmSample>,
    /// Round trip, delays, flags, observers.
    pub timing: Option<SampleTiming>,
}

fn joints(stamp: u64, arm: &str, theta: [f64; 3], v: Option<[f64; 3]>, e: [f64; 3]) -> JointState {
    JointState {
        header: Header::at(stamp, ""),
        name: crate::arm::joint_names(arm),
        position: theta.to_vec(),
        velocity: v.map_or_else(Vec::new, |v| v.to_vec()),
        effort: e.to_vec(),
    }
}

fn pose(stamp: u64, frame: &str, p: [f64; 3]) -> PoseStamped {
    PoseStamped {
        header: Header::at(stamp, frame),
        position: p,
        orientation: IDENTITY,
    }
}

fn turned(mut p: PoseStamped, rotation: [f64; 4]) -> PoseStamped {
    p.orientation = rotation;
    p
}

fn wrench(stamp: u64, frame: &str, f: [f64; 3]) -> WrenchStamped {
    WrenchStamped {
        header: Header::at(stamp, frame),
        force: f,
        torque: [0.0; 3],
    }
}

/// The master's base frame.
pub const MASTER_BASE: &str = "master_base";
/// The slave's base frame.
pub const SLAVE_BASE: &str = "slave_base";

impl SampleView {
    /// Puts the sample's messages, headers stamped `stamp` (ns since the Unix epoch in
    /// the live view, the log time in a recording), in one order: the master's and the
    /// slave's joints, then poses, forces, timing.
    pub fn emit<S: Sink>(&self, stamp: u64, sink: &mut S) -> Result<(), S::Error> {
        use At::{MasterRecv, MasterTick, SlaveSend};
        if let Some(m) = &self.master {
            let js = joints(stamp, "master", m.theta, m.velocity, m.tau);
            sink.put(MASTER_JOINTS, MasterTick, &js)?;
        }
        if let Some(s) = &self.slave {
            let js = joints(stamp, "slave", s.theta, s.velocity, s.torque);
            sink.put(SLAVE_JOINTS, SlaveSend, &js)?;
        }
        if let Some(m) = &self.master {
            sink.put(
                MASTER_TARGET,
                MasterTick,
                &turned(pose(stamp, MASTER_BASE, m.target), m.rotation),
            )?;
            sink.put(
                MASTER_HANDLE,
                MasterTick,
                &turned(pose(stamp, MASTER_BASE, m.handle), m.rotation),
            )?;
        }
        if let Some(s) = &self.slave {
            sink.put(SLAVE_TOOL, SlaveSend, &pose(stamp, SLAVE_BASE, s.tool))?;
            sink.put(SLAVE_FORCE, SlaveSend, &wrench(stamp, SLAVE_BASE, s.force))?;
        }
        if let Some(a) = &self.arm {
            a.view().emit(stamp, sink)?;
        }
        if let Some(m) = &self.master {
            sink.put(MASTER_FORCE, MasterRecv, &wrench(stamp, MASTER_BASE, m.q))?;
            sink.put(MASTER_FELT, MasterRecv, &wrench(stamp, MASTER_BASE, m.felt))?;
        }
        if let Some(t) = &self.timing {
            sink.put(TIMING, At::MasterDone, t)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Names(Vec<&'static str>);

    impl Sink for Names {
        type Error = ();
        fn put<M: Message>(&mut self, t: Typed<M>, _: At, _: &M) -> Result<(), ()> {
            assert_eq!(t.topic().ty, M::TYPE);
            self.0.push(t.topic().name);
            Ok(())
        }
    }

    #[test]
    fn each_side_emits_its_live_topics_and_nothing_else() {
        let names = |v: SampleView| {
            let mut n = Names(Vec::new());
            v.emit(0, &mut n).expect("emit");
            n.0
        };
        let live = |ix: &[usize]| ix.iter().map(|&i| TOPICS[i].name).collect::<Vec<_>>();
        let master = SampleView {
            master: Some(MasterView::default()),
            timing: Some(SampleTiming::default()),
            ..SampleView::default()
        };
        assert_eq!(names(master), live(&MASTER_LIVE));
        let slave = SampleView {
            slave: Some(SlaveView::default()),
            ..SampleView::default()
        };
        assert_eq!(names(slave), live(&SLAVE_LIVE));
        let arm = SampleView {
            arm: Some(ArmSample {
                base: "panda_link0".into(),
                names: vec!["a".to_string()].into(),
                q: Joints::from_slice(&[0.5]).expect("one joint"),
                effort: Joints::from_slice(&[1.0]).expect("one joint"),
                tool: [0.0; 3],
                force: [0.0; 3],
            }),
            ..SampleView::default()
        };
        assert_eq!(names(arm), live(&SLAVE_LIVE));
    }
}
