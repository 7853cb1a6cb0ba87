//! The simulated operator as a person (`[master.human]`): where along its path the
//! hand is and how far off it, sample by sample. A path is what a person means to do;
//! this adds what a person also does: a physiological tremor (band-limited noise), a
//! slow wander (an Ornstein-Uhlenbeck process), and a reaction to a felt force that
//! comes a reaction time after the force does (a pause, a stop, or backing off).
//! Each draws from its own random stream of the run's seed, so turning one on leaves
//! the others' draws as they were, and the same seed gives the same hand.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use tactile_scenario::{HumanConfig, Response};

/// The random streams of the master's operator, apart from the emulator's (1 to 502).
const TREMOR_STREAM: u64 = 600;
const DRIFT_STREAM: u64 = 601;
const REACTION_STREAM: u64 = 602;

/// One sample of the person: how far along the path the hand is (the path's sample
/// number) and how far off it, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sway {
    /// The path's sample the hand is at (behind the run's when it has paused).
    pub progress: u64,
    /// Tremor, wander and back-off together, m.
    pub offset: [f64; 3],
}

/// What the person is doing about a felt force.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Reaction {
    /// Following the path; `armed` once the force has fallen below half `contact_n`
    /// since the last reaction, so a lasting contact is reacted to once.
    Following { armed: bool },
    /// A force was felt; the response starts at sample `at`, along `dir`.
    Noticing { at: u64, dir: [f64; 3] },
    /// Responding since sample `since`, along `dir` (backing off).
    Responding { since: u64, dir: [f64; 3] },
}

/// Band-limited tremor per axis: a resonator driven by white noise (an AR(2) process
/// whose spectrum peaks at the band's centre), scaled to the asked RMS.
#[derive(Debug, Clone)]
struct Tremor {
    a1: f64,
    a2: f64,
    sigma: f64,
    last: [[f64; 2]; 3],
    rng: ChaCha8Rng,
}

impl Tremor {
    fn new(cfg: &HumanConfig, t_s: f64, seed: u64) -> Tremor {
        let theta = 2.0 * std::f64::consts::PI * cfg.tremor_hz * t_s;
        let r = (-std::f64::consts::PI * cfg.tremor_band_hz * t_s).exp();
        let (a1, a2) = (2.0 * r * theta.cos(), -r * r);
        Tremor {
            a1,
            a2,
            sigma: cfg.tremor_um * 1e-6 / ar2_gain(a1, a2).sqrt(),
            last: [[0.0; 2]; 3],
            rng: stream(seed, TREMOR_STREAM),
        }
    }

    fn step(&mut self) -> [f64; 3] {
        [0, 1, 2].map(|k| {
            let e: f64 = self.rng.sample(StandardNormal);
            let [x1, x2] = self.last[k];
            let x = self.a1 * x1 + self.a2 * x2 + self.sigma * e;
            self.last[k] = [x, x1];
            x
        })
    }
}

/// The stationary variance of `x = a1 x1 + a2 x2 + e` per unit variance of `e`.
pub fn ar2_gain(a1: f64, a2: f64) -> f64 {
    (1.0 - a2) / ((1.0 + a2) * ((1.0 - a2).powi(2) - a1 * a1))
}

fn stream(seed: u64, id: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(id);
    r
}

/// The person holding the simulated handle.
#[derive(Debug, Clone)]
pub struct Human {
    cfg: HumanConfig,
    t_s: f64,
    tremor: Option<Tremor>,
    /// The wander per axis, its decay a sample, its drive's scale and its stream.
    drift: Option<([f64; 3], f64, f64, ChaCha8Rng)>,
    reactions: ChaCha8Rng,
    reaction: Reaction,
    progress: u64,
    last: Option<(u64, Sway)>,
    /// Reactions so far.
    pub reacted: u64,
}

impl Human {
    /// The person of `cfg` at loop period `t_s`, drawing from `seed`; `None` when the
    /// table changes nothing (the operator is the path exactly, as before it existed).
    pub fn new(cfg: &HumanConfig, t_s: f64, seed: u64) -> Option<Human> {
        if cfg.is_off() {
            return None;
        }
        let drift = (cfg.drift_mm > 0.0).then(|| {
            let phi = (-t_s / cfg.drift_s).exp();
            let scale = cfg.drift_mm * 1e-3 * (1.0 - phi * phi).sqrt();
            ([0.0; 3], phi, scale, stream(seed, DRIFT_STREAM))
        });
        Some(Human {
            cfg: cfg.clone(),
            t_s,
            tremor: (cfg.tremor_um > 0.0).then(|| Tremor::new(cfg, t_s, seed)),
            drift,
            reactions: stream(seed, REACTION_STREAM),
            reaction: Reaction::Following { armed: true },
            progress: 0,
            last: None,
            reacted: 0,
        })
    }

    fn samples(&self, ms: f64) -> u64 {
        (ms * 1e-3 / self.t_s).round() as u64
    }

    /// Sample `n` (in order; the same `n` again gives the same answer), having felt
    /// `felt` (N) at the sample before.
    pub fn step(&mut self, n: u64, felt: [f64; 3]) -> Sway {
        if let Some((m, s)) = self.last {
            if m == n {
                return s;
            }
        }
        let (hold, back) = self.react(n, felt);
        if n > 0 && !hold {
            self.progress += 1;
        }
        let tremor = self.tremor.as_mut().map_or([0.0; 3], Tremor::step);
        let drift = match &mut self.drift {
            Some((x, phi, scale, rng)) => {
                for v in x.iter_mut() {
                    let e: f64 = rng.sample(StandardNormal);
                    *v = *phi * *v + *scale * e;
                }
                *x
            }
            None => [0.0; 3],
        };
        let sway = Sway {
            progress: self.progress,
            offset: [0, 1, 2].map(|k| tremor[k] + drift[k] + back[k]),
        };
        self.last = Some((n, sway));
        sway
    }

    /// The reaction's part at sample `n`: whether the path waits, and the back-off.
    fn react(&mut self, n: u64, felt: [f64; 3]) -> (bool, [f64; 3]) {
        let f = felt.iter().map(|x| x * x).sum::<f64>().sqrt();
        let f = if f.is_finite() { f } else { 0.0 };
        match self.reaction {
            Reaction::Following { armed } => {
                let noticed = armed && self.cfg.reaction_ms > 0.0 && f >= self.cfg.contact_n;
                self.reaction = match noticed {
                    true => Reaction::Noticing {
                        at: n + self.reaction_time(),
                        dir: felt.map(|x| x / f),
                    },
                    false => Reaction::Following {
                        armed: armed || f < self.cfg.contact_n / 2.0,
                    },
                };
                (false, [0.0; 3])
            }
            Reaction::Noticing { at, dir } if n >= at => {
                self.reacted += 1;
                self.reaction = Reaction::Responding { since: n, dir };
                self.react(n, felt)
            }
            Reaction::Noticing { .. } => (false, [0.0; 3]),
            Reaction::Responding { since, dir } => self.respond(n - since, dir, f),
        }
    }

    /// `k` samples into the response along `dir`, the force now `f`.
    fn respond(&mut self, k: u64, dir: [f64; 3], f: f64) -> (bool, [f64; 3]) {
        let pause = self.samples(self.cfg.pause_ms);
        let done = |h: &mut Human| {
            h.reaction = Reaction::Following {
                armed: f < h.cfg.contact_n / 2.0,
            }
        };
        match self.cfg.response {
            Response::Pause if k < pause => (true, [0.0; 3]),
            Response::Stop if f >= self.cfg.contact_n / 2.0 => (true, [0.0; 3]),
            Response::Pause | Response::Stop => {
                done(self);
                (false, [0.0; 3])
            }
            Response::BackOff => {
                let ramp = self.samples(self.cfg.back_off_ms).max(1);
                let depth = match k {
                    k if k < ramp => k as f64 / ramp as f64,
                    k if k < ramp + pause => 1.0,
                    k if k < 2 * ramp + pause => 1.0 - (k - ramp - pause) as f64 / ramp as f64,
                    _ => {
                        done(self);
                        return (false, [0.0; 3]);
                    }
                };
                let d = self.cfg.back_off_mm * 1e-3 * crate::operator::min_jerk(depth);
                (k < ramp + pause, dir.map(|x| x * d))
            }
        }
    }

    /// A reaction time drawn from a log-normal of the configured mean and spread,
    /// samples.
    fn reaction_time(&mut self) -> u64 {
        let (m, s) = (self.cfg.reaction_ms, self.cfg.reaction_sd_ms);
        let var = (1.0 + (s * s) / (m * m)).ln();
        let z: f64 = self.reactions.sample(StandardNormal);
        let ms = (m.ln() - var / 2.0 + var.sqrt() * z).exp();
        self.samples(ms.min(10.0 * m))
    }
}

#[cfg(test)]
#[path = "human_tests.rs"]
mod tests;
