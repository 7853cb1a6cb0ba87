//! The slave's robot over ROS 2 (the master's device is in [`crate::ros_hand`]):
//! subscriptions that fill an [`Inbox`] (decoded, mapped and checked on Zenoh's
//! threads), a [`Watch`] the loop asks each tick, and the publisher of what the loop
//! sends back.

use crate::gate::JointGate;
use crate::map::force_cdr;
use crate::rmw_node::{RosNode, RosPublisher, RosSubscription};
use crate::watch::{Inbox, Latest, Watch};
use crate::RosError;
use crate::{Change, JointMap, Joints, Reading, Robot};
use std::sync::Arc;
use tactile_ros::msg::{Float64MultiArray, JointState, Message, WrenchStamped};
use tactile_scenario::RosRobotConfig;

/// Three joint angles or a force, as the loop takes them.
type Inbox3 = Arc<Inbox<[f64; 3]>>;

fn joints_in(
    node: &Arc<RosNode>,
    topic: &str,
    map: JointMap,
) -> Result<(Inbox3, RosSubscription), RosError> {
    let inbox = Inbox::new();
    let sub = node.subscribe(topic, JointState::TYPE, &inbox, move |cdr| {
        map.angles_cdr(cdr)
    })?;
    Ok((inbox, sub))
}

/// A robot arm through ros2_control (and a force-torque sensor, if named).
#[derive(Debug)]
pub struct RosRobot {
    /// The session everything below lives on, kept open while the robot is.
    node: Arc<RosNode>,
    joints: Arc<Inbox<[f64; 3]>>,
    wrench: Option<Arc<Inbox<[f64; 3]>>>,
    _subs: Vec<RosSubscription>,
    command: RosPublisher,
    map: JointMap,
    wrench_map: tactile_scenario::ForceMapConfig,
    gate: JointGate,
    watch: Watch,
    topic: String,
    /// The loop's last tick, CLOCK_MONOTONIC ns: the end's hold is judged at it.
    last_tick_ns: u64,
}

impl RosRobot {
    /// Subscribes to the joint states (and the wrench) and declares the command
    /// publisher.
    pub fn open(node: &Arc<RosNode>, cfg: &RosRobotConfig, t_s_ns: u64) -> Result<Self, RosError> {
        let map = JointMap::new(cfg.paper_joints(), cfg.paper_map());
        let (joints, sub) = joints_in(node, &cfg.joint_states, map.clone())?;
        let mut subs = vec![sub];
        let wrench = if cfg.wrench_topic.is_empty() {
            None
        } else {
            let inbox = Inbox::new();
            let max = cfg.max_force;
            let decode = move |cdr: &[u8]| force_cdr(cdr, max);
            subs.push(node.subscribe(&cfg.wrench_topic, WrenchStamped::TYPE, &inbox, decode)?);
            Some(inbox)
        };
        Ok(RosRobot {
            node: Arc::clone(node),
            joints,
            wrench,
            _subs: subs,
            command: node.publisher(&cfg.command_topic, Float64MultiArray::TYPE)?,
            gate: {
                let (lo, hi) = map.raw_range();
                let t_s = t_s_ns as f64 * 1e-9;
                JointGate::new(
                    lo,
                    hi,
                    map.raw_step(cfg.paper_max_velocity().map(|v| v * t_s)),
                )
            },
            map,
            wrench_map: cfg.paper_wrench_map(),
            watch: Watch::new(&cfg.watch, t_s_ns),
            topic: cfg.joint_states.clone(),
            last_tick_ns: 0,
        })
    }
}

/// `Peripheral` for a robot of fields `node`, `joints` (its JointState inbox), `wrench`
/// (its sensor's, if any), `watch` and `topic`: the paper's arm and an arm from its
/// URDF are judged and counted alike.
macro_rules! robot_peripheral {
    ($t:ty) => {
        impl $crate::Peripheral for $t {
            fn kind(&self) -> &'static str {
                "robot"
            }

            fn heard(&self) -> bool {
                self.joints.latest().is_some()
            }

            fn counters(&self) -> $crate::DeviceCounters {
                let mut counts = vec![self.joints.counts()];
                counts.extend(self.wrench.as_ref().map(|w| w.counts()));
                self.watch.counters(&counts)
            }

            fn take_reject(&self) -> Option<$crate::Reject> {
                self.joints
                    .take_reject()
                    .or_else(|| self.wrench.as_ref().and_then(|w| w.take_reject()))
            }

            fn describe(&self) -> String {
                format!("the robot on {}", self.topic)
            }

            fn unreached(&self) -> Option<String> {
                self.node.unreached()
            }
        }
    };
}
pub(crate) use robot_peripheral;

robot_peripheral!(RosRobot);

impl Robot for RosRobot {
    fn read(&mut self, now_ns: u64) -> (Reading<Joints>, Change) {
        let (reading, change) = self.watch.judge(self.joints.latest(), now_ns);
        (reading.map(Joints::from), change)
    }

    fn force(&mut self, now_ns: u64) -> Option<[f64; 3]> {
        let w = self.wrench.as_ref()?;
        let f = self.watch.force(w.latest(), now_ns);
        Some(self.wrench_map.to_paper(f))
    }

    fn command(&mut self, theta_ref: Joints, now_ns: u64) {
        let theta_ref = theta_ref.to_array3();
        self.last_tick_ns = now_ns;
        if let Some(l) = self.joints.latest() {
            self.gate.start_at(self.map.raw(l.value));
        }
        let passed = self.gate.pass(self.map.raw(theta_ref));
        self.watch.gated(&passed);
        if let Some(raw) = passed.value() {
            let m = Float64MultiArray { data: raw.to_vec() };
            let ok = self.command.put(&m.to_cdr());
            self.watch.published(ok);
        }
    }

    fn release(&mut self) -> bool {
        let map = &self.map;
        let raw = self.joints.latest().map(|l| Latest {
            value: map.raw(l.value),
            at_ns: l.at_ns,
        });
        let Some(raw) = hold_at(raw, self.last_tick_ns, &mut self.gate, &mut self.watch) else {
            return false;
        };
        let m = Float64MultiArray { data: raw.to_vec() };
        released(&self.command, &m.to_cdr(), &mut self.watch)
    }
}

/// The hold at a run's end: where the robot is (`latest`, in the driver's unit),
/// checked like every command; never heard from, or silent past the timeout at the
/// last tick (it may have moved since), nothing: the controller holds the last command
/// it took.
pub(crate) fn hold_at<V: Clone + PartialEq + AsRef<[f64]> + AsMut<[f64]>>(
    latest: Option<Latest<V>>,
    last_tick_ns: u64,
    gate: &mut JointGate<V>,
    watch: &mut Watch,
) -> Option<V> {
    let l = latest?;
    if !watch.fresh(l.at_ns, last_tick_ns) {
        return None;
    }
    let passed = gate.hold(l.value);
    watch.gated(&passed);
    passed.value()
}

/// Sends the hold `cdr` so it arrives; true if a controller took it.
pub(crate) fn released(command: &RosPublisher, cdr: &[u8], watch: &mut Watch) -> bool {
    let (sent, matched) = command.put_reliably(cdr);
    watch.published(sent);
    watch.released(sent && matched);
    sent && matched
}
