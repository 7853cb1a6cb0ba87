//! Scenario files: what one run of the loop does.
//!
//! A scenario is TOML; every table rejects unknown keys so a typo is an error naming
//! the key rather than a silently ignored setting. [`Scenario::from_toml_str`] parses
//! and then checks ranges ([`Scenario::validate`]) so that an absurd value (a negative
//! delay, a zero rate, negative noise) is refused with the field's dotted path before
//! anything starts. The defaults reproduce the paper's setup.

use crate::arith::ArithKind;
pub use crate::bilateral::{ControlConfig, ControlKind, HandConfig, HandMode, MasterDeviceConfig};
use crate::cordic::{CordicConfig, Rounding};
use crate::geometry::Geometry;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// A scenario that cannot run, with the dotted path of the offending field.
#[derive(Debug, Error, PartialEq)]
pub enum ScenarioError {
    /// TOML syntax, an unknown key or a wrong type (the message names the key).
    #[error("{0}")]
    Parse(String),
    /// A value out of range.
    #[error("field `{field}`: {problem}")]
    Invalid {
        /// Dotted path of the field, e.g. `network.forward.delay`.
        field: String,
        /// What is wrong.
        problem: String,
    },
}

pub(crate) fn invalid(field: impl Into<String>, problem: impl Into<String>) -> ScenarioError {
    ScenarioError::Invalid {
        field: field.into(),
        problem: problem.into(),
    }
}

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
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name used in reports.
    #[serde(default = "default_name")]
    pub name: String,
    /// `realtime` or `lockstep`.
    #[serde(default)]
    pub mode: Mode,
    /// Sampling rate 1/t_s in Hz, 100 to 10000 (the paper: 100 Hz).
    #[serde(default = "default_rate")]
    pub rate_hz: f64,
    /// Number of samples the master sends.
    #[serde(default = "default_samples")]
    pub samples: u64,
    /// Arithmetic of the HMD and HSD kernels: `f64`, `f32` or `hybrid`.
    #[serde(default)]
    pub arithmetic: ArithKind,
    /// Fixed-point format of the hybrid CORDIC block.
    #[serde(default)]
    pub cordic: CordicSettings,
    /// Device geometry of master and slave: a preset name or explicit lengths.
    #[serde(default)]
    pub device: DeviceChoice,
    /// Seed of every random source (channel noise), so runs repeat.
    #[serde(default)]
    pub seed: u64,
    /// What the operator does.
    #[serde(default)]
    pub operator: Operator,
    /// The emulated network.
    #[serde(default)]
    pub network: Network,
    /// The master side: device limits.
    #[serde(default)]
    pub master: MasterConfig,
    /// The slave side: controller and device dynamics.
    #[serde(default)]
    pub slave: SlaveConfig,
    /// Fault handling shared by the processes.
    #[serde(default)]
    pub faults: FaultConfig,
    /// Objects in the slave's environment.
    #[serde(default)]
    pub environment: Environment,
    /// Stability control on the channel.
    #[serde(default)]
    pub control: ControlConfig,
    /// Deadband codecs per direction.
    #[serde(default)]
    pub codec: crate::codec::Codecs,
}

fn default_name() -> String {
    "unnamed".into()
}
fn default_rate() -> f64 {
    100.0
}
fn default_samples() -> u64 {
    1200
}

/// CORDIC settings in a scenario; missing keys take the [s16.13] defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CordicSettings {
    /// Word length V of [sV.N].
    #[serde(default = "default_word")]
    pub word: u32,
    /// Fractional bits N.
    #[serde(default = "default_frac")]
    pub frac: u32,
    /// Iterations; default derived from `frac`.
    #[serde(default)]
    pub iterations: Option<u32>,
    /// `truncate` or `nearest`.
    #[serde(default = "default_rounding")]
    pub rounding: Rounding,
}

fn default_word() -> u32 {
    CordicConfig::S16_13.word
}
fn default_frac() -> u32 {
    CordicConfig::S16_13.frac
}
fn default_rounding() -> Rounding {
    CordicConfig::S16_13.rounding
}

impl Default for CordicSettings {
    fn default() -> Self {
        CordicSettings {
            word: default_word(),
            frac: default_frac(),
            iterations: None,
            rounding: default_rounding(),
        }
    }
}

impl CordicSettings {
    /// The validated configuration.
    pub fn config(&self) -> Result<CordicConfig, ScenarioError> {
        CordicConfig::new(self.word, self.frac, self.iterations, self.rounding)
            .map_err(|e| invalid("cordic", e.to_string()))
    }
}

/// A device preset (`"paper"`, `"omni"`) or explicit lengths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum DeviceChoice {
    /// `device = "paper"`.
    Preset(String),
    /// `[device]` with `l1`, `l2`, `l3`, `a`.
    Lengths(Geometry),
}

impl Default for DeviceChoice {
    fn default() -> Self {
        DeviceChoice::Preset("paper".into())
    }
}

impl DeviceChoice {
    /// The validated geometry.
    pub fn geometry(&self) -> Result<Geometry, ScenarioError> {
        match self {
            DeviceChoice::Preset(name) => Geometry::preset(name).ok_or_else(|| {
                invalid(
                    "device",
                    format!("unknown preset {name:?}: expected \"paper\", \"omni\" or a table with l1, l2, l3, a"),
                )
            }),
            DeviceChoice::Lengths(g) => {
                g.validate().map_err(|e| invalid("device", e.to_string()))?;
                Ok(*g)
            }
        }
    }
}

/// The operator's motion, a(n).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Operator {
    /// The paper's validation path: three 4 s joint moves, played back and forth if the
    /// run is longer.
    #[default]
    Paper,
    /// A circle in a plane parallel to two axes.
    Circle {
        /// Centre, metres.
        center: [f64; 3],
        /// Radius, metres.
        radius: f64,
        /// Seconds per revolution.
        period_s: f64,
        /// Plane of the circle: `xy`, `yz` or `xz`.
        #[serde(default = "default_plane")]
        plane: String,
    },
    /// A figure-eight (Gerono lemniscate) in a plane parallel to two axes.
    FigureEight {
        /// Centre, metres.
        center: [f64; 3],
        /// Half width, metres.
        size: f64,
        /// Seconds per figure.
        period_s: f64,
        /// Plane: `xy`, `yz` or `xz`.
        #[serde(default = "default_plane")]
        plane: String,
    },
    /// A press: from one point to another along a minimum-jerk path in `move_s`
    /// seconds, then held there (into a wall, the hand keeps pushing).
    Press {
        /// Start, metres.
        from: [f64; 3],
        /// End, held, metres.
        to: [f64; 3],
        /// Seconds to get there.
        move_s: f64,
    },
    /// Positions from a CSV file with header `x,y,z`, one row per sample (looped).
    Csv {
        /// Path, relative to the scenario file's folder.
        path: String,
    },
}

fn default_plane() -> String {
    "xy".into()
}

/// Both channels of the emulated network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Network {
    /// Master to slave: positions c(n) -> v(n).
    #[serde(default)]
    pub forward: ChannelConfig,
    /// Slave to master: forces h(n) -> q(n).
    #[serde(default)]
    pub backward: ChannelConfig,
}

/// One channel: v_i(n) = c_i(n - d_i(n)) + r_i(n).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelConfig {
    /// Constant delay per signal (x, y, z), in whole samples.
    #[serde(default)]
    pub delay: [i64; 3],
    /// Optional schedule overriding `delay`: `[[from_sample, dx, dy, dz], ...]`, sorted by
    /// `from_sample`; each entry holds from its sample until the next.
    #[serde(default)]
    pub schedule: Vec<[i64; 4]>,
    /// Standard deviation of the zero-mean Gaussian noise per signal (m forward, N back).
    #[serde(default)]
    pub noise_std: [f64; 3],
    /// Probability that the emulator drops a sample on purpose, 0 to 1 (seeded).
    #[serde(default)]
    pub loss: f64,
    /// Fault injection: probability that the emulator replaces a sample's values with
    /// NaN, 0 to 1 (seeded), to prove the receivers reject them.
    #[serde(default)]
    pub corrupt: f64,
    /// Jitter on each packet's delay, netem's `delay D JITTER CORRELATION
    /// distribution NAME` with D the `delay` above (all in samples).
    #[serde(default)]
    pub jitter: Option<crate::netem::JitterConfig>,
    /// Whether a packet may overtake an earlier one when jitter shortens its delay
    /// (netem's behaviour) [true]; false keeps arrivals in sending order.
    #[serde(default = "default_reorder")]
    pub reorder: bool,
    /// A loss model instead of `loss` (netem's random loss): `gemodel` or `state`.
    #[serde(default)]
    pub loss_model: Option<crate::netem::LossModel>,
    /// A recorded network replayed packet by packet, instead of `delay`, `schedule`
    /// and `jitter`.
    #[serde(default)]
    pub replay: Option<crate::netem::ReplayConfig>,
    /// Probability that a packet is sent twice, netem's `duplicate` (the copy takes
    /// its own jitter), 0 to 1 [0].
    #[serde(default)]
    pub duplicate: f64,
}

fn default_reorder() -> bool {
    true
}

impl Default for ChannelConfig {
    fn default() -> Self {
        ChannelConfig {
            delay: [0; 3],
            schedule: Vec::new(),
            noise_std: [0.0; 3],
            loss: 0.0,
            corrupt: 0.0,
            jitter: None,
            reorder: default_reorder(),
            loss_model: None,
            replay: None,
            duplicate: 0.0,
        }
    }
}

/// Largest delay accepted, in samples: ten seconds at the highest rate.
pub const MAX_DELAY_SAMPLES: i64 = 100_000;

impl ChannelConfig {
    fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        let check_delay = |d: i64, f: String| {
            if d < 0 {
                Err(invalid(
                    f,
                    format!("delay {d} is negative: a channel cannot deliver before sending"),
                ))
            } else if d > MAX_DELAY_SAMPLES {
                Err(invalid(
                    f,
                    format!("delay {d} exceeds {MAX_DELAY_SAMPLES} samples"),
                ))
            } else {
                Ok(())
            }
        };
        for (i, d) in self.delay.iter().enumerate() {
            check_delay(*d, format!("{field}.delay[{i}]"))?;
        }
        let mut last = -1;
        for (k, e) in self.schedule.iter().enumerate() {
            if e[0] < 0 || e[0] <= last {
                return Err(invalid(
                    format!("{field}.schedule[{k}]"),
                    "from_sample must be non-negative and strictly increasing",
                ));
            }
            last = e[0];
            for i in 0..3 {
                check_delay(e[i + 1], format!("{field}.schedule[{k}][{}]", i + 1))?;
            }
        }
        for (name, p) in [
            ("loss", self.loss),
            ("corrupt", self.corrupt),
            ("duplicate", self.duplicate),
        ] {
            if !p.is_finite() || !(0.0..=1.0).contains(&p) {
                return Err(invalid(
                    format!("{field}.{name}"),
                    format!("{p} is not a probability in [0, 1]"),
                ));
            }
        }
        for (i, s) in self.noise_std.iter().enumerate() {
            if !s.is_finite() || *s < 0.0 {
                return Err(invalid(
                    format!("{field}.noise_std[{i}]"),
                    format!("{s} must be a finite, non-negative standard deviation"),
                ));
            }
        }
        if let Some(j) = &self.jitter {
            j.validate(field)?;
        }
        if let Some(r) = &self.replay {
            r.validate(field)?;
            if self.jitter.is_some() || !self.schedule.is_empty() || self.delay != [0; 3] {
                return Err(invalid(
                    format!("{field}.replay"),
                    "gives each packet's delay: leave delay at [0, 0, 0], and schedule and jitter out",
                ));
            }
        }
        if let Some(m) = &self.loss_model {
            m.validate(field)?;
            if self.loss > 0.0 {
                return Err(invalid(
                    format!("{field}.loss_model"),
                    "and `loss` both set: choose one loss model",
                ));
            }
        }
        Ok(())
    }
}

/// The master device's limits (PHANToM Omni class by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MasterConfig {
    /// Largest force the operator is made to feel, N, per axis (the Omni: ~3.3 N).
    #[serde(default = "default_force_limit")]
    pub force_limit: f64,
    /// Largest torque commanded on a master joint, N m.
    #[serde(default = "default_master_torque_limit")]
    pub torque_limit: [f64; 3],
    /// How the operator's hand holds the handle.
    #[serde(default)]
    pub hand: HandConfig,
    /// The master device's joints (used with an impedance hand).
    #[serde(default)]
    pub device: MasterDeviceConfig,
    /// How the master fills forces not received (CPD/JPD-HMD).
    #[serde(default)]
    pub predictor: crate::codec::PredictorConfig,
}

fn default_force_limit() -> f64 {
    3.3
}
fn default_master_torque_limit() -> [f64; 3] {
    [0.45; 3]
}

impl Default for MasterConfig {
    fn default() -> Self {
        MasterConfig {
            force_limit: default_force_limit(),
            torque_limit: default_master_torque_limit(),
            hand: HandConfig::default(),
            device: MasterDeviceConfig::default(),
            predictor: crate::codec::PredictorConfig::default(),
        }
    }
}

/// How the processes notice a dead peer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultConfig {
    /// Consecutive samples without an answer after which the master declares the loop
    /// broken, commands zero torque and marks the samples; and without input after
    /// which the slave holds its position.
    #[serde(default = "default_peer_timeout")]
    pub peer_timeout_samples: u64,
}

fn default_peer_timeout() -> u64 {
    10
}

impl Default for FaultConfig {
    fn default() -> Self {
        FaultConfig {
            peer_timeout_samples: default_peer_timeout(),
        }
    }
}

/// The slave side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SlaveConfig {
    /// Joint controller.
    #[serde(default)]
    pub controller: ControllerConfig,
    /// Joint dynamics of the slave device.
    #[serde(default)]
    pub dynamics: DynamicsConfig,
    /// How the slave fills positions not received (CPD-HSD).
    #[serde(default)]
    pub predictor: crate::codec::PredictorConfig,
}

/// PD or PID per joint: u = kp e + ki integral(e) + kd de/dt, clamped to the limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerConfig {
    /// Proportional gains, N m / rad.
    #[serde(default = "default_kp")]
    pub kp: [f64; 3],
    /// Integral gains, N m / (rad s); zero gives PD.
    #[serde(default)]
    pub ki: [f64; 3],
    /// Derivative gains, N m s / rad.
    #[serde(default = "default_kd")]
    pub kd: [f64; 3],
    /// Torque limit per joint, N m (the Omni's 3.3 N at its 0.132 m arm: ~0.44 N m).
    #[serde(default = "default_torque_limit")]
    pub torque_limit: [f64; 3],
}

fn default_kp() -> [f64; 3] {
    [6.0; 3]
}
fn default_kd() -> [f64; 3] {
    [0.12; 3]
}
fn default_torque_limit() -> [f64; 3] {
    [0.45; 3]
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig {
            kp: default_kp(),
            ki: [0.0; 3],
            kd: default_kd(),
            torque_limit: default_torque_limit(),
        }
    }
}

/// Per-joint inertia and viscous damping, integrated at a fixed step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsConfig {
    /// Inertia per joint, kg m^2.
    #[serde(default = "default_inertia")]
    pub inertia: [f64; 3],
    /// Viscous damping per joint, N m s / rad.
    #[serde(default = "default_damping")]
    pub damping: [f64; 3],
    /// Integration step, seconds, at most 0.01; each sample integrates t_s in steps of
    /// at most this (one step of t_s when t_s is shorter).
    #[serde(default = "default_step")]
    pub step_s: f64,
}

fn default_inertia() -> [f64; 3] {
    [2.0e-3; 3]
}
fn default_damping() -> [f64; 3] {
    [5.0e-3; 3]
}
fn default_step() -> f64 {
    2.5e-4
}

impl Default for DynamicsConfig {
    fn default() -> Self {
        DynamicsConfig {
            inertia: default_inertia(),
            damping: default_damping(),
            step_s: default_step(),
        }
    }
}

/// The slave's environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Environment {
    /// Objects; the one the tool penetrates most deeply produces the contact force.
    #[serde(default)]
    pub objects: Vec<Object>,
}

/// A rigid object with a stiffness per axis (the paper's h_x, h_y, h_z).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Object {
    /// Half-space behind a plane: contact when (p - point) . normal < 0.
    Plane {
        /// A point on the plane, metres.
        point: [f64; 3],
        /// Outward normal (normalised on load).
        normal: [f64; 3],
        /// Stiffness per axis, N/m.
        stiffness: [f64; 3],
    },
    /// Solid sphere.
    Sphere {
        /// Centre, metres.
        center: [f64; 3],
        /// Radius, metres.
        radius: f64,
        /// Stiffness per axis, N/m.
        stiffness: [f64; 3],
    },
    /// Solid axis-aligned box.
    Box {
        /// Centre, metres.
        center: [f64; 3],
        /// Half extents along x, y, z, metres.
        half_extents: [f64; 3],
        /// Stiffness per axis, N/m.
        stiffness: [f64; 3],
    },
}

/// The PHANToM Omni's nominal maximum stiffness, N/m (0.7 N/mm): above it a scenario
/// loads with a warning (the device cannot render it without buzzing).
pub const NOMINAL_MAX_STIFFNESS: f64 = 700.0;
/// Stiffness refused outright, N/m: ten times the nominal maximum.
pub const MAX_STIFFNESS: f64 = 10.0 * NOMINAL_MAX_STIFFNESS;

impl Object {
    /// Stiffness per axis.
    pub fn stiffness(&self) -> [f64; 3] {
        match self {
            Object::Plane { stiffness, .. }
            | Object::Sphere { stiffness, .. }
            | Object::Box { stiffness, .. } => *stiffness,
        }
    }
}

fn finite3(v: &[f64; 3], field: &str) -> Result<(), ScenarioError> {
    for (i, x) in v.iter().enumerate() {
        if !x.is_finite() {
            return Err(invalid(
                format!("{field}[{i}]"),
                format!("{x} is not a finite number"),
            ));
        }
    }
    Ok(())
}

pub(crate) fn positive3(v: &[f64; 3], field: &str, allow_zero: bool) -> Result<(), ScenarioError> {
    finite3(v, field)?;
    for (i, x) in v.iter().enumerate() {
        if *x < 0.0 || (!allow_zero && *x == 0.0) {
            let want = if allow_zero {
                "non-negative"
            } else {
                "positive"
            };
            return Err(invalid(
                format!("{field}[{i}]"),
                format!("{x} must be {want}"),
            ));
        }
    }
    Ok(())
}

/// A TOML error as one line: `line L, column C: message`.
pub fn one_line(text: &str, e: &toml::de::Error) -> String {
    let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("line {line}, column {column}: {msg}")
        }
        None => msg,
    }
}

impl Scenario {
    /// The paper scenario (`deploy/scenarios/paper.toml` holds the same values).
    pub fn paper() -> Scenario {
        Scenario {
            name: "paper".into(),
            mode: Mode::Realtime,
            rate_hz: default_rate(),
            samples: default_samples(),
            arithmetic: ArithKind::Hybrid,
            cordic: CordicSettings::default(),
            device: DeviceChoice::default(),
            seed: 1,
            operator: Operator::Paper,
            network: Network::default(),
            master: MasterConfig::default(),
            slave: SlaveConfig::default(),
            faults: FaultConfig::default(),
            control: ControlConfig::default(),
            codec: crate::codec::Codecs::default(),
            environment: Environment {
                objects: vec![Object::Plane {
                    point: [0.0, 0.0, -0.16],
                    normal: [0.0, 0.0, 1.0],
                    stiffness: [300.0; 3],
                }],
            },
        }
    }

    /// Parses TOML and validates every range.
    pub fn from_toml_str(text: &str) -> Result<Scenario, ScenarioError> {
        let s: Scenario =
            toml::from_str(text).map_err(|e| ScenarioError::Parse(one_line(text, &e)))?;
        s.validate()?;
        Ok(s)
    }

    /// The same scenario with every relative path made absolute against `base_dir`
    /// (the scenario file's folder), so a copy of it runs from any folder.
    pub fn resolved(&self, base_dir: &std::path::Path) -> Scenario {
        let mut s = self.clone();
        let absolute = |path: &mut String| {
            let p = std::path::Path::new(path.as_str());
            if p.is_relative() {
                *path = base_dir.join(p).display().to_string();
            }
        };
        if let Operator::Csv { path } = &mut s.operator {
            absolute(path);
        }
        for c in [&mut s.network.forward, &mut s.network.backward] {
            if let Some(r) = &mut c.replay {
                absolute(&mut r.path);
            }
        }
        s
    }

    /// The scenario as TOML text (what a run's `scenario.toml` holds).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_else(|e| format!("# cannot encode the scenario: {e}\n"))
    }

    /// Things that load but deserve a word: stiffness above the device's nominal
    /// maximum.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        for (k, o) in self.environment.objects.iter().enumerate() {
            for (i, h) in o.stiffness().iter().enumerate() {
                if *h > NOMINAL_MAX_STIFFNESS {
                    w.push(format!(
                        "environment.objects[{k}].stiffness[{i}] = {h} N/m is above the device's nominal {NOMINAL_MAX_STIFFNESS} N/m: contact may buzz"
                    ));
                }
            }
        }
        w
    }

    /// Sampling period t_s in seconds.
    pub fn t_s(&self) -> f64 {
        1.0 / self.rate_hz
    }

    /// Sampling period in nanoseconds.
    pub fn t_s_ns(&self) -> u64 {
        (1e9 / self.rate_hz).round() as u64
    }

    /// Checks every value is in range; the error names the field.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if !self.rate_hz.is_finite() || !(100.0..=10_000.0).contains(&self.rate_hz) {
            return Err(invalid(
                "rate_hz",
                format!("{} Hz is outside 100..=10000 Hz", self.rate_hz),
            ));
        }
        if self.samples == 0 || self.samples > 100_000_000 {
            return Err(invalid(
                "samples",
                format!("{} is outside 1..=100000000", self.samples),
            ));
        }
        self.cordic.config()?;
        self.device.geometry()?;
        match &self.operator {
            Operator::Paper => {}
            Operator::Circle {
                center,
                radius,
                period_s,
                plane,
            }
            | Operator::FigureEight {
                center,
                size: radius,
                period_s,
                plane,
            } => {
                finite3(center, "operator.center")?;
                if !radius.is_finite() || *radius <= 0.0 || *radius > 1.0 {
                    return Err(invalid(
                        "operator.radius",
                        format!("{radius} m is outside (0, 1] m"),
                    ));
                }
                if !period_s.is_finite() || *period_s <= 0.0 {
                    return Err(invalid(
                        "operator.period_s",
                        format!("{period_s} must be positive"),
                    ));
                }
                if !["xy", "yz", "xz"].contains(&plane.as_str()) {
                    return Err(invalid(
                        "operator.plane",
                        format!("{plane:?} is not xy, yz or xz"),
                    ));
                }
            }
            Operator::Press { from, to, move_s } => {
                finite3(from, "operator.from")?;
                finite3(to, "operator.to")?;
                if !move_s.is_finite() || *move_s <= 0.0 {
                    return Err(invalid(
                        "operator.move_s",
                        format!("{move_s} must be positive"),
                    ));
                }
            }
            Operator::Csv { path } => {
                if path.is_empty() {
                    return Err(invalid("operator.path", "is empty"));
                }
            }
        }
        self.master.hand.validate()?;
        self.master.device.validate()?;
        self.control.validate()?;
        self.codec.forward.validate("codec.forward")?;
        self.codec.backward.validate("codec.backward")?;
        self.master.predictor.validate("master.predictor")?;
        self.slave.predictor.validate("slave.predictor")?;
        self.network.forward.validate("network.forward")?;
        self.network.backward.validate("network.backward")?;
        let c = &self.slave.controller;
        positive3(&c.kp, "slave.controller.kp", true)?;
        positive3(&c.ki, "slave.controller.ki", true)?;
        positive3(&c.kd, "slave.controller.kd", true)?;
        positive3(&c.torque_limit, "slave.controller.torque_limit", false)?;
        let d = &self.slave.dynamics;
        positive3(&d.inertia, "slave.dynamics.inertia", false)?;
        positive3(&d.damping, "slave.dynamics.damping", true)?;
        // A sample shorter than the step is integrated in one step of t_s; a step
        // longer than 10 ms makes the default joints' integration unstable.
        if !d.step_s.is_finite() || d.step_s < 1e-6 || d.step_s > 0.01 {
            return Err(invalid(
                "slave.dynamics.step_s",
                format!("{} s is outside 1 us to 10 ms", d.step_s),
            ));
        }
        if !self.master.force_limit.is_finite() || self.master.force_limit <= 0.0 {
            return Err(invalid(
                "master.force_limit",
                format!("{} N must be positive", self.master.force_limit),
            ));
        }
        positive3(&self.master.torque_limit, "master.torque_limit", false)?;
        if self.faults.peer_timeout_samples == 0 {
            return Err(invalid("faults.peer_timeout_samples", "must be at least 1"));
        }
        for (k, o) in self.environment.objects.iter().enumerate() {
            let f = format!("environment.objects[{k}]");
            positive3(&o.stiffness(), &format!("{f}.stiffness"), true)?;
            for (i, h) in o.stiffness().iter().enumerate() {
                if *h > MAX_STIFFNESS {
                    return Err(invalid(
                        format!("{f}.stiffness[{i}]"),
                        format!("{h} N/m is above {MAX_STIFFNESS} N/m, ten times the device's nominal maximum"),
                    ));
                }
            }
            match o {
                Object::Plane { point, normal, .. } => {
                    finite3(point, &format!("{f}.point"))?;
                    finite3(normal, &format!("{f}.normal"))?;
                    if normal.iter().map(|v| v * v).sum::<f64>() < 1e-12 {
                        return Err(invalid(
                            format!("{f}.normal"),
                            "must not be the zero vector",
                        ));
                    }
                }
                Object::Sphere { center, radius, .. } => {
                    finite3(center, &format!("{f}.center"))?;
                    if !radius.is_finite() || *radius <= 0.0 {
                        return Err(invalid(
                            format!("{f}.radius"),
                            format!("{radius} must be positive"),
                        ));
                    }
                }
                Object::Box {
                    center,
                    half_extents,
                    ..
                } => {
                    finite3(center, &format!("{f}.center"))?;
                    positive3(half_extents, &format!("{f}.half_extents"), false)?;
                }
            }
        }
        Ok(())
    }
}
