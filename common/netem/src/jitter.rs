//! netem-class channel models with netem's meanings and names (Linux `tc-netem(8)`):
//! delay jitter drawn from a distribution, with correlation; packet loss as a
//! Gilbert-Elliott model (netem's `gemodel p r 1-h 1-k`) or netem's 4-state Markov
//! model (`state p13 p31 p32 p23 p14`, Salsano et al., "Definition of a general and
//! intuitive loss model for packet networks", 2012). Everything is seeded and pure.
//!
//! Where netem's own implementation is known to be wrong we keep its meaning and not
//! its flaw: netem correlates successive uniform draws by mixing (next = c last +
//! (1-c) fresh), which shrinks the spread and does not give correlation c. Here the
//! jitter is driven by a Gaussian AR(1) process z_n = c z_{n-1} + sqrt(1-c^2) e_n,
//! whose marginal stays standard normal and whose lag-1 correlation is exactly c, and
//! is mapped to each distribution through its inverse CDF (a Gaussian copula), so the
//! spread is the configured one whatever the correlation.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use tactile_scenario::{JitterConfig, JitterDistribution, JITTER_CAP};

/// The correlated jitter process of one channel.
#[derive(Debug, Clone)]
pub struct Jitter {
    cfg: JitterConfig,
    z: Ar1,
    offset: f64,
    scale: f64,
}

/// The driving Gaussian AR(1) process z_n = c z_{n-1} + sqrt(1-c^2) e_n: standard
/// normal at every step, lag-1 correlation exactly c (shared by the jitter and the
/// delay histograms, which map it through their inverse CDFs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ar1 {
    c: f64,
    z: Option<f64>,
}

impl Ar1 {
    /// The process of lag-1 correlation `c` (in [0, 1)), before its first step.
    pub(crate) fn new(c: f64) -> Self {
        Ar1 { c, z: None }
    }

    /// The next value, with the standard normal innovation `e` (the first is `e`).
    pub(crate) fn next(&mut self, e: f64) -> f64 {
        let c = self.c;
        let z = match self.z {
            None => e,
            Some(last) => c * last + (1.0 - c * c).sqrt() * e,
        };
        self.z = Some(z);
        z
    }
}

/// Standard normal CDF (Abramowitz and Stegun 7.1.26 via erfc, error below 1.5e-7).
pub(crate) fn phi(z: f64) -> f64 {
    let x = z.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erfc = poly * (-x * x).exp();
    if z >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

/// Pareto shape: 3, the smallest integer shape with a finite variance.
const PARETO_SHAPE: f64 = 3.0;

/// A shape-3 Pareto value at quantile u, standardized (mean 0, variance 1).
fn pareto(u: f64) -> f64 {
    let a = PARETO_SHAPE;
    let mean = a / (a - 1.0);
    let sd = (a / ((a - 1.0) * (a - 1.0) * (a - 2.0))).sqrt();
    let x = (1.0 - u.clamp(0.0, 1.0 - 1e-16)).powf(-1.0 / a);
    (x - mean) / sd
}

/// The shape of a distribution at the driving Gaussian's value z, before scaling:
/// Pareto and paretonormal cut at [`JITTER_CAP`] standard units, so the delay line is
/// bounded (the cut is inside the shape, and the scale below restores the spread).
fn shape(d: JitterDistribution, z: f64) -> f64 {
    match d {
        JitterDistribution::Uniform => 2.0 * phi(z) - 1.0,
        JitterDistribution::Normal => z,
        JitterDistribution::Pareto => pareto(phi(z)).min(JITTER_CAP),
        JitterDistribution::Paretonormal => {
            (0.25 * z + 0.75 * pareto(phi(z))).clamp(-JITTER_CAP, JITTER_CAP)
        }
    }
}

/// Mean, standard deviation and kurtosis of [`shape`] over a standard normal z, by
/// quadrature (midpoint rule over +-9 sigma).
pub(crate) fn shape_moments(d: JitterDistribution) -> (f64, f64, f64) {
    let (n, lo, hi) = (20_000, -9.0, 9.0);
    let h = (hi - lo) / f64::from(n);
    let mut m = [0.0; 5];
    for k in 0..n {
        let z = lo + (f64::from(k) + 0.5) * h;
        let w = (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt() * h;
        let v = shape(d, z);
        for (p, acc) in m.iter_mut().enumerate() {
            *acc += w * v.powi(p as i32);
        }
    }
    let mean = m[1] / m[0];
    let var = m[2] / m[0] - mean * mean;
    let c4 = m[4] / m[0] - 4.0 * mean * m[3] / m[0] + 6.0 * mean * mean * m[2] / m[0]
        - 3.0 * mean.powi(4);
    (mean, var.sqrt(), c4 / (var * var))
}

impl Jitter {
    /// The process for `cfg` (validated).
    pub fn new(cfg: &JitterConfig) -> Self {
        // Uniform spans +-jitter as netem's does; the others have mean zero and
        // standard deviation `jitter`, their cut tails included.
        let (offset, scale) = match cfg.distribution {
            JitterDistribution::Uniform | JitterDistribution::Normal => (0.0, 1.0),
            d => {
                let (mean, sd, _) = shape_moments(d);
                (mean, 1.0 / sd)
            }
        };
        Jitter {
            cfg: cfg.clone(),
            z: Ar1::new(cfg.correlation),
            offset,
            scale,
        }
    }

    /// The next packet's jitter, samples (continuous; the channel rounds the delay).
    pub fn next(&mut self, rng: &mut impl Rng) -> f64 {
        let e: f64 = StandardNormal.sample(rng);
        self.next_with(e)
    }

    /// The next jitter with the given standard normal innovation.
    pub fn next_with(&mut self, e: f64) -> f64 {
        let z = self.z.next(e);
        let x = self.cfg.jitter * self.scale * (shape(self.cfg.distribution, z) - self.offset);
        x.clamp(-self.cfg.bound(), self.cfg.bound())
    }
}
