//! A robot arm from its URDF over ROS 2 (`[slave.arm]` with `slave.backend = "ros2"`):
//! the chain's joints read by name from the robot's `JointState`, each reference sent
//! as the controller takes it (a forward position controller's `Float64MultiArray`, in
//! the chain's order, or a joint_trajectory_controller's `JointTrajectory` of one
//! point), or, for a stack that does its own IK (MoveIt Servo, cartesian_controllers),
//! the tool's pose those joints put it at (`PoseStamped` in the base link, stamped with
//! the wall clock), always through the gate of the URDF's limits; and a force-torque
//! sensor's wrench turned into the base's axes through the chain.

use crate::arm_map::{framed_force_cdr, in_base, ArmJointMap, FramedForce};
use crate::gate::JointGate;
use crate::rmw_node::{wall_ns, RosNode, RosPublisher, RosSubscription};
use crate::ros_devices::{hold_at, released};
use crate::watch::{Inbox, Watch};
use crate::{Change, Joints, Reading, Robot, RosError};
use std::sync::Arc;
use tactile_chain::{Chain, Tree};
use tactile_ros::msg::{
    Float64MultiArray, Header, JointState, JointTrajectory, Message, PoseStamped, Time,
    WrenchStamped,
};
use tactile_scenario::{RobotCommand, RosRobotConfig};

/// An arm through ros2_control.
#[derive(Debug)]
pub struct RosArm {
    node: Arc<RosNode>,
    joints: Arc<Inbox<Joints>>,
    wrench: Option<Arc<Inbox<FramedForce>>>,
    _subs: Vec<RosSubscription>,
    command: RosPublisher,
    kind: RobotCommand,
    /// A trajectory point's time from start.
    point_time: Time,
    map: ArmJointMap,
    tree: Arc<Tree>,
    /// The chain, for a pose command's FK.
    chain: Chain,
    base: String,
    /// The torque that came with the last force, about the tool, in the base's axes.
    torque: [f64; 3],
    /// The point the wrench's torque is about.
    torque_about: tactile_scenario::TorqueAbout,
    gate: JointGate<Joints>,
    watch: Watch,
    topic: String,
    last_tick_ns: u64,
}

impl RosArm {
    /// Subscribes to the joint states (and the wrench) and declares the command
    /// publisher of the arm `chain` (from `tree`'s URDF).
    pub fn open(
        node: &Arc<RosNode>,
        cfg: &RosRobotConfig,
        chain: &Chain,
        tree: Tree,
        t_s_ns: u64,
    ) -> Result<Self, RosError> {
        let t_s = t_s_ns as f64 * 1e-9;
        let map = ArmJointMap::of(chain).map_err(|e| RosError::new("the arm's joints", e))?;
        let tree = Arc::new(tree);
        let joints = Inbox::new();
        let m = map.clone();
        let decode = move |cdr: &[u8]| m.positions_cdr(cdr);
        let mut subs =
            vec![node.subscribe(&cfg.joint_states, JointState::TYPE, &joints, decode)?];
        let wrench = if cfg.wrench_topic.is_empty() {
            None
        } else {
            let inbox = Inbox::new();
            let (t, base, max) = (Arc::clone(&tree), chain.base.clone(), cfg.max_force);
            let decode = move |cdr: &[u8]| framed_force_cdr(cdr, &t, &base, max);
            subs.push(node.subscribe(&cfg.wrench_topic, WrenchStamped::TYPE, &inbox, decode)?);
            Some(inbox)
        };
        let ty = match cfg.command {
            RobotCommand::Positions => Float64MultiArray::TYPE,
            RobotCommand::Trajectory => JointTrajectory::TYPE,
            RobotCommand::Pose => PoseStamped::TYPE,
        };
        let point_s = cfg.trajectory_time_s.unwrap_or(t_s);
        Ok(RosArm {
            node: Arc::clone(node),
            joints,
            wrench,
            _subs: subs,
            command: node.publisher(&cfg.command_topic, ty)?,
            kind: cfg.command,
            point_time: Time::from_ns((point_s * 1e9).round() as u64),
            gate: map.gate(t_s),
            map,
            tree,
            chain: chain.clone(),
            base: chain.base.clone(),
            torque: [0.0; 3],
            torque_about: cfg.wrench_torque,
            watch: Watch::new(&cfg.watch, t_s_ns),
            topic: cfg.joint_states.clone(),
            last_tick_ns: 0,
        })
    }

    /// The command message for joint values `q` (which passed the gate): a pose
    /// command's is the tool's pose at `q`, so it is reachable and moves no joint
    /// faster than the gate lets it.
    fn message(&self, q: Joints) -> Vec<u8> {
        match self.kind {
            RobotCommand::Positions => Float64MultiArray { data: q.to_vec() }.to_cdr(),
            RobotCommand::Trajectory => JointTrajectory {
                // A zero stamp: the controller starts the point on receipt.
                header: Header::at(0, ""),
                joint_names: self.map.names.clone(),
                positions: q.to_vec(),
                velocities: Vec::new(),
                time_from_start: self.point_time,
            }
            .to_cdr(),
            RobotCommand::Pose => {
                let tool = self.chain.fk(&q);
                PoseStamped {
                    header: Header::at(wall_ns(), &self.base),
                    position: tool.p.into(),
                    orientation: tactile_chain::spatial::quaternion(&tool.r),
                }
                .to_cdr()
            }
        }
    }
}

crate::ros_devices::robot_peripheral!(RosArm);

impl Robot for RosArm {
    fn read(&mut self, now_ns: u64) -> (Reading<Joints>, Change) {
        self.watch.judge(self.joints.latest(), now_ns)
    }

    fn force(&mut self, now_ns: u64) -> Option<[f64; 3]> {
        let w = self.wrench.as_ref()?;
        let latest = w.latest();
        let fresh = latest
            .as_ref()
            .filter(|l| self.watch.fresh(l.at_ns, now_ns));
        let force = latest.as_ref().map(|l| crate::watch::Latest {
            value: l.value.0,
            at_ns: l.at_ns,
        });
        // Judged (and counted) as the paper robot's sensor is; turned into the base's
        // axes at the joints last read. The torque comes with a fresh force only.
        let judged = self.watch.force(force, now_ns);
        self.torque = [0.0; 3];
        let (Some(l), Some(q)) = (fresh, self.joints.latest()) else {
            return Some(judged);
        };
        let torque = if judged == l.value.0 {
            l.value.1
        } else {
            [0.0; 3]
        };
        let (f, t) = in_base(
            &self.tree,
            (&self.base, &self.chain.tip, self.torque_about),
            &self.map.names,
            &q.value,
            &(judged, torque, l.value.2.clone()),
        );
        self.torque = t;
        Some(f)
    }

    fn torque(&self) -> [f64; 3] {
        self.torque
    }

    fn command(&mut self, reference: Joints, now_ns: u64) {
        self.last_tick_ns = now_ns;
        if let Some(l) = self.joints.latest() {
            self.gate.start_at(l.value);
        }
        let passed = self.gate.pass(reference);
        self.watch.gated(&passed);
        if let Some(q) = passed.value() {
            let ok = self.command.put(&self.message(q));
            self.watch.published(ok);
        }
    }

    fn release(&mut self) -> bool {
        // As the paper robot's: where the arm is, if it was heard from in time.
        let latest = self.joints.latest();
        let Some(q) = hold_at(latest, self.last_tick_ns, &mut self.gate, &mut self.watch) else {
            return false;
        };
        released(&self.command, &self.message(q), &mut self.watch)
    }
}
