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
use tactile_scenario::{JitterConfig, JitterDistribution, LossModel, ReplayConfig, JITTER_CAP};

/// The long-run loss rate (the stationary probability of the losing states).
pub fn loss_rate(model: &LossModel) -> f64 {
    match *model {
        LossModel::Gemodel {
            p,
            r,
            bad_loss,
            good_loss,
        } => {
            if p + r == 0.0 {
                return good_loss;
            }
            let bad = p / (p + r);
            (1.0 - bad) * good_loss + bad * bad_loss
        }
        LossModel::State {
            p13,
            p31,
            p32,
            p23,
            p14,
        } => {
            // Balance: pi4 = p14 pi1; pi3 (p31 + p32) = p13 pi1 + p23 pi2;
            // pi2 p23 = p32 pi3. With p23 > 0: pi3 p31 = p13 pi1.
            let s = StateChain::stationary(p13, p31, p32, p23, p14);
            s[2] + s[3]
        }
    }
}

/// The stationary distribution of the 4-state chain.
struct StateChain;

impl StateChain {
    /// The long-run share of each state, starting from state 1 (for a chain that is
    /// not irreducible, the class the chain ends up in from there).
    fn stationary(p13: f64, p31: f64, p32: f64, p23: f64, p14: f64) -> [f64; 4] {
        // Never leaving {1, 4}: pi4 = p14 pi1.
        if p13 == 0.0 {
            return [1.0 / (1.0 + p14), 0.0, 0.0, p14 / (1.0 + p14)];
        }
        // Once in {2, 3} for good (no way back to 1): the 2-3 chain alone.
        if p31 == 0.0 {
            return match (p32 > 0.0, p23 > 0.0) {
                (true, true) => [0.0, p23 / (p23 + p32), p32 / (p23 + p32), 0.0],
                (true, false) => [0.0, 1.0, 0.0, 0.0],
                _ => [0.0, 0.0, 1.0, 0.0],
            };
        }
        // State 2 absorbing once reached.
        if p32 > 0.0 && p23 == 0.0 {
            return [0.0, 1.0, 0.0, 0.0];
        }
        // Relative to pi1 = 1: pi4 = p14; pi3 = p13 / p31 (the flows between {1, 4}
        // and {2, 3} balance, and only 1 -> 3 and 3 -> 1 cross); pi2 = p32 pi3 / p23.
        let pi3 = p13 / p31;
        let pi2 = if p23 > 0.0 { p32 * pi3 / p23 } else { 0.0 };
        let total = 1.0 + p14 + pi3 + pi2;
        [1.0 / total, pi2 / total, pi3 / total, p14 / total]
    }
}

/// The correlated jitter process of one channel.
#[derive(Debug, Clone)]
pub struct Jitter {
    cfg: JitterConfig,
    z: Option<f64>,
    offset: f64,
    scale: f64,
}

/// Standard normal CDF (Abramowitz and Stegun 7.1.26 via erfc, error below 1.5e-7).
fn phi(z: f64) -> f64 {
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
fn shape_moments(d: JitterDistribution) -> (f64, f64, f64) {
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
            z: None,
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
        let c = self.cfg.correlation;
        let z = match self.z {
            None => e,
            Some(last) => c * last + (1.0 - c * c).sqrt() * e,
        };
        self.z = Some(z);
        let x = self.cfg.jitter * self.scale * (shape(self.cfg.distribution, z) - self.offset);
        x.clamp(-self.cfg.bound(), self.cfg.bound())
    }
}

/// The state of a loss model.
#[derive(Debug, Clone)]
pub struct Loss {
    model: LossModel,
    state: u8,
}

impl Loss {
    /// A model in its good state.
    pub fn new(model: &LossModel) -> Self {
        Loss {
            model: model.clone(),
            state: 1,
        }
    }

    /// Whether the next packet is lost; moves the chain one packet on.
    pub fn lose(&mut self, rng: &mut impl Rng) -> bool {
        match self.model {
            LossModel::Gemodel {
                p,
                r,
                bad_loss,
                good_loss,
            } => {
                // The state moves, then the packet's fate is drawn in the state it moved
                // to (netem's loss_gilb_ell draws the fate in the state it leaves; the
                // long-run rates are the same).
                let u: f64 = rng.random();
                self.state = match self.state {
                    1 if u < p => 3,
                    3 if u < r => 1,
                    s => s,
                };
                let loss = if self.state == 3 { bad_loss } else { good_loss };
                loss > 0.0 && rng.random::<f64>() < loss
            }
            LossModel::State {
                p13,
                p31,
                p32,
                p23,
                p14,
            } => {
                let u: f64 = rng.random();
                self.state = match self.state {
                    1 if u < p13 => 3,
                    1 if u < p13 + p14 => 4,
                    2 if u < p23 => 3,
                    3 if u < p31 => 1,
                    3 if u < p31 + p32 => 2,
                    4 => 1,
                    s => s,
                };
                self.state == 3 || self.state == 4
            }
        }
    }
}

/// A loaded replay: each packet's delay (samples) and whether it is lost.
#[derive(Debug, Clone, PartialEq)]
pub enum Replay {
    /// Rows of a CSV file, one per packet sent, looped; the number of packets so far.
    Packets(Vec<(u32, bool)>, u64),
    /// Mahimahi delivery opportunities (ms), looped, served first come first served.
    Mahimahi(Mahimahi),
}

/// The FIFO queue of a Mahimahi link.
#[derive(Debug, Clone, PartialEq)]
pub struct Mahimahi {
    times_ms: Vec<u64>,
    period_ms: u64,
    per_opportunity: u32,
    max_queue: u32,
    next: u64,
    used: u32,
}

impl Replay {
    /// Parses a CSV replay: header `delay,lost`; the error names the line. Rows are
    /// read straight into 5 bytes each (a replay file may hold hours of packets).
    pub fn parse_csv(text: &str) -> Result<Replay, String> {
        let mut lines = text.lines().enumerate();
        match lines.next() {
            Some((_, h)) if h.trim().replace(' ', "") == "delay,lost" => {}
            Some((_, h)) => return Err(format!("line 1: header is {h:?}, expected delay,lost")),
            None => return Err("empty: expected the header delay,lost".into()),
        }
        let mut out = Vec::new();
        for (k, raw) in lines {
            let line = k + 1;
            let row = raw.trim();
            if row.is_empty() {
                continue;
            }
            let mut cells = row.split(',').map(str::trim);
            let (Some(d), Some(l), None) = (cells.next(), cells.next(), cells.next()) else {
                return Err(format!("line {line}: expected 2 columns (delay,lost)"));
            };
            let d: u32 = d
                .parse()
                .ok()
                .filter(|d| i64::from(*d) <= tactile_scenario::MAX_DELAY_SAMPLES)
                .ok_or_else(|| {
                    format!("line {line}: delay {d} is not a whole number of samples in 0..=100000")
                })?;
            let l = match l {
                "0" => false,
                "1" => true,
                other => return Err(format!("line {line}: lost {other} is not 0 or 1")),
            };
            out.push((d, l));
        }
        if out.is_empty() {
            return Err("no packets after the header".into());
        }
        Ok(Replay::Packets(out, 0))
    }

    /// Parses a Mahimahi trace (one non-decreasing millisecond timestamp per line).
    pub fn parse_mahimahi(text: &str, cfg: &ReplayConfig) -> Result<Replay, String> {
        let mut times = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let t = line.trim();
            if t.is_empty() {
                continue;
            }
            let v: u64 = t.parse().map_err(|_| {
                format!(
                    "line {}: {t:?} is not a whole number of milliseconds",
                    k + 1
                )
            })?;
            if times.last().is_some_and(|&last| v < last) {
                return Err(format!("line {}: {v} ms goes back in time", k + 1));
            }
            times.push(v);
        }
        let Some(&last) = times.last() else {
            return Err("no delivery opportunities".into());
        };
        if last == 0 {
            return Err("the trace lasts 0 ms".into());
        }
        Ok(Replay::Mahimahi(Mahimahi {
            times_ms: times,
            period_ms: last,
            per_opportunity: (1500 / cfg.packet_bytes).max(1),
            max_queue: cfg.max_queue_samples,
            next: 0,
            used: 0,
        }))
    }

    /// The largest delay a packet can be given, samples.
    pub fn bound(&self) -> u32 {
        match self {
            Replay::Packets(rows, _) => rows.iter().map(|r| r.0).max().unwrap_or(0),
            Replay::Mahimahi(m) => m.max_queue,
        }
    }

    /// The sample `n`, sent at n t_s if `sent` (a sample its codec did not send is no
    /// packet: it takes no row and no room on the link): the packet's delay in samples
    /// and whether it is lost. Samples come in order.
    pub fn packet(&mut self, n: u64, t_s: f64, sent: bool) -> (u32, bool) {
        if !sent {
            return (0, false);
        }
        match self {
            Replay::Packets(rows, k) => {
                let r = rows[(*k % rows.len() as u64) as usize];
                *k += 1;
                r
            }
            Replay::Mahimahi(m) => m.deliver(n, t_s),
        }
    }
}

impl Mahimahi {
    fn time(&self, k: u64) -> u64 {
        let len = self.times_ms.len() as u64;
        self.times_ms[(k % len) as usize] + (k / len) * self.period_ms
    }

    /// The first opportunity at or after `ms`, found directly (a late or sparse
    /// packet must not walk the trace one opportunity at a time).
    fn first_at(&self, ms: f64) -> u64 {
        let len = self.times_ms.len() as u64;
        let ms = ms.clamp(0.0, 1e15);
        let loops = (ms / self.period_ms as f64).floor() as u64;
        let within = ms - (loops * self.period_ms) as f64;
        let mut k = loops * len + self.times_ms.partition_point(|&t| (t as f64) < within) as u64;
        // The last opportunity of a loop falls at the period itself, where the next
        // loop starts: step back onto opportunities that are still at or after `ms`.
        while k > 0 && self.time(k - 1) as f64 >= ms {
            k -= 1;
        }
        k
    }

    /// The first opportunity at or after the packet's sending time with room left.
    fn deliver(&mut self, n: u64, t_s: f64) -> (u32, bool) {
        let sent_ms = n as f64 * t_s * 1e3;
        let k = self.first_at(sent_ms);
        if k > self.next {
            self.next = k;
            self.used = 0;
        }
        if self.used >= self.per_opportunity {
            self.next += 1;
            self.used = 0;
        }
        let at_ms = self.time(self.next) as f64;
        let delay = ((at_ms - sent_ms) / (t_s * 1e3)).ceil().max(0.0);
        if delay > f64::from(self.max_queue) {
            // The queue is full: dropped, and it takes no room.
            return (self.max_queue, true);
        }
        self.used += 1;
        (delay as u32, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use tactile_scenario::ReplayFormat;

    const N: usize = 100_000;

    fn stats(x: &[f64]) -> (f64, f64, f64) {
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        let lag = x
            .windows(2)
            .map(|w| (w[0] - mean) * (w[1] - mean))
            .sum::<f64>()
            / (n - 1.0);
        (mean, var.sqrt(), lag / var)
    }

    /// Each value's rank in the series, 0 to N - 1.
    fn ranks(x: &[f64]) -> Vec<f64> {
        let mut order: Vec<usize> = (0..x.len()).collect();
        order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
        let mut r = vec![0.0; x.len()];
        for (rank, &k) in order.iter().enumerate() {
            r[k] = rank as f64;
        }
        r
    }

    fn draw(cfg: JitterConfig, seed: u64) -> Vec<f64> {
        let mut j = Jitter::new(&cfg);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..N).map(|_| j.next(&mut rng)).collect()
    }

    /// Tolerances from the sample count: for an AR(1) series of lag-1 correlation c the
    /// effective count is N (1 - c) / (1 + c), so the mean's standard error is
    /// sd sqrt((1 + c) / (N (1 - c))); the sample standard deviation's relative error
    /// about sqrt((1 + c^2) / (2 N (1 - c^2))) for Gaussian data (heavier tails need
    /// more: Pareto shape 3 has no fourth moment, so its spread is checked to 5 %);
    /// the lag-1 correlation's about sqrt((1 - c^2) / N). Five standard errors each.
    /// The spread's error depends on the tail (kurtosis): see `spread_tolerance`.
    #[test]
    fn jitter_matches_its_distribution_spread_and_correlation() {
        // The sample variance's relative standard error is sqrt((kurtosis - 1) / N_eff)
        // (half that for the standard deviation), N_eff = N (1 - c^2) / (1 + c^2).
        let spread_tolerance = |d: JitterDistribution, c: f64| {
            let kurtosis = match d {
                JitterDistribution::Uniform => 1.8,
                JitterDistribution::Normal => 3.0,
                d => shape_moments(d).2,
            };
            let n_eff = N as f64 * (1.0 - c * c) / (1.0 + c * c);
            5.0 * 0.5 * ((kurtosis - 1.0) / n_eff).sqrt()
        };
        for distribution in [
            JitterDistribution::Uniform,
            JitterDistribution::Normal,
            JitterDistribution::Pareto,
            JitterDistribution::Paretonormal,
        ] {
            for c in [0.0, 0.5, 0.9] {
                let x = draw(
                    JitterConfig {
                        jitter: 4.0,
                        correlation: c,
                        distribution,
                    },
                    7,
                );
                let (mean, sd, rho) = stats(&x);
                // netem's uniform takes `jitter` as the half-width: sd = J / sqrt(3).
                let want_sd = if distribution == JitterDistribution::Uniform {
                    4.0 / 3f64.sqrt()
                } else {
                    4.0
                };
                let se_mean = want_sd * ((1.0 + c) / (N as f64 * (1.0 - c))).sqrt();
                assert!(
                    mean.abs() < 5.0 * se_mean,
                    "{distribution:?} c {c}: mean {mean}"
                );
                let rel = (sd - want_sd).abs() / want_sd;
                assert!(
                    rel < spread_tolerance(distribution, c),
                    "{distribution:?} c {c}: sd {sd}"
                );
                // Through the copula the rank (Spearman) correlation of successive
                // values is (6/pi) asin(c/2) whatever the distribution; the Pearson
                // correlation is c itself for normal. Bartlett: the lag-1 estimate's
                // standard error is about sqrt((1 - c^2) / N); at least 1/sqrt(N) here.
                let se_rho = ((1.0 - c * c) / N as f64)
                    .sqrt()
                    .max(1.0 / (N as f64).sqrt());
                let want_rank = 6.0 / std::f64::consts::PI * (c / 2.0).asin();
                let rank = stats(&ranks(&x)).2;
                assert!(
                    (rank - want_rank).abs() < 5.0 * se_rho,
                    "{distribution:?} c {c}: rank correlation {rank} vs {want_rank}"
                );
                if distribution == JitterDistribution::Normal {
                    assert!((rho - c).abs() < 5.0 * se_rho, "c {c}: rho {rho}");
                }
            }
        }
        // Pareto's tail: skewed right, so the median sits below the mean.
        let mut x = draw(
            JitterConfig {
                jitter: 1.0,
                correlation: 0.0,
                distribution: JitterDistribution::Pareto,
            },
            3,
        );
        x.sort_by(f64::total_cmp);
        assert!(x[N / 2] < -0.2, "median {}", x[N / 2]);
    }

    /// Loss runs: the loss rate against the stationary probability, and the mean burst
    /// length against 1/r (simple Gilbert: every packet in the bad state is lost).
    /// A Markov chain's loss indicator has lag correlation lambda = 1 - p - r, so the
    /// rate's standard error is sqrt(pi (1 - pi) (1 + lambda) / (N (1 - lambda))); a
    /// burst length is geometric with mean 1/r and variance (1 - r)/r^2, averaged over
    /// about N pi r bursts. Five standard errors each.
    #[test]
    fn gilbert_elliott_loss_rate_and_burst_length_match_the_closed_form() {
        for (p, r) in [(0.01, 0.3), (0.002, 0.05), (0.05, 0.5)] {
            let model = LossModel::Gemodel {
                p,
                r,
                bad_loss: 1.0,
                good_loss: 0.0,
            };
            let mut loss = Loss::new(&model);
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            let lost: Vec<bool> = (0..N).map(|_| loss.lose(&mut rng)).collect();
            let rate = lost.iter().filter(|l| **l).count() as f64 / N as f64;
            let pi = loss_rate(&model);
            assert!((pi - p / (p + r)).abs() < 1e-15);
            let lambda = 1.0 - p - r;
            let se = (pi * (1.0 - pi) * (1.0 + lambda) / (N as f64 * (1.0 - lambda))).sqrt();
            assert!(
                (rate - pi).abs() < 5.0 * se,
                "p {p} r {r}: rate {rate} vs {pi}"
            );
            let mut bursts = Vec::new();
            let mut run = 0u32;
            for l in &lost {
                if *l {
                    run += 1;
                } else if run > 0 {
                    bursts.push(f64::from(run));
                    run = 0;
                }
            }
            let mean = bursts.iter().sum::<f64>() / bursts.len() as f64;
            let se_b = ((1.0 - r) / (r * r) / bursts.len() as f64).sqrt();
            assert!(
                (mean - 1.0 / r).abs() < 5.0 * se_b,
                "p {p} r {r}: burst {mean} vs {}",
                1.0 / r
            );
        }
    }

    #[test]
    fn gilbert_elliott_with_partial_loss_and_the_four_state_model_match_their_rates() {
        let cases = [
            LossModel::Gemodel {
                p: 0.02,
                r: 0.2,
                bad_loss: 0.6,
                good_loss: 0.01,
            },
            LossModel::State {
                p13: 0.01,
                p31: 0.4,
                p32: 0.1,
                p23: 0.3,
                p14: 0.005,
            },
        ];
        for model in cases {
            let mut loss = Loss::new(&model);
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let rate = (0..N).filter(|_| loss.lose(&mut rng)).count() as f64 / N as f64;
            let pi = loss_rate(&model);
            // Bursty: allow for correlation with a generous effective count of N / 20.
            let se = (pi * (1.0 - pi) / (N as f64 / 20.0)).sqrt();
            assert!((rate - pi).abs() < 5.0 * se, "{model:?}: {rate} vs {pi}");
        }
        // The 4-state chain's stationary distribution solves every balance equation
        // (pi = pi P, state by state), and the chains that are not irreducible end
        // where they must.
        let (p13, p31, p32, p23, p14) = (0.01, 0.4, 0.1, 0.3, 0.005);
        let s = StateChain::stationary(p13, p31, p32, p23, p14);
        assert!((s.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let next = [
            s[0] * (1.0 - p13 - p14) + s[2] * p31 + s[3],
            s[1] * (1.0 - p23) + s[2] * p32,
            s[0] * p13 + s[1] * p23 + s[2] * (1.0 - p31 - p32),
            s[0] * p14,
        ];
        for k in 0..4 {
            assert!(
                (next[k] - s[k]).abs() < 1e-12,
                "state {}: {next:?} vs {s:?}",
                k + 1
            );
        }
        assert_eq!(
            StateChain::stationary(0.0, 0.4, 0.1, 0.3, 0.25),
            [0.8, 0.0, 0.0, 0.2]
        );
        let t = StateChain::stationary(0.1, 0.0, 0.1, 0.3, 0.0);
        assert!(
            (t[1] - 0.75).abs() < 1e-12 && (t[2] - 0.25).abs() < 1e-12,
            "{t:?}"
        );
    }

    #[test]
    fn a_csv_replay_reads_back_row_by_row_and_loops() {
        let mut r = Replay::parse_csv("delay,lost\n3,0\n5,1\n0,0\n").expect("csv");
        let got: Vec<(u32, bool)> = (0..6).map(|n| r.packet(n, 1e-3, true)).collect();
        let want = [
            (3, false),
            (5, true),
            (0, false),
            (3, false),
            (5, true),
            (0, false),
        ];
        assert_eq!(got, want);
        // A sample not sent takes no row: the next packet gets the next one.
        assert_eq!(r.packet(6, 1e-3, false), (0, false));
        assert_eq!(r.packet(7, 1e-3, true), (3, false));
        assert_eq!(r.bound(), 5);
        for (text, needle) in [
            ("delay,lost\n1.5,0\n", "line 2: delay 1.5"),
            ("delay,lost\n-1,0\n", "line 2: delay -1"),
            ("delay,lost\n1\n", "line 2: expected 2 columns"),
            ("delay,lost\n1,2\n", "line 2: lost 2"),
            ("delay,lost\n", "no packets"),
            ("d,l\n1,0\n", "header"),
        ] {
            let e = Replay::parse_csv(text).expect_err(text);
            assert!(e.contains(needle), "{text}: {e}");
        }
    }

    /// A Mahimahi link that can deliver one MTU every 2 ms carries 6 packets of 250
    /// bytes per opportunity: at 1 kHz (a packet per ms) it keeps up, each packet
    /// waiting for the next opportunity; at 10 kHz it cannot, the queue grows to its
    /// limit and the excess is dropped.
    #[test]
    fn a_mahimahi_link_queues_and_drops_what_it_cannot_carry() {
        let cfg = ReplayConfig {
            path: "x".into(),
            format: ReplayFormat::Mahimahi,
            packet_bytes: 250,
            max_queue_samples: 50,
        };
        let mut r = Replay::parse_mahimahi("2\n4\n", &cfg).expect("trace");
        let got: Vec<(u32, bool)> = (0..6).map(|n| r.packet(n, 1e-3, true)).collect();
        let want = [
            (2, false),
            (1, false),
            (0, false),
            (1, false),
            (0, false),
            (1, false),
        ];
        assert_eq!(got, want);
        let mut fast = Replay::parse_mahimahi("2\n4\n", &cfg).expect("trace");
        let lost = (0..10_000)
            .filter(|&n| fast.packet(n, 1e-4, true).1)
            .count();
        // 3 packets per ms fit of the 10 sent: 70 % dropped once the queue is full.
        assert!((6_500..=7_100).contains(&lost), "{lost}");
        // A packet sent an hour in goes at once: the trace is not walked.
        let mut late = Replay::parse_mahimahi("2\n4\n", &cfg).expect("trace");
        assert_eq!(late.packet(3_600_000, 1e-3, true), (0, false));
        // Samples not sent take no room.
        let mut quiet = Replay::parse_mahimahi("2\n4\n", &cfg).expect("trace");
        assert!((0..10_000).all(|n| !quiet.packet(n, 1e-4, n % 10 == 0).1));
        assert!(Replay::parse_mahimahi("3\n2\n", &cfg).is_err());
        assert!(Replay::parse_mahimahi("x\n", &cfg).is_err());
    }

    #[test]
    fn seeded_and_repeatable() {
        let cfg = JitterConfig {
            jitter: 3.0,
            correlation: 0.3,
            distribution: JitterDistribution::Paretonormal,
        };
        assert_eq!(draw(cfg.clone(), 1), draw(cfg.clone(), 1));
        assert_ne!(draw(cfg.clone(), 1), draw(cfg, 2));
    }

    #[test]
    fn phi_is_the_normal_cdf() {
        for (z, want) in [
            (0.0, 0.5),
            (1.0, 0.841_344_746),
            (-1.96, 0.024_997_895),
            (3.0, 0.998_650_102),
        ] {
            assert!((phi(z) - want).abs() < 2e-7, "{z}: {}", phi(z));
        }
    }
}
