//! The master's haptic device through its ROS 2 driver: the handle read from a
//! `JointState` (three joints, and the gimbal's with a Touch) or a `PoseStamped`, the
//! clutch from its own topic, each decoded and checked on Zenoh's threads into an
//! [`Inbox`]; a [`Watch`] the loop asks each tick; and the force out, through the
//! gate, in the message the driver takes.

use crate::gate::ForceGate;
use crate::hand::{clutch_cdr, force_cdr, force_type, joints_cdr, pose_cdr, Gimbal, Hand};
use crate::rmw_node::{wall_ns, RosNode, RosPublisher, RosSubscription};
use crate::watch::{Inbox, Watch};
use crate::RosError;
use crate::{Change, DeviceCounters, HapticDevice, JointMap, Peripheral, Reading, Reject};
use std::sync::Arc;
use tactile_ros::hand_msg::{Bool, Joy, OmniButtonEvent};
use tactile_ros::msg::{JointState, Message, PoseStamped};
use tactile_scenario::{ClutchConfig, ForceMessage, HandInput, RosDeviceConfig};

/// How many times the zero at the end is put, and how far apart: a driver that misses
/// one (a subscriber's queue full) takes the next.
const RELEASE_PUTS: u32 = 3;
const RELEASE_GAP: std::time::Duration = std::time::Duration::from_millis(5);

/// A haptic device through its ROS 2 driver.
#[derive(Debug)]
pub struct RosHapticDevice {
    /// The session everything below lives on, kept open while the device is.
    node: Arc<RosNode>,
    hand: Arc<Inbox<Hand>>,
    clutch: Option<Arc<Inbox<bool>>>,
    _subs: Vec<RosSubscription>,
    force: RosPublisher,
    message: ForceMessage,
    frame: String,
    force_map: tactile_scenario::ForceMapConfig,
    gate: ForceGate,
    watch: Watch,
    input: HandInput,
    topic: String,
    released: bool,
}

impl RosHapticDevice {
    /// Subscribes to the handle (and the clutch) and declares the force publisher;
    /// forces stay within `force_limit` N per axis. `gimbal`: the device's chain for
    /// the orientation, read from `cfg.gimbal`'s URDF by the caller.
    pub fn open(
        node: &Arc<RosNode>,
        cfg: &RosDeviceConfig,
        gimbal: Option<Gimbal>,
        t_s_ns: u64,
        force_limit: f64,
    ) -> Result<Self, RosError> {
        let t_s = t_s_ns as f64 * 1e-9;
        let hand = Inbox::new();
        let (topic, sub) = match cfg.input {
            HandInput::Joints => {
                let map = JointMap::new(cfg.joints.clone(), cfg.map.clone());
                let decode = move |cdr: &[u8]| joints_cdr(&map, gimbal.as_ref(), cdr);
                let sub = node.subscribe(&cfg.joint_states, JointState::TYPE, &hand, decode)?;
                (cfg.joint_states.clone(), sub)
            }
            HandInput::Pose => {
                let sub = node.subscribe(&cfg.pose_topic, PoseStamped::TYPE, &hand, pose_cdr)?;
                (cfg.pose_topic.clone(), sub)
            }
        };
        let mut subs = vec![sub];
        let clutch = match clutch_type(&cfg.clutch) {
            None => None,
            Some((t, ty)) => {
                let inbox = Inbox::new();
                let c = cfg.clutch.clone();
                subs.push(node.subscribe(t, ty, &inbox, move |cdr| clutch_cdr(&c, cdr))?);
                Some(inbox)
            }
        };
        Ok(RosHapticDevice {
            node: Arc::clone(node),
            hand,
            clutch,
            _subs: subs,
            force: node.publisher(&cfg.force_topic, force_type(cfg.force_message))?,
            message: cfg.force_message,
            frame: cfg.frame_id.clone(),
            force_map: cfg.force_map.clone(),
            gate: ForceGate::new(force_limit, cfg.max_force_rate, cfg.ramp_s, t_s),
            watch: Watch::new(&cfg.watch, t_s_ns),
            input: cfg.input,
            topic,
            released: false,
        })
    }

    fn force_cdr(&self, force: [f64; 3]) -> Vec<u8> {
        force_cdr(self.message, force, wall_ns(), &self.frame)
    }
}

/// The clutch's topic and type.
fn clutch_type(c: &ClutchConfig) -> Option<(&str, &'static str)> {
    let ty = match c {
        ClutchConfig::None => return None,
        ClutchConfig::Bool { .. } => Bool::TYPE,
        ClutchConfig::Joy { .. } => Joy::TYPE,
        ClutchConfig::OmniButton { .. } => OmniButtonEvent::TYPE,
    };
    c.topic().map(|t| (t, ty))
}

impl Drop for RosHapticDevice {
    /// A driver holds its last command: leave the device rendering nothing, however
    /// the run ends (the loop's driver releases it first; this is the last resort).
    fn drop(&mut self) {
        if !self.released {
            self.release();
        }
    }
}

impl Peripheral for RosHapticDevice {
    fn kind(&self) -> &'static str {
        "device"
    }

    fn heard(&self) -> bool {
        self.hand.latest().is_some()
    }

    fn counters(&self) -> DeviceCounters {
        let mut counts = vec![self.hand.counts()];
        counts.extend(self.clutch.as_ref().map(|c| c.counts()));
        self.watch.counters(&counts)
    }

    fn take_reject(&self) -> Option<Reject> {
        self.hand
            .take_reject()
            .or_else(|| self.clutch.as_ref().and_then(|c| c.take_reject()))
    }

    fn describe(&self) -> String {
        format!("the device on {}", self.topic)
    }

    fn unreached(&self) -> Option<String> {
        self.node.unreached()
    }
}

impl HapticDevice for RosHapticDevice {
    fn read(&mut self, now_ns: u64) -> (Reading<Hand>, Change) {
        self.watch.judge(self.hand.latest(), now_ns)
    }

    /// The button's last state: drivers send it on change only, so its age says
    /// nothing; released until the first message.
    fn clutch(&self) -> Option<bool> {
        let c = self.clutch.as_ref()?;
        Some(c.latest().is_some_and(|l| l.value))
    }

    fn input(&self) -> HandInput {
        self.input
    }

    fn render(&mut self, force: [f64; 3], _now_ns: u64) {
        let passed = self.gate.pass(self.force_map.to_device(force));
        self.watch.gated(&passed);
        self.watch.ramps(self.gate.ramps());
        if let Some(f) = passed.value() {
            let ok = self.force.put(&self.force_cdr(f));
            self.watch.published(ok);
        }
    }

    fn restart_ramp(&mut self) {
        self.gate.restart();
        self.watch.ramps(self.gate.ramps());
    }

    fn release(&mut self) -> bool {
        let zero = self.force_cdr([0.0; 3]);
        let (mut sent, mut matched) = (false, false);
        for k in 0..RELEASE_PUTS {
            if k > 0 {
                std::thread::sleep(RELEASE_GAP);
            }
            let (s, m) = self.force.put_reliably(&zero);
            self.watch.published(s);
            (sent, matched) = (sent || s, matched || m);
        }
        self.released = true;
        self.watch.released(sent && matched);
        sent && matched
    }
}
