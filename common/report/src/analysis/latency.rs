//! One latency distribution: its count, percentiles, maximum and mean, as a latency
//! researcher reads them.
//!
//! Every value goes into an HdrHistogram (1 ns to 60 s, 3 significant digits), whose
//! percentile of a value is, by HdrHistogram's convention (`value_at_quantile`), the
//! highest value of the value's bucket: up to 0.1 % above what was recorded. An exact
//! 50 ms round trip read 50,003,967 ns that way, the bucket's rounding shown as a
//! measurement. So the distribution also keeps every distinct value with its count,
//! while there are at most [`EXACT_VALUES`] of them: a run with synthetic stamps (in
//! process, a round trip is the injected delay to the nanosecond) or a short run
//! reports its percentiles exactly, each one a value recorded, by the same rank
//! (the smallest value with `ceil(q n)` values at or below it, at least the first).
//! Past that, the percentiles are the histogram's, and [`Percentiles::exact`] says so.
//! The count, the maximum and the mean are always exact (a running count, maximum and
//! sum), and no percentile is above the maximum.

use hdrhistogram::Histogram;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Distinct values a distribution keeps exactly, each with its count (some 100 kB at
/// most): past this many its percentiles come from the histogram. A run of synthetic
/// stamps has a few dozen (the delay's ramp at the start, then the delay); 4,096
/// answers of real stamps are 4 s at 1 kHz.
pub const EXACT_VALUES: usize = 4096;

/// Percentiles of one latency distribution, nanoseconds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Percentiles {
    /// Values recorded.
    pub count: u64,
    /// Median.
    pub p50: u64,
    /// 90th percentile.
    pub p90: u64,
    /// 99th percentile.
    pub p99: u64,
    /// 99.9th percentile.
    pub p999: u64,
    /// Largest value (exact).
    pub max: u64,
    /// Mean (exact).
    pub mean: f64,
    /// True when p50 ... p999 are values recorded; false when they are the
    /// HdrHistogram's at 3 significant digits (each the highest value of its bucket,
    /// at most 0.1 % above the value recorded, and never above `max`).
    #[serde(default)]
    pub exact: bool,
}

/// A latency distribution being collected.
#[derive(Debug, Clone)]
pub struct Latency {
    hist: Histogram<u64>,
    /// Each distinct value and its count, while there are at most [`EXACT_VALUES`].
    exact: Option<BTreeMap<u64, u64>>,
    sum: u128,
    max: u64,
    /// Values below zero clamped to zero (possible for overhead, see docs/06-records-and-reports.md).
    pub negative: u64,
}

impl Default for Latency {
    fn default() -> Self {
        Latency {
            // 1 ns .. 60 s at 3 significant digits: bounds are constants, always valid.
            hist: Histogram::new_with_bounds(1, 60_000_000_000, 3)
                .expect("constant histogram bounds are valid"),
            exact: Some(BTreeMap::new()),
            sum: 0,
            max: 0,
            negative: 0,
        }
    }
}

impl Latency {
    /// Records one value in ns; negatives are clamped to 0 and counted.
    pub fn record(&mut self, ns: i64) {
        if ns < 0 {
            self.negative += 1;
        }
        let v = ns.max(0) as u64;
        self.hist.saturating_record(v);
        self.sum += u128::from(v);
        self.max = self.max.max(v);
        if let Some(t) = &mut self.exact {
            *t.entry(v).or_default() += 1;
            if t.len() > EXACT_VALUES {
                self.exact = None;
            }
        }
    }

    /// The value at quantile `q`: exact while the distribution is kept whole, else
    /// the histogram's (never above the maximum).
    fn value_at(&self, q: f64) -> u64 {
        match &self.exact {
            Some(t) => {
                let rank = ((q.min(1.0) * self.hist.len() as f64).ceil() as u64).max(1);
                let mut below = 0;
                t.iter()
                    .find(|(_, &c)| {
                        below += c;
                        below >= rank
                    })
                    .map_or(self.max, |(&v, _)| v)
            }
            None => self.hist.value_at_quantile(q).min(self.max),
        }
    }

    /// The summary percentiles; `None` when nothing was recorded.
    pub fn percentiles(&self) -> Option<Percentiles> {
        let count = self.hist.len();
        if count == 0 {
            return None;
        }
        Some(Percentiles {
            count,
            p50: self.value_at(0.50),
            p90: self.value_at(0.90),
            p99: self.value_at(0.99),
            p999: self.value_at(0.999),
            max: self.max,
            mean: self.sum as f64 / count as f64,
            exact: self.exact.is_some(),
        })
    }

    /// Each value recorded with its count, ascending: the values themselves while the
    /// distribution is kept whole, else the histogram's buckets (each its highest
    /// value, the last no higher than the maximum).
    pub fn counts(&self) -> Vec<(u64, u64)> {
        match &self.exact {
            Some(t) => t.iter().map(|(&v, &c)| (v, c)).collect(),
            None => self
                .hist
                .iter_recorded()
                .map(|v| (v.value_iterated_to().min(self.max), v.count_at_value()))
                .collect(),
        }
    }

    /// The population standard deviation: exact while the distribution is kept
    /// whole, else the histogram's.
    fn stdev(&self) -> f64 {
        match &self.exact {
            Some(t) => {
                let n = self.hist.len() as f64;
                let mean = self.sum as f64 / n;
                let sq: f64 = t
                    .iter()
                    .map(|(&v, &c)| c as f64 * (v as f64 - mean).powi(2))
                    .sum();
                (sq / n).sqrt()
            }
            None => self.hist.stdev(),
        }
    }

    /// HdrHistogram percentile distribution text, values in microseconds: while the
    /// distribution is kept whole, one line per distinct value (its cumulative
    /// percentile), else the histogram's quantile iteration; the footer's mean and
    /// maximum exact.
    pub fn hgrm(&self) -> String {
        let mut s = String::from("       Value     Percentile TotalCount 1/(1-Percentile)\n\n");
        let n = self.hist.len();
        if n == 0 {
            return s;
        }
        let mut line = |v: u64, q: f64, total: u64| {
            let inv = if q < 1.0 {
                format!("{:.2}", 1.0 / (1.0 - q))
            } else {
                String::from("inf")
            };
            let us = v as f64 / 1000.0;
            let _ = writeln!(s, "{us:12.3} {q:14.12} {total:10} {inv:>14}");
        };
        match &self.exact {
            Some(t) => {
                let mut total = 0;
                for (k, (&v, &c)) in t.iter().enumerate() {
                    if k == 0 {
                        line(v, 0.0, c);
                    }
                    total += c;
                    line(v, total as f64 / n as f64, total);
                }
            }
            None => {
                let mut total = 0;
                for v in self.hist.iter_quantiles(5) {
                    total += v.count_since_last_iteration();
                    let at = v.value_iterated_to().min(self.max);
                    line(at, v.quantile_iterated_to(), total);
                }
            }
        }
        let _ = writeln!(
            s,
            "#[Mean    = {:12.3}, StdDeviation   = {:12.3}]\n#[Max     = {:12.3}, Total count    = {:12}]",
            self.sum as f64 / n as f64 / 1000.0,
            self.stdev() / 1000.0,
            self.max as f64 / 1000.0,
            n
        );
        s
    }
}

/// Renders percentiles in microseconds for the terminal; "n/a" when none.
pub fn us_line(name: &str, p: Option<&Percentiles>) -> String {
    let us = |v: u64| format!("{:.1}", v as f64 / 1000.0);
    match p {
        Some(p) => format!(
            "{name:<24} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10}",
            p.count,
            us(p.p50),
            us(p.p90),
            us(p.p99),
            us(p.p999),
            us(p.max)
        ),
        None => format!(
            "{name:<24} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10}",
            0, "n/a", "n/a", "n/a", "n/a", "n/a"
        ),
    }
}

/// The line the text prints under the latency rows `shown` when any of them is not
/// exact: what its percentiles are.
pub fn rounding_note<'a>(shown: impl IntoIterator<Item = &'a Percentiles>) -> Option<&'static str> {
    shown.into_iter().any(|p| !p.exact).then_some(
        "  (p50 to p99.9 of a row of more than 4096 distinct values from HdrHistogram at 3 significant digits: \
         each the highest value of its bucket, at most 0.1 % above the value recorded; count and max exact)",
    )
}

/// Header matching [`us_line`].
pub fn us_header() -> String {
    format!(
        "{:<24} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "latency (us)", "count", "p50", "p90", "p99", "p99.9", "max"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An in-process run's round trips: the delay's ramp at the start (25 to 49 ms),
    /// then exactly 50 ms. Every figure is a value recorded: p50 is 50,000,000 ns,
    /// not the histogram's 50,003,967.
    #[test]
    fn an_exact_delay_reads_exactly() {
        let mut l = Latency::default();
        for ms in 25..50 {
            l.record(ms * 1_000_000);
        }
        for _ in 0..7950 {
            l.record(50_000_000);
        }
        let p = l.percentiles().expect("values");
        assert!(p.exact);
        assert_eq!(
            (p.p50, p.p90, p.p99, p.p999, p.max),
            (50_000_000, 50_000_000, 50_000_000, 50_000_000, 50_000_000)
        );
        let sum: u64 = (25..50).map(|ms| ms * 1_000_000).sum::<u64>() + 7950 * 50_000_000;
        assert_eq!(p.mean, sum as f64 / 7975.0);
        // The percentile file says the same: its last line and its footer.
        let hgrm = l.hgrm();
        let last = crate::plots::read_hgrm(&hgrm).pop().expect("lines");
        assert_eq!(last, (1.0, 50_000.0));
        assert!(hgrm.contains("#[Max     =    50000.000"), "{hgrm}");
        // The first line is the smallest value, at percentile 0.
        assert_eq!(crate::plots::read_hgrm(&hgrm)[0], (0.0, 25_000.0));
    }

    /// Exact percentiles follow HdrHistogram's rank: the smallest value with at least
    /// ceil(q n) values at or below it.
    #[test]
    fn an_exact_percentile_is_the_value_of_its_rank() {
        let mut l = Latency::default();
        for v in 1..=1000 {
            l.record(v * 1000);
        }
        let p = l.percentiles().expect("values");
        assert_eq!(
            (p.p50, p.p90, p.p99, p.p999),
            (500_000, 900_000, 990_000, 999_000)
        );
        assert_eq!(l.value_at(0.0), 1000);
        assert_eq!(l.value_at(1.0), 1_000_000);
        let mut one = Latency::default();
        one.record(7);
        assert_eq!(one.percentiles().map(|p| (p.p50, p.max)), Some((7, 7)));
    }

    /// The text notes the histogram's rounding only under rows that have it.
    #[test]
    fn the_text_notes_rounded_percentiles() {
        let exact = Percentiles {
            exact: true,
            ..Percentiles::default()
        };
        let rounded = Percentiles::default();
        assert_eq!(rounding_note([&exact, &exact]), None);
        let note = rounding_note([&exact, &rounded]).expect("a note");
        assert!(note.contains("3 significant digits") && note.contains("0.1 %"));
        assert!(note.contains(&EXACT_VALUES.to_string()));
    }

    /// Past [`EXACT_VALUES`] distinct values, the histogram's percentiles: within 0.1 %
    /// above the exact one, never above the maximum, and said to be so; the count,
    /// maximum and mean stay exact.
    #[test]
    fn many_distinct_values_take_the_histograms_percentiles_and_say_so() {
        let mut l = Latency::default();
        let n = 3 * EXACT_VALUES as u64;
        let value = |k: u64| 1_000_000 + 997 * k;
        for k in 0..n {
            l.record(value(k) as i64);
        }
        let p = l.percentiles().expect("values");
        assert!(!p.exact);
        assert_eq!(p.count, n);
        assert_eq!(p.max, value(n - 1));
        let exact_mean = (0..n).map(value).sum::<u64>() as f64 / n as f64;
        assert_eq!(p.mean, exact_mean);
        for (q, got) in [(0.5, p.p50), (0.9, p.p90), (0.99, p.p99), (0.999, p.p999)] {
            let rank = (q * n as f64).ceil() as u64;
            let exact = value(rank - 1);
            assert!(got >= exact && got <= p.max, "{q}: {got} against {exact}");
            assert!(
                (got - exact) as f64 <= exact as f64 * 1e-3,
                "{q}: {got} against {exact}"
            );
        }
        let last = crate::plots::read_hgrm(&l.hgrm()).pop().expect("lines");
        assert_eq!(last.1, p.max as f64 / 1000.0);
    }
}
