//! `[control]`, `[codec.*]` and `[*.predictor]`: the channel's stability control, the
//! deadband codecs and the predictors, as the scenario sets them (their behaviour is in
//! `tactile-control`).

use crate::shown::Num;
use crate::{invalid, positive, ScenarioError};
use serde::{Deserialize, Serialize};

/// Stability control on the channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ControlKind {
    /// Positions forward, forces back, nothing else (observers still watch).
    #[default]
    None,
    /// Time-domain passivity approach, two-port, position-force architecture.
    Tdpa,
    /// Wave variables with an impedance-matched slave.
    Wave,
    /// Model-mediated teleoperation: the slave estimates the wall it touches and sends
    /// the model; the master renders it locally.
    Mmt,
}

impl ControlKind {
    /// The name used in scenarios and reports.
    pub fn name(self) -> &'static str {
        match self {
            ControlKind::None => "none",
            ControlKind::Tdpa => "tdpa",
            ControlKind::Wave => "wave",
            ControlKind::Mmt => "mmt",
        }
    }
}

/// `[control]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControlConfig {
    /// `none`, `tdpa`, `wave` or `mmt`.
    pub kind: ControlKind,
    /// Wave impedance b, N s/m: larger feels stiffer contact and more damping in free
    /// motion.
    pub wave_impedance: f64,
    /// TDPA: speeds below this count as this when the master's passivity controller
    /// computes its damping (v^2 in a denominator), m/s.
    pub velocity_floor: f64,
    /// TDPA: the largest damping the master's passivity controller adds, N s/m; a
    /// deficit it cannot remove at once is carried to the next samples.
    pub max_damping: f64,
    /// TDPA: the fastest the slave's reference is pulled back towards the master's
    /// position when energy allows (position drift compensation), m/s; 0 disables it.
    pub drift_rate: f64,
    /// `[control.mmt]`: the model's estimator and renderer.
    pub mmt: MmtConfig,
}

/// `[control.mmt]`: model-mediated teleoperation's settings. The defaults estimate the
/// shipped walls (300 to 600 N/m) to within 2 % in well under a second of contact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MmtConfig {
    /// The estimator's forgetting factor per sample, at most 1: 1 remembers every
    /// contact sample; 0.995 weighs the last 200 (0.2 s at 1 kHz) [0.995]. Its memory,
    /// 1/(1 - forgetting) samples, must be at least [`MIN_MEMORY_SAMPLES`] and at
    /// least `min_contacts` (a model waits for that many samples; one from a shorter
    /// memory rests on fewer): 0.95 at the defaults. Below that the model follows
    /// each sample's force, not a wall: on `wall-change.toml` 245 models are sent at
    /// 0.95, 513 at 0.9 and 2,170 at 1e-300 (32 at 0.995); the renderer keeps them
    /// from kicking the hand (largest felt step 0.063 N down to 0.8, 0.09 N at
    /// 1e-300; docs/05).
    pub forgetting: f64,
    /// A contact force above this is contact, below it free motion, N [0.05].
    pub contact_force: f64,
    /// The stiffness assumed at first contact, before the data says otherwise, N/m [300].
    pub prior_stiffness: f64,
    /// Samples in contact before the first model is sent [20].
    pub min_contacts: u32,
    /// A model is sent again when its stiffness changed by more than this fraction
    /// [0.02] ...
    pub stiffness_change: f64,
    /// ... or its surface moved by more than this, m [0.0002] ...
    pub offset_change: f64,
    /// ... or its normal turned by more than this, rad [0.02].
    pub angle_change: f64,
    /// How fast the felt force may change while the master's rendered surface returns
    /// to the model's with the handle inside the wall, N/s [50: 50 mN a sample at 1 kHz;
    /// the Omni's 3.3 N in 66 ms].
    pub force_rate: f64,
    /// How a changed model is taken while the handle is inside: `blend` (towards the
    /// model at `force_rate` either way, the energy added booked) or `passive` (only changes
    /// that add no energy; the rest wait until the handle leaves the wall) [blend].
    pub update: MmtUpdate,
    /// What the slave does with the master's position: `follow` it (as `none`) or pass
    /// it through TDPA's slave side, which bounds the energy the slave puts into the
    /// wall by what the master's port put in, and pulls the drift back with what is
    /// left (`control.velocity_floor`, `max_damping`, `drift_rate` apply) [follow].
    pub slave: MmtSlave,
}

/// `control.mmt.slave`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MmtSlave {
    /// The received position is the slave's reference.
    #[default]
    Follow,
    /// TDPA's passive slave reference.
    Tdpa,
}

/// `control.mmt.update`: how the master takes a changed model while the handle is in
/// the wall (`tactile_control::mmt::ModelRenderer` says what each does).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MmtUpdate {
    /// Blended in at a bounded rate; the energy it adds is booked.
    #[default]
    Blend,
    /// The energy check: nothing that adds energy at the handle.
    Passive,
}

impl Default for MmtConfig {
    fn default() -> Self {
        MmtConfig {
            forgetting: 0.995,
            contact_force: 0.05,
            prior_stiffness: 300.0,
            min_contacts: 20,
            stiffness_change: 0.02,
            offset_change: 2.0e-4,
            angle_change: 0.02,
            force_rate: 50.0,
            update: MmtUpdate::Blend,
            slave: MmtSlave::Follow,
        }
    }
}

/// The fewest samples the MMT estimator may remember (1/(1 - forgetting)): the
/// default `min_contacts` (`control.mmt.forgetting`'s documentation has the figures).
pub const MIN_MEMORY_SAMPLES: u32 = 20;

impl MmtConfig {
    /// The smallest `forgetting` allowed: a memory of [`MIN_MEMORY_SAMPLES`] and of
    /// `min_contacts` samples.
    pub fn min_forgetting(&self) -> f64 {
        1.0 - 1.0 / f64::from(self.min_contacts.max(MIN_MEMORY_SAMPLES))
    }

    /// Checks the ranges; errors name `control.mmt.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if self.min_contacts == 0 {
            return Err(invalid("control.mmt.min_contacts", "must be at least 1"));
        }
        let floor = self.min_forgetting();
        if !(self.forgetting >= floor && self.forgetting <= 1.0) {
            let memory = if self.forgetting < 1.0 {
                let m = 1.0 / (1.0 - self.forgetting);
                format!(
                    "it remembers about {} samples (1/(1 - forgetting)), and ",
                    Num((m * 10.0).round() / 10.0)
                )
            } else {
                String::new()
            };
            return Err(invalid(
                "control.mmt.forgetting",
                format!(
                    "{} is outside [{}, 1]: {memory}the estimator must remember at least {} samples ({MIN_MEMORY_SAMPLES}, and control.mmt.min_contacts = {}), or its model follows each sample's force",
                    Num(self.forgetting),
                    Num(floor),
                    self.min_contacts.max(MIN_MEMORY_SAMPLES),
                    self.min_contacts
                ),
            ));
        }
        positive(self.contact_force, "control.mmt.contact_force", false)?;
        positive(self.stiffness_change, "control.mmt.stiffness_change", false)?;
        positive(self.offset_change, "control.mmt.offset_change", false)?;
        positive(self.angle_change, "control.mmt.angle_change", false)?;
        positive(self.force_rate, "control.mmt.force_rate", false)
    }
}

impl Default for ControlConfig {
    fn default() -> Self {
        ControlConfig {
            kind: ControlKind::None,
            wave_impedance: 10.0,
            // Measured on wall-delay over floors 1e-5..1e-3 m/s and caps 200..1e4 N s/m: these
            // kept the channel's energy closest to zero without a codec (docs/05-control.md). Larger caps make
            // the force chatter between full and zero, and the sampling's prediction error grows.
            velocity_floor: 1.0e-3,
            max_damping: 200.0,
            drift_rate: 0.05,
            mmt: MmtConfig::default(),
        }
    }
}

impl ControlConfig {
    /// Checks the ranges; errors name `control.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        positive(self.wave_impedance, "control.wave_impedance", false)?;
        positive(self.velocity_floor, "control.velocity_floor", false)?;
        positive(self.max_damping, "control.max_damping", false)?;
        positive(self.drift_rate, "control.drift_rate", true)?;
        self.mmt.validate()
    }
}
/// `[codec.forward]`, `[codec.backward]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CodecConfig {
    /// `none`, `deadband` or `adaptive` [none].
    pub kind: CodecKind,
    /// Weber fraction k [0.1].
    pub k: f64,
    /// Absolute threshold near zero, in the signal's unit (m forward, N backward)
    /// [0.0005 forward, 0.02 backward when left at 0].
    pub floor: f64,
    /// Adaptive: the speed at which the fraction doubles, m/s [0.05].
    pub v_ref: f64,
}

/// The codec's kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum CodecKind {
    /// Every sample is sent.
    #[default]
    None,
    /// Weber deadband with a fixed fraction.
    Deadband,
    /// Velocity-adaptive deadband.
    Adaptive,
}

impl Default for CodecConfig {
    fn default() -> Self {
        CodecConfig {
            kind: CodecKind::None,
            k: 0.1,
            floor: 0.0,
            v_ref: 0.05,
        }
    }
}

/// Both directions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Codecs {
    /// Master to slave (positions).
    pub forward: CodecConfig,
    /// Slave to master (forces).
    pub backward: CodecConfig,
}

impl CodecConfig {
    /// Checks the ranges; errors name `FIELD.*`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        if !self.k.is_finite() || !(0.0..=10.0).contains(&self.k) {
            return Err(invalid(
                format!("{field}.k"),
                format!("{} is outside 0..=10", Num(self.k)),
            ));
        }
        for (name, v) in [("floor", self.floor), ("v_ref", self.v_ref)] {
            if !v.is_finite() || v < 0.0 || (name == "v_ref" && v == 0.0) {
                return Err(invalid(
                    format!("{field}.{name}"),
                    format!("{} must be positive", Num(v)),
                ));
            }
        }
        Ok(())
    }
}

/// `[slave.predictor]`, `[master.predictor]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PredictorConfig {
    /// `hold`, `linear` or `kalman` [hold].
    pub kind: PredictorKind,
    /// Kalman: the white acceleration's spectral density (per second, squared units
    /// per s^3) [1.0].
    pub process_noise: f64,
    /// Kalman: the measurement's variance, squared units [1e-8].
    pub measurement_noise: f64,
    /// Values farther than this from the last accepted one per second are not
    /// physically possible and are rejected (m/s forward, N/s backward) [100 m/s,
    /// 1e5 N/s when left at 0: generous, so noise and stiff contacts pass, garbage
    /// does not].
    pub max_rate: f64,
    /// Linear and Kalman: the longest they extrapolate, s; past it they hold [0.05]
    /// (a codec's silence means "within the deadband", not "going on for ever").
    pub horizon_s: f64,
}

/// The predictors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PredictorKind {
    /// The last value received.
    #[default]
    Hold,
    /// Straight on from the last two values received.
    Linear,
    /// A constant-velocity Kalman filter per axis.
    Kalman,
}

impl Default for PredictorConfig {
    fn default() -> Self {
        PredictorConfig {
            kind: PredictorKind::Hold,
            process_noise: 1.0,
            measurement_noise: 1e-8,
            max_rate: 0.0,
            horizon_s: 0.05,
        }
    }
}

impl PredictorConfig {
    /// Checks the ranges; errors name `FIELD.*`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        for (name, v) in [
            ("process_noise", self.process_noise),
            ("measurement_noise", self.measurement_noise),
        ] {
            if !v.is_finite() || v <= 0.0 || v > 1e12 {
                return Err(invalid(
                    format!("{field}.{name}"),
                    format!("{} is outside (0, 1e12]", Num(v)),
                ));
            }
        }
        if !self.horizon_s.is_finite() || !(0.0..=10.0).contains(&self.horizon_s) {
            return Err(invalid(
                format!("{field}.horizon_s"),
                format!("{} s is outside 0..=10 s", Num(self.horizon_s)),
            ));
        }
        if !self.max_rate.is_finite() || self.max_rate < 0.0 {
            return Err(invalid(
                format!("{field}.max_rate"),
                format!("{} must be non-negative", Num(self.max_rate)),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::overrides::{apply, Set};
    use crate::Scenario;

    fn read(sets: &[&str]) -> Result<Scenario, String> {
        let sets: Vec<Set> = sets.iter().map(|s| Set::parse(s).expect("set")).collect();
        Scenario::from_toml_str(&apply("", &sets).expect("applied")).map_err(|e| e.to_string())
    }

    /// `forgetting = 1e-300` was accepted: the estimator forgot everything every
    /// sample, and the felt force stepped 1.24 N on wall-change.toml.
    #[test]
    fn forgetting_keeps_a_memory_of_the_samples_a_model_waits_for() {
        let e = read(&["control.mmt.forgetting=1e-300"]).expect_err("no memory");
        assert!(
            e.contains("field `control.mmt.forgetting`: 1e-300 is outside [0.95, 1]")
                && e.contains("about 1 samples"),
            "{e}"
        );
        read(&["control.mmt.forgetting=0.95"]).expect("20 samples");
        read(&["control.mmt.forgetting=1.0"]).expect("remembers all");
        read(&["control.mmt.forgetting=0.949"]).expect_err("under 20 samples");
        // A model that waits for 100 samples needs a memory of 100.
        let e = read(&[
            "control.mmt.min_contacts=100",
            "control.mmt.forgetting=0.98",
        ])
        .expect_err("50 samples");
        assert!(
            e.contains("[0.99, 1]") && e.contains("min_contacts = 100"),
            "{e}"
        );
        read(&[
            "control.mmt.min_contacts=100",
            "control.mmt.forgetting=0.99",
        ])
        .expect("100");
        // Fewer contacts than the floor do not lower it.
        read(&["control.mmt.min_contacts=2", "control.mmt.forgetting=0.9"])
            .expect_err("10 samples");
    }
}
