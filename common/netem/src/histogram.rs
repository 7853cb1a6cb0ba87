//! Delay histograms: each packet's whole delay drawn from a measured distribution (a
//! histogram file, `tactile_scenario::HistogramConfig`), as DETERMINISTIC6G's
//! NetworkDelayEmulator draws it: a bin by its count, then a delay uniform within the
//! bin (its `userspace_delay` draws a whole number of ns from the bin's lower edge to
//! its upper, both included; here the draw is continuous, a difference below 1 ns).
//! That is the inverse of the histogram's CDF (linear within each bin) at a uniform
//! u; u is the same Gaussian AR(1) process as the jitter's through the normal CDF (a
//! Gaussian copula), so successive delays can be correlated (which that emulator,
//! drawing its delays ahead of the packets, cannot) with the marginal unchanged: the
//! rank correlation of successive delays is (6/pi) asin(C/2).

use crate::jitter::{phi, Ar1};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use tactile_scenario::HistogramFormat;

/// What is wrong in a histogram file; each message names the line and the column.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HistogramError {
    /// A CSV whose first line is not `delay_ms,count`.
    #[error("line 1: header is {0:?}, expected delay_ms,count")]
    Header(String),
    /// A line of another number of columns.
    #[error("line {line}: expected {want} columns ({columns})")]
    Columns {
        /// The line.
        line: usize,
        /// How many the format has.
        want: usize,
        /// Their names.
        columns: &'static str,
    },
    /// A cell that is no finite number.
    #[error("line {line}: {column} {text:?} is not a finite number")]
    NotNumber {
        /// The line.
        line: usize,
        /// The column's name.
        column: &'static str,
        /// What it holds.
        text: String,
    },
    /// A unit the D6G format does not have.
    #[error("line {line}: unit {text:?} is not ns, us, ms or s")]
    Unit {
        /// The line.
        line: usize,
        /// What it holds.
        text: String,
    },
    /// A bin edge below zero.
    #[error("line {line}: {column} {ms} ms is negative: a channel cannot deliver before sending")]
    Negative {
        /// The line.
        line: usize,
        /// The column's name.
        column: &'static str,
        /// The edge, ms.
        ms: f64,
    },
    /// A bin edge not above the one before.
    #[error("line {line}: {column} {ms} ms is not above the line before's {before} ms: bins must increase")]
    NotIncreasing {
        /// The line.
        line: usize,
        /// The column's name.
        column: &'static str,
        /// The edge, ms.
        ms: f64,
        /// The edge before, ms.
        before: f64,
    },
    /// A negative count.
    #[error("line {line}: count {count} is negative")]
    NegativeCount {
        /// The line.
        line: usize,
        /// The count.
        count: f64,
    },
    /// A last line with a count: it closes the last bin, which would have no end.
    #[error("line {line}: count {count} on the last line: the last line gives the last bin's upper edge, so its count must be 0")]
    OpenEnd {
        /// The line.
        line: usize,
        /// The count.
        count: f64,
    },
    /// Fewer than two lines: no bin.
    #[error("no bin: a histogram needs a line for each bin's lower edge and a last one for the upper edge")]
    NoBin,
    /// Counts that add up to zero (or beyond any number).
    #[error("count: the counts add up to {0}, not a positive finite total")]
    Total(f64),
    /// An edge beyond the longest delay a channel applies.
    #[error("line {line}: {column} {ms} ms is {samples} samples at {rate_hz} Hz, beyond {max}")]
    TooLong {
        /// The line.
        line: usize,
        /// The column's name.
        column: &'static str,
        /// The edge, ms.
        ms: f64,
        /// The edge, samples.
        samples: f64,
        /// The scenario's rate.
        rate_hz: f64,
        /// The longest delay, samples.
        max: i64,
    },
}

/// A histogram as read: bin edges (ms, or samples after [`DelayHistogram::in_samples`])
/// and the CDF at each edge.
#[derive(Debug, Clone, PartialEq)]
pub struct DelayHistogram {
    edges: Vec<f64>,
    cdf: Vec<f64>,
    /// The line of the last edge, and its column's name (for [`HistogramError::TooLong`]).
    last: (usize, &'static str),
}

/// One parsed line: its number, its edge in ms, its count.
type Row = (usize, f64, f64);

impl DelayHistogram {
    /// Reads a histogram in `format`; the error names the line and the column.
    pub fn parse(text: &str, format: HistogramFormat) -> Result<DelayHistogram, HistogramError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(k, l)| (k + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());
        let column = match format {
            HistogramFormat::Csv => {
                match lines.next() {
                    Some((_, h)) if h.replace(' ', "") == "delay_ms,count" => {}
                    Some((_, h)) => return Err(HistogramError::Header(h.to_string())),
                    None => return Err(HistogramError::NoBin),
                }
                "delay_ms"
            }
            HistogramFormat::D6g => "lower",
            HistogramFormat::D6gData => "lower_ms",
        };
        let rows = lines
            .map(|(line, l)| row(line, l, format, column))
            .collect::<Result<Vec<Row>, _>>()?;
        Self::of_rows(&rows, column)
    }

    /// The histogram of rows (edge, count) checked: edges non-negative and increasing,
    /// counts non-negative, the last 0, the total positive.
    fn of_rows(rows: &[Row], column: &'static str) -> Result<DelayHistogram, HistogramError> {
        let mut before: Option<f64> = None;
        for &(line, ms, count) in rows {
            if ms < 0.0 {
                return Err(HistogramError::Negative { line, column, ms });
            }
            if let Some(b) = before.filter(|b| ms <= *b) {
                return Err(HistogramError::NotIncreasing {
                    line,
                    column,
                    ms,
                    before: b,
                });
            }
            before = Some(ms);
            if count < 0.0 {
                return Err(HistogramError::NegativeCount { line, count });
            }
        }
        let (Some(&(last_line, _, last_count)), true) = (rows.last(), rows.len() >= 2) else {
            return Err(HistogramError::NoBin);
        };
        if last_count != 0.0 {
            return Err(HistogramError::OpenEnd {
                line: last_line,
                count: last_count,
            });
        }
        let total: f64 = rows.iter().map(|r| r.2).sum();
        if !(total.is_finite() && total > 0.0) {
            return Err(HistogramError::Total(total));
        }
        let mut cdf = Vec::with_capacity(rows.len());
        let mut sum = 0.0;
        for r in rows {
            cdf.push(sum / total);
            sum += r.2;
        }
        // The rounding of the sums must not leave the top below 1.
        if let Some(top) = cdf.last_mut() {
            *top = 1.0;
        }
        Ok(DelayHistogram {
            edges: rows.iter().map(|r| r.1).collect(),
            cdf,
            last: (last_line, column),
        })
    }

    /// The same histogram in samples at `rate_hz` (fractional: the channel rounds each
    /// packet's delay to the nearest whole sample, as it does a jittered one); an
    /// edge beyond `max_samples` is refused, naming its line.
    pub fn in_samples(
        &self,
        rate_hz: f64,
        max_samples: i64,
    ) -> Result<DelayHistogram, HistogramError> {
        let per_ms = rate_hz / 1000.0;
        let top = self.edges.last().copied().unwrap_or(0.0);
        if top * per_ms > max_samples as f64 {
            let (line, column) = self.last;
            return Err(HistogramError::TooLong {
                line,
                column,
                ms: top,
                samples: top * per_ms,
                rate_hz,
                max: max_samples,
            });
        }
        Ok(DelayHistogram {
            edges: self.edges.iter().map(|e| e * per_ms).collect(),
            ..self.clone()
        })
    }

    /// The delay at quantile `u` (0 to 1): the inverse CDF, linear within each bin.
    pub fn quantile(&self, u: f64) -> f64 {
        // The first edge whose CDF is above u closes u's bin (an empty bin, whose CDF
        // does not rise, is never it).
        let j = self.cdf.partition_point(|c| *c <= u);
        if j == 0 {
            return self.edges[0];
        }
        if j >= self.cdf.len() {
            return self.edges[self.edges.len() - 1];
        }
        let (c0, c1) = (self.cdf[j - 1], self.cdf[j]);
        let (e0, e1) = (self.edges[j - 1], self.edges[j]);
        e0 + (u - c0) / (c1 - c0) * (e1 - e0)
    }

    /// The probability of a delay at most `x` (the histogram's CDF).
    pub fn cdf(&self, x: f64) -> f64 {
        let j = self.edges.partition_point(|e| *e <= x);
        if j == 0 {
            return 0.0;
        }
        if j >= self.edges.len() {
            return 1.0;
        }
        let (e0, e1) = (self.edges[j - 1], self.edges[j]);
        let (c0, c1) = (self.cdf[j - 1], self.cdf[j]);
        c0 + (x - e0) / (e1 - e0) * (c1 - c0)
    }

    /// The bin edges (ms, or samples after [`DelayHistogram::in_samples`]).
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }

    /// The longest delay it gives (the last edge).
    pub fn bound(&self) -> f64 {
        self.edges.last().copied().unwrap_or(0.0)
    }
}

/// Line `line` of a histogram file in `format`: its edge in ms and its count.
fn row(
    line: usize,
    l: &str,
    format: HistogramFormat,
    column: &'static str,
) -> Result<Row, HistogramError> {
    let cells: Vec<&str> = match format {
        HistogramFormat::D6gData => l.split_whitespace().collect(),
        _ => l.split(',').map(str::trim).collect(),
    };
    let (want, columns) = match format {
        HistogramFormat::Csv => (2, "delay_ms,count"),
        HistogramFormat::D6g => (3, "lower,count,unit"),
        HistogramFormat::D6gData => (2, "lower_ms TAB count"),
    };
    if cells.len() != want {
        return Err(HistogramError::Columns {
            line,
            want,
            columns,
        });
    }
    let edge = number(line, column, cells[0])?;
    let count = number(line, "count", cells[1])?;
    let ms = match format {
        HistogramFormat::D6g => edge * unit_ms(line, cells[2])?,
        _ => edge,
    };
    Ok((line, ms, count))
}

/// A cell as a finite number.
fn number(line: usize, column: &'static str, text: &str) -> Result<f64, HistogramError> {
    text.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| HistogramError::NotNumber {
            line,
            column,
            text: text.to_string(),
        })
}

/// A D6G unit in ms.
fn unit_ms(line: usize, unit: &str) -> Result<f64, HistogramError> {
    match unit {
        "ns" => Ok(1e-6),
        "us" => Ok(1e-3),
        "ms" => Ok(1.0),
        "s" => Ok(1e3),
        other => Err(HistogramError::Unit {
            line,
            text: other.to_string(),
        }),
    }
}

/// One channel's delays drawn from a histogram (in samples), correlated.
#[derive(Debug, Clone)]
pub struct HistogramDelay {
    histogram: DelayHistogram,
    z: Ar1,
}

impl HistogramDelay {
    /// The process over `histogram` with lag-1 correlation `correlation` (in [0, 1))
    /// of its driving Gaussian.
    pub fn new(histogram: DelayHistogram, correlation: f64) -> Self {
        HistogramDelay {
            histogram,
            z: Ar1::new(correlation),
        }
    }

    /// The next packet's delay (continuous; the channel rounds it).
    pub fn next(&mut self, rng: &mut impl Rng) -> f64 {
        let e: f64 = StandardNormal.sample(rng);
        self.next_with(e)
    }

    /// The next delay with the given standard normal innovation.
    pub fn next_with(&mut self, e: f64) -> f64 {
        let z = self.z.next(e);
        self.histogram.quantile(phi(z))
    }

    /// The longest delay it gives.
    pub fn bound(&self) -> f64 {
        self.histogram.bound()
    }
}

/// What draws each packet's delay on a channel: jitter around the configured delay,
/// or a histogram (the whole delay).
#[derive(Debug, Clone)]
pub enum Drawn {
    /// netem's jitter.
    Jitter(crate::Jitter),
    /// A delay histogram.
    Histogram(HistogramDelay),
}

impl Drawn {
    /// The next packet's draw, samples.
    pub fn next(&mut self, rng: &mut impl Rng) -> f64 {
        match self {
            Drawn::Jitter(j) => j.next(rng),
            Drawn::Histogram(h) => h.next(rng),
        }
    }

    /// The next draw with the given standard normal innovation.
    pub fn next_with(&mut self, e: f64) -> f64 {
        match self {
            Drawn::Jitter(j) => j.next_with(e),
            Drawn::Histogram(h) => h.next_with(e),
        }
    }
}

#[cfg(test)]
#[path = "histogram_tests.rs"]
mod tests;
