//! Each feature's statistics as LeRobot's `stats.json` holds them (min, max, mean,
//! population std and count per entry), kept as running sums (Welford's) so a dataset
//! of any length takes the same memory. LeRobot's quantiles (q01 ... q99) need every
//! value or a sketch of them: they are not written (LeRobot's loader does not require
//! them; a policy normalising by quantiles computes them itself).

use serde_json::{json, Value};

/// One entry's running statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Running {
    n: u64,
    min: f64,
    max: f64,
    mean: f64,
    m2: f64,
}

impl Default for Running {
    fn default() -> Self {
        Running {
            n: 0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            mean: 0.0,
            m2: 0.0,
        }
    }
}

impl Running {
    fn add(&mut self, x: f64) {
        self.n += 1;
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    fn std(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            (self.m2 / self.n as f64).max(0.0).sqrt()
        }
    }
}

/// A feature's statistics, one [`Running`] per entry.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Stats {
    entries: Vec<Running>,
}

/// The statistics LeRobot keeps per feature, in its order.
pub const NAMES: [&str; 5] = ["min", "max", "mean", "std", "count"];

impl Stats {
    /// Statistics of `len` entries.
    pub fn new(len: usize) -> Stats {
        Stats {
            entries: vec![Running::default(); len],
        }
    }

    /// Adds one frame's values (as many as the entries; further ones ignored).
    pub fn add(&mut self, values: impl IntoIterator<Item = f64>) {
        for (r, x) in self.entries.iter_mut().zip(values) {
            r.add(x);
        }
    }

    /// Values added to the first entry.
    pub fn count(&self) -> u64 {
        self.entries.first().map_or(0, |r| r.n)
    }

    /// Each statistic of [`NAMES`] but the count, per entry (zeros where none was added).
    pub fn columns(&self) -> [Vec<f64>; 4] {
        let seen = |f: fn(&Running) -> f64| -> Vec<f64> {
            self.entries
                .iter()
                .map(|r| if r.n == 0 { 0.0 } else { f(r) })
                .collect()
        };
        [
            seen(|r| r.min),
            seen(|r| r.max),
            seen(|r| r.mean),
            seen(Running::std),
        ]
    }

    /// As `stats.json` holds a feature's.
    pub fn to_json(&self) -> Value {
        let [min, max, mean, std] = self.columns();
        json!({
            "min": min,
            "max": max,
            "mean": mean,
            "std": std,
            "count": [self.count()],
        })
    }

    /// Clears the sums (an episode's, for the next).
    pub fn reset(&mut self) {
        self.entries.fill(Running::default());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sums_give_the_population_statistics() {
        let mut s = Stats::new(2);
        for x in [1.0, 2.0, 4.0, 7.0] {
            s.add([x, -x]);
        }
        let [min, max, mean, std] = s.columns();
        assert_eq!(
            (min, max, mean),
            (vec![1.0, -7.0], vec![7.0, -1.0], vec![3.5, -3.5])
        );
        // Population variance: (6.25 + 2.25 + 0.25 + 12.25) / 4 = 5.25.
        assert!((std[0] - 5.25f64.sqrt()).abs() < 1e-12, "{std:?}");
        assert_eq!(s.count(), 4);
        s.reset();
        assert_eq!(s.count(), 0);
    }
}
