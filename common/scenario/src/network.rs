//! `[network.forward]`, `[network.backward]`: each channel's delay, noise, loss and
//! the netem-class models and replays (their behaviour is in `tactile-netem`; their
//! settings and ranges are here).

use crate::histogram::HistogramConfig;
use crate::link::LinkConfig;
use crate::shown::Num;
use crate::{invalid, ScenarioError};
use serde::{Deserialize, Serialize};

/// Both channels of the emulated network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Network {
    /// Master to slave: positions c(n) -> v(n).
    pub forward: ChannelConfig,
    /// Slave to master: forces h(n) -> q(n).
    pub backward: ChannelConfig,
}

/// One channel: v_i(n) = c_i(n - d_i(n)) + r_i(n).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChannelConfig {
    /// Constant delay per signal (x, y, z), in whole samples.
    pub delay: [i64; 3],
    /// Optional schedule overriding `delay`: `[[from_sample, dx, dy, dz], ...]`, sorted by
    /// `from_sample`; each entry holds from its sample until the next.
    pub schedule: Vec<[i64; 4]>,
    /// Standard deviation of the zero-mean Gaussian noise per signal (m forward, N back).
    pub noise_std: [f64; 3],
    /// Probability that the emulator drops a sample on purpose, 0 to 1 (seeded).
    pub loss: f64,
    /// Fault injection: probability that the emulator replaces a sample's values with
    /// NaN, 0 to 1 (seeded), to prove the receivers reject them.
    pub corrupt: f64,
    /// Jitter on each packet's delay, netem's `delay D JITTER CORRELATION
    /// distribution NAME` with D the `delay` above (all in samples).
    pub jitter: Option<JitterConfig>,
    /// Whether a packet may overtake an earlier one when jitter shortens its delay
    /// (netem's behaviour) [true]; false keeps arrivals in sending order.
    pub reorder: bool,
    /// A loss model instead of `loss` (netem's random loss): `gemodel` or `state`.
    pub loss_model: Option<LossModel>,
    /// A recorded network replayed packet by packet, instead of `delay`, `schedule`
    /// and `jitter`.
    pub replay: Option<ReplayConfig>,
    /// Probability that a packet is sent twice, netem's `duplicate` (the copy takes
    /// its own jitter), 0 to 1 [0].
    pub duplicate: f64,
    /// Each packet's whole delay drawn from a measured distribution, instead of
    /// `delay`, `schedule`, `jitter` and `replay` (`crate::histogram`).
    pub delay_histogram: Option<HistogramConfig>,
    /// A link with a rate and a queue (mm-link's), instead of `delay`, `schedule`,
    /// `jitter`, `duplicate` and `replay`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link: Option<LinkConfig>,
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
            reorder: true,
            loss_model: None,
            replay: None,
            duplicate: 0.0,
            delay_histogram: None,
            link: None,
        }
    }
}

/// Largest delay accepted, in samples: ten seconds at the highest rate.
pub const MAX_DELAY_SAMPLES: i64 = 100_000;

/// A delay a channel can apply: non-negative, at most [`MAX_DELAY_SAMPLES`].
fn check_delay(d: i64, f: String) -> Result<(), ScenarioError> {
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
}

impl ChannelConfig {
    pub(crate) fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        self.validate_delays(field)?;
        self.validate_faults(field)?;
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
        if let Some(h) = &self.delay_histogram {
            h.validate(field)?;
            self.histogram_alone(field)?;
        }
        if let Some(l) = &self.link {
            l.validate(field)?;
            let alone = self.jitter.is_none()
                && self.schedule.is_empty()
                && self.delay == [0; 3]
                && self.replay.is_none()
                && self.duplicate == 0.0
                && self.delay_histogram.is_none();
            if !alone {
                return Err(invalid(
                    format!("{field}.link"),
                    "gives each packet's delay: leave delay at [0, 0, 0], and schedule, jitter, duplicate, replay and delay_histogram out",
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

    /// A histogram gives each packet's whole delay: the other delay models are left
    /// out (the first one set is named).
    fn histogram_alone(&self, field: &str) -> Result<(), ScenarioError> {
        let other = [
            ("delay", self.delay != [0; 3]),
            ("schedule", !self.schedule.is_empty()),
            ("jitter", self.jitter.is_some()),
            ("replay", self.replay.is_some()),
            ("link", self.link.is_some()),
        ];
        match other.iter().find(|(_, set)| *set) {
            Some((key, _)) => Err(invalid(
                format!("{field}.delay_histogram"),
                format!("and `{field}.{key}` both set: the histogram gives each packet's whole delay; leave delay at [0, 0, 0] (or delay_ms at 0), and schedule, jitter, replay and link out"),
            )),
            None => Ok(()),
        }
    }

    /// The delays and the schedule's: each one a channel can apply, the schedule's
    /// samples increasing.
    fn validate_delays(&self, field: &str) -> Result<(), ScenarioError> {
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
        Ok(())
    }

    /// The probabilities and the noise: each in its range.
    fn validate_faults(&self, field: &str) -> Result<(), ScenarioError> {
        for (name, p) in [
            ("loss", self.loss),
            ("corrupt", self.corrupt),
            ("duplicate", self.duplicate),
        ] {
            if !p.is_finite() || !(0.0..=1.0).contains(&p) {
                return Err(invalid(
                    format!("{field}.{name}"),
                    format!("{} is not a probability in [0, 1]", Num(p)),
                ));
            }
        }
        for (i, s) in self.noise_std.iter().enumerate() {
            if !s.is_finite() || *s < 0.0 {
                return Err(invalid(
                    format!("{field}.noise_std[{i}]"),
                    format!(
                        "{} must be a finite, non-negative standard deviation",
                        Num(*s)
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// netem's jitter distributions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum JitterDistribution {
    /// Uniform on delay +- jitter (netem's default when no distribution is named).
    #[default]
    Uniform,
    /// Normal, standard deviation `jitter`.
    Normal,
    /// Pareto (shape 3, the heavy right tail of queueing), shifted to mean zero and
    /// scaled to standard deviation `jitter`.
    Pareto,
    /// netem's paretonormal: a quarter normal and three quarters Pareto, mean zero,
    /// standard deviation `jitter` (here the two parts move together, so the
    /// correlation carries through).
    Paretonormal,
}

/// `jitter = { jitter = J, correlation = C, distribution = "normal" }`: the delay of
/// each packet is `delay + X`, X drawn as netem draws it, in samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JitterConfig {
    /// Spread, samples: half-width for uniform, standard deviation otherwise.
    pub jitter: f64,
    /// Correlation of successive packets' jitter, 0 to 1 (lag-1, of the driving
    /// Gaussian process) [0].
    #[serde(default)]
    pub correlation: f64,
    /// `uniform`, `normal`, `pareto` or `paretonormal` [uniform].
    #[serde(default)]
    pub distribution: JitterDistribution,
}

/// Loss models beyond netem's `random` (which is the channel's `loss`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum LossModel {
    /// Gilbert-Elliott, netem's `gemodel p r 1-h 1-k`: a good and a bad state; p the
    /// probability of going bad, r of recovering; a packet is lost with probability
    /// `1 - k` in the good state [0] and `1 - h` in the bad state [1]. With the
    /// defaults it is the simple Gilbert model: loss rate p/(p+r), mean burst 1/r.
    Gemodel {
        /// Good to bad.
        p: f64,
        /// Bad to good.
        r: f64,
        /// Loss probability in the bad state, netem's `1-h` [1].
        #[serde(default = "one")]
        bad_loss: f64,
        /// Loss probability in the good state, netem's `1-k` [0].
        #[serde(default)]
        good_loss: f64,
    },
    /// netem's 4-state model: 1 good reception, 2 good reception within a burst, 3
    /// burst loss, 4 isolated loss. Lost in states 3 and 4.
    State {
        /// 1 to 3.
        p13: f64,
        /// 3 to 1.
        p31: f64,
        /// 3 to 2 [0].
        #[serde(default)]
        p32: f64,
        /// 2 to 3 [0].
        #[serde(default)]
        p23: f64,
        /// 1 to 4 [0].
        #[serde(default)]
        p14: f64,
    },
}

fn one() -> f64 {
    1.0
}

fn probability(v: f64, field: &str) -> Result<(), ScenarioError> {
    if !v.is_finite() || !(0.0..=1.0).contains(&v) {
        return Err(invalid(
            field,
            format!("{} is not a probability in [0, 1]", Num(v)),
        ));
    }
    Ok(())
}

/// Jitter beyond this many spreads is cut off (a Pareto tail is unbounded; the delay
/// line must not be). For Pareto and paretonormal the cut is part of the shape, whose
/// scale then gives the configured spread exactly.
pub const JITTER_CAP: f64 = 10.0;

impl JitterConfig {
    /// Checks the ranges; errors name `FIELD.jitter.*`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        if !self.jitter.is_finite() || self.jitter < 0.0 || self.jitter > 10_000.0 {
            return Err(invalid(
                format!("{field}.jitter.jitter"),
                format!("{} samples is outside 0..=10000", Num(self.jitter)),
            ));
        }
        let c = self.correlation;
        if !c.is_finite() || !(0.0..1.0).contains(&c) {
            return Err(invalid(
                format!("{field}.jitter.correlation"),
                format!("{} is outside [0, 1)", Num(c)),
            ));
        }
        Ok(())
    }

    /// The largest jitter it can add, samples (the cut shapes, rescaled, stay within
    /// twice the cap).
    pub fn bound(&self) -> f64 {
        2.0 * JITTER_CAP * self.jitter
    }
}

impl LossModel {
    /// Checks the probabilities; errors name `FIELD.loss_model.*`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        let f = |k: &str| format!("{field}.loss_model.{k}");
        match self {
            LossModel::Gemodel {
                p,
                r,
                bad_loss,
                good_loss,
            } => {
                for (k, v) in [
                    ("p", p),
                    ("r", r),
                    ("bad_loss", bad_loss),
                    ("good_loss", good_loss),
                ] {
                    probability(*v, &f(k))?;
                }
            }
            LossModel::State {
                p13,
                p31,
                p32,
                p23,
                p14,
            } => {
                for (k, v) in [
                    ("p13", p13),
                    ("p31", p31),
                    ("p32", p32),
                    ("p23", p23),
                    ("p14", p14),
                ] {
                    probability(*v, &f(k))?;
                }
                if p13 + p14 > 1.0 {
                    return Err(invalid(
                        f("p14"),
                        format!("p13 + p14 = {} exceeds 1", Num(p13 + p14)),
                    ));
                }
                if p31 + p32 > 1.0 {
                    return Err(invalid(
                        f("p32"),
                        format!("p31 + p32 = {} exceeds 1", Num(p31 + p32)),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// `replay = { path = "...", format = "csv" }`: a recorded network, packet by packet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReplayConfig {
    /// The file, relative to the scenario's folder.
    pub path: String,
    /// `csv`: header `delay,lost`, one row per packet (delay in samples, lost 0 or 1),
    /// looped; `mahimahi`: Mahimahi's delivery trace, run as `link = { path }` (mm-link
    /// with its default, infinite, queue) [csv].
    #[serde(default)]
    pub format: ReplayFormat,
    /// Refused: the old Mahimahi replay's packet size, replaced by the link's
    /// `payload_bytes` and `header_bytes`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub packet_bytes: Option<u32>,
    /// Refused: the old Mahimahi replay's bound by waiting time, which mm-link does not
    /// have; replaced by the link's `queue`, `packets` and `bytes`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_queue_samples: Option<u32>,
}

/// Replay formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ReplayFormat {
    /// Per-packet delays and losses.
    #[default]
    Csv,
    /// Mahimahi's delivery opportunities.
    Mahimahi,
}

impl ReplayConfig {
    /// Checks the fields; errors name `FIELD.replay.*`. The old Mahimahi replay's keys
    /// are refused with the keys that replace them: the link now runs mm-link's
    /// algorithm (1504-byte opportunities that carry a packet's remaining bytes over,
    /// a queue bounded in packets or bytes), which they cannot describe.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        if self.path.is_empty() {
            return Err(invalid(format!("{field}.replay.path"), "is empty"));
        }
        if self.packet_bytes.is_some() {
            return Err(invalid(
                format!("{field}.replay.packet_bytes"),
                "is no longer read: write link = { path = \"...\", payload_bytes = P, header_bytes = H } (a packet is P + H bytes on the wire; 250 + 28 by default)",
            ));
        }
        if self.max_queue_samples.is_some() {
            return Err(invalid(
                format!("{field}.replay.max_queue_samples"),
                "is no longer read: mm-link bounds its queue by size, not waiting time; write link = { path = \"...\", queue = \"droptail\", packets = N } (or bytes = B)",
            ));
        }
        Ok(())
    }
}
