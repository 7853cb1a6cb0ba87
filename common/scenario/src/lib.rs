//! Scenario files: what one run of the loop does.
//!
//! A scenario is TOML; every table rejects unknown keys so a typo is an error naming
//! the key rather than a silently ignored setting. [`Scenario::from_toml_str`] parses
//! and then checks ranges ([`Scenario::validate`]) so that an absurd value (a negative
//! delay, a zero rate, negative noise) is refused with the field's dotted path before
//! anything starts. The defaults reproduce the paper's setup.

mod aqm;
mod arm;
mod bounds;
pub use bounds::MAX_POSITION_M;
mod compact;
mod control;
pub mod csv;
mod device;
pub mod endpoint;
mod error;
pub mod hand;
mod histogram;
mod human;
mod lengths;
mod link;
mod master;
#[cfg(test)]
mod messages_tests;
mod network;
mod operator;
pub mod overrides;
mod path;
mod ros;
mod ros_robot;
mod ros_tls;
/// Numbers and name lists as error messages show them (defined in `tactile-math`, shared with the URDF chain).
pub use tactile_math::shown;
mod slave;
mod task;
pub mod units;
mod validate;
pub use validate::MAX_NAME_CHARS;
mod warnings;
mod watch;
pub use watch::WatchConfig;
pub mod world;
mod world_check;
pub use task::{TaskConfig, TOOL_BODY};
pub use world_check::{MAX_BODIES, MAX_HULL_POINTS, MAX_SIZE_M};
pub mod workspace;

pub use aqm::{
    ClassConfig, CodelArithmetic, CodelConfig, FqCodelConfig, PieConfig, PriorityConfig,
    WeightedConfig, MAX_AQM_MS, MAX_CLASSES, MAX_FLOW_ID,
};
pub use arm::{ArmConfig, ArmIkConfig, ArmServo, CartesianConfig, MAX_ARM_DOF};
pub use control::{
    CodecConfig, CodecKind, Codecs, ControlConfig, ControlKind, MmtConfig, MmtSlave, MmtUpdate,
    PredictorConfig, PredictorKind, MIN_MEMORY_SAMPLES,
};
pub use device::{geometry_from_toml, CordicSettings, DeviceChoice};
pub(crate) use error::{finite3, invalid, positive, positive3};
pub use error::{one_line, ScenarioError};
pub use hand::{ClutchConfig, ForceMessage, GimbalConfig, HandInput, OmniButton};
pub use histogram::{
    shipped_histogram, HistogramConfig, HistogramFormat, ShippedHistogram, SHIPPED_HISTOGRAMS,
};
pub use human::{HumanConfig, Response};
pub use link::{
    LinkConfig, QueueKind, MAX_PACKET_BYTES, MAX_QUEUE_PACKETS, MAX_RATE, MAX_TRACE_PACKET_BYTES,
    NETWORKS_DIR, SHIPPED_TRACES,
};
pub use master::{FaultConfig, HandConfig, HandMode, MasterConfig, MasterDeviceConfig};
pub use network::{
    ChannelConfig, JitterConfig, JitterDistribution, LossModel, Network, ReplayConfig,
    ReplayFormat, JITTER_CAP, MAX_DELAY_SAMPLES,
};
pub use operator::{Operator, TrajectoryEnd};
pub use ros::{
    topic_name, AngleUnit, Backend, ForceMapConfig, JointMapConfig, LiveConfig, RosConfig,
    RosDeviceConfig,
};
pub use ros_robot::{RobotCommand, RosRobotConfig, TorqueAbout, PAPER_MAX_VELOCITY};
pub use ros_tls::RosTlsConfig;
use serde::{Deserialize, Serialize};
pub use slave::{
    Change, ControllerConfig, DynamicsConfig, Environment, Object, SlaveConfig, GRAVITY,
    MAX_STIFFNESS, NOMINAL_MAX_STIFFNESS, SUBSTEPS,
};
pub use tactile_math::arith::ArithKind;
pub use workspace::{FrameRotation, Scale, Workspace};

/// How the master paces the loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// The master ticks every `t_s` of wall-clock time.
    #[default]
    Realtime,
    /// Each sample goes round as fast as the processes allow; no sleeping.
    Lockstep,
}

/// One whole run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scenario {
    /// Name used in reports.
    pub name: String,
    /// `realtime` or `lockstep`.
    pub mode: Mode,
    /// Sampling rate 1/t_s in Hz, 100 to 10000 (the paper: 100 Hz).
    pub rate_hz: f64,
    /// Number of samples the master sends.
    pub samples: u64,
    /// Arithmetic of the HMD and HSD kernels: `f64`, `f32` or `hybrid`.
    pub arithmetic: ArithKind,
    /// Fixed-point format of the hybrid CORDIC block.
    pub cordic: CordicSettings,
    /// Device geometry of master and slave: a preset name or explicit lengths.
    pub device: DeviceChoice,
    /// Seed of every random source (channel noise), so runs repeat.
    pub seed: u64,
    /// What the operator does.
    pub operator: Operator,
    /// The emulated network.
    pub network: Network,
    /// The master side: device limits.
    pub master: MasterConfig,
    /// The slave side: controller and device dynamics.
    pub slave: SlaveConfig,
    /// Fault handling shared by the processes.
    pub faults: FaultConfig,
    /// Objects in the slave's environment.
    pub environment: Environment,
    /// Stability control on the channel.
    pub control: ControlConfig,
    /// Deadband codecs per direction.
    pub codec: Codecs,
    /// How the nodes reach ROS 2 (devices, robots, the live view).
    pub ros: RosConfig,
    /// What success is, in a physics world (docs/16); none by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub task: Option<TaskConfig>,
}

impl Default for Scenario {
    /// What a scenario file that sets nothing runs: 1200 samples at 100 Hz of the
    /// paper's trajectory, seed 0, no objects; each table its own defaults.
    fn default() -> Self {
        Scenario {
            name: "unnamed".into(),
            mode: Mode::default(),
            rate_hz: 100.0,
            samples: 1200,
            arithmetic: ArithKind::default(),
            cordic: CordicSettings::default(),
            device: DeviceChoice::default(),
            seed: 0,
            operator: Operator::default(),
            network: Network::default(),
            master: MasterConfig::default(),
            slave: SlaveConfig::default(),
            faults: FaultConfig::default(),
            environment: Environment::default(),
            control: ControlConfig::default(),
            codec: Codecs::default(),
            ros: RosConfig::default(),
            task: None,
        }
    }
}

impl Scenario {
    /// The paper scenario (`deploy/scenarios/paper.toml` holds the same values).
    pub fn paper() -> Scenario {
        Scenario {
            name: "paper".into(),
            arithmetic: ArithKind::Hybrid,
            seed: 1,
            environment: Environment {
                objects: vec![Object::Plane {
                    point: [0.0, 0.0, -0.16],
                    normal: [0.0, 0.0, 1.0],
                    stiffness: [300.0; 3],
                }],
                ..Environment::default()
            },
            ..Scenario::default()
        }
    }

    /// Parses TOML, converts the `_ms` keys into samples ([`units`]) and validates
    /// every range.
    pub fn from_toml_str(text: &str) -> Result<Scenario, ScenarioError> {
        let mut written = text.parse::<toml::Value>().ok();
        let converted = match &mut written {
            Some(w) => units::to_samples(w)?,
            None => false,
        };
        if let Some(w) = &written {
            // By name, before the types: `max_velocity = 2.0` beside an arm is told
            // what to write instead, not that it takes an array of three.
            ros_robot::refuse_written(w)?;
        }
        let s: Scenario = match (&written, converted) {
            (Some(w), true) => units::parse_converted(text, w)?,
            _ => toml::from_str(text).map_err(|e| ScenarioError::Parse(one_line(text, &e)))?,
        };
        if let (Some(written), Ok(parsed)) = (&written, toml::Value::try_from(&s)) {
            lengths::check(written, &parsed)?;
        }
        s.validate()?;
        let mut s = s;
        for c in [&mut s.network.forward, &mut s.network.backward] {
            if let Some(l) = &mut c.link {
                l.name_to_path();
            }
        }
        Ok(s)
    }

    /// The same scenario with every relative path made absolute against `base_dir`
    /// (the scenario file's folder), so a copy of it runs from any folder.
    pub fn resolved(&self, base_dir: &std::path::Path) -> Scenario {
        let resolve = |path: &mut String| {
            let p = std::path::Path::new(path.as_str());
            if p.is_relative() {
                *path = base_dir.join(p).display().to_string();
            }
        };
        let mut s = self.clone();
        s.input_paths_mut().into_iter().for_each(resolve);
        // The session's TLS files are read where they are, never copied into a run's
        // inputs/ (a private key has no place in a folder of results).
        if let Some(t) = &mut s.ros.tls {
            [&mut t.ca, &mut t.cert, &mut t.key]
                .into_iter()
                .for_each(resolve);
        }
        s
    }

    /// The paths of every file the scenario reads (a trajectory, recorded networks, an
    /// arm's URDF, a device's gimbal URDF): the one list that `tactile run` checks as
    /// its inputs, resolves against the scenario's folder and copies into the run's
    /// `inputs/`, so a file missing here would be read from the wrong folder.
    pub fn input_paths_mut(&mut self) -> Vec<&mut String> {
        let mut v = Vec::new();
        if let Operator::Csv { path, .. } = &mut self.operator {
            v.push(path);
        }
        if let Some(arm) = &mut self.slave.arm {
            v.push(&mut arm.urdf);
        }
        if let Some(g) = &mut self.master.ros2.gimbal {
            v.push(&mut g.urdf);
        }
        let shapes = self.environment.bodies.iter_mut().map(|b| &mut b.shape);
        for shape in shapes.chain([&mut self.environment.tool.shape]) {
            match shape {
                world::Shape::Mesh { file, .. }
                | world::Shape::ConvexHull {
                    file: Some(file), ..
                } => v.push(file),
                _ => {}
            }
        }
        for c in [&mut self.network.forward, &mut self.network.backward] {
            if let Some(r) = &mut c.replay {
                v.push(&mut r.path);
            }
            if let Some(p) = c.delay_histogram.as_mut().and_then(|h| h.path.as_mut()) {
                v.push(p);
            }
            if let Some(l) = &mut c.link {
                v.extend(l.path.as_mut());
                v.extend(l.rate_trace.as_mut());
            }
        }
        v
    }

    /// The paths of [`Scenario::input_paths_mut`], as written.
    pub fn input_paths(&self) -> Vec<String> {
        let mut s = self.clone();
        s.input_paths_mut().into_iter().map(|p| p.clone()).collect()
    }

    /// The scenario with input paths inside `dir` made relative to it: a run's
    /// `scenario.toml` refers to the copies beside it, so the folder reruns anywhere.
    pub fn relative_to(&self, dir: &std::path::Path) -> Scenario {
        let mut s = self.clone();
        for path in s.input_paths_mut() {
            if let Ok(rel) = std::path::Path::new(path.as_str()).strip_prefix(dir) {
                *path = rel.display().to_string();
            }
        }
        s
    }

    /// The scenario as TOML text (what a run's `scenario.toml` holds), an extreme
    /// number written short ([`compact`]).
    pub fn to_toml(&self) -> String {
        match toml::to_string(self) {
            Ok(text) => compact::floats(&text),
            Err(e) => format!("# cannot encode the scenario: {e}\n"),
        }
    }

    /// Sampling period t_s in seconds.
    pub fn t_s(&self) -> f64 {
        1.0 / self.rate_hz
    }

    /// Sampling period in nanoseconds.
    pub fn t_s_ns(&self) -> u64 {
        (1e9 / self.rate_hz).round() as u64
    }
}
