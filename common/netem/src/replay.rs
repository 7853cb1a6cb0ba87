//! Recorded networks replayed packet by packet: per-packet delays and losses from a
//! CSV, or a Mahimahi delivery trace served first come first served.

use tactile_scenario::ReplayConfig;

/// What is wrong in a replay file; each message names the line.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReplayError {
    /// A CSV whose first line is not `delay,lost`.
    #[error("line 1: header is {0:?}, expected delay,lost")]
    Header(String),
    /// An empty CSV.
    #[error("empty: expected the header delay,lost")]
    Empty,
    /// A row of another number of columns.
    #[error("line {0}: expected 2 columns (delay,lost)")]
    Columns(usize),
    /// A delay that is no whole number of samples in range.
    #[error("line {line}: delay {delay} is not a whole number of samples in 0..=100000")]
    Delay {
        /// The line.
        line: usize,
        /// The delay as written.
        delay: String,
    },
    /// A loss that is neither 0 nor 1.
    #[error("line {line}: lost {lost} is not 0 or 1")]
    Lost {
        /// The line.
        line: usize,
        /// The loss as written.
        lost: String,
    },
    /// A header and nothing else.
    #[error("no packets after the header")]
    NoPackets,
    /// A Mahimahi line that is no whole number of milliseconds.
    #[error("line {line}: {text:?} is not a whole number of milliseconds")]
    NotMs {
        /// The line.
        line: usize,
        /// What it holds.
        text: String,
        /// Why it is no number.
        source: std::num::ParseIntError,
    },
    /// A Mahimahi time before the one above it.
    #[error("line {line}: {ms} ms goes back in time")]
    Backwards {
        /// The line.
        line: usize,
        /// The time.
        ms: u64,
    },
    /// A Mahimahi trace with no line.
    #[error("no delivery opportunities")]
    NoOpportunities,
    /// A Mahimahi trace of only time 0.
    #[error("the trace lasts 0 ms")]
    Instant,
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
    pub fn parse_csv(text: &str) -> Result<Replay, ReplayError> {
        let mut lines = text.lines().enumerate();
        match lines.next() {
            Some((_, h)) if h.trim().replace(' ', "") == "delay,lost" => {}
            Some((_, h)) => return Err(ReplayError::Header(h.to_string())),
            None => return Err(ReplayError::Empty),
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
                return Err(ReplayError::Columns(line));
            };
            let d: u32 = d
                .parse()
                .ok()
                .filter(|d| i64::from(*d) <= tactile_scenario::MAX_DELAY_SAMPLES)
                .ok_or_else(|| ReplayError::Delay {
                    line,
                    delay: d.to_string(),
                })?;
            let l = match l {
                "0" => false,
                "1" => true,
                other => {
                    return Err(ReplayError::Lost {
                        line,
                        lost: other.to_string(),
                    })
                }
            };
            out.push((d, l));
        }
        if out.is_empty() {
            return Err(ReplayError::NoPackets);
        }
        Ok(Replay::Packets(out, 0))
    }

    /// Parses a Mahimahi trace (one non-decreasing millisecond timestamp per line).
    pub fn parse_mahimahi(text: &str, cfg: &ReplayConfig) -> Result<Replay, ReplayError> {
        let mut times = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let t = line.trim();
            if t.is_empty() {
                continue;
            }
            let v: u64 = t.parse().map_err(|source| ReplayError::NotMs {
                line: k + 1,
                text: t.to_string(),
                source,
            })?;
            if times.last().is_some_and(|&last| v < last) {
                return Err(ReplayError::Backwards { line: k + 1, ms: v });
            }
            times.push(v);
        }
        let Some(&last) = times.last() else {
            return Err(ReplayError::NoOpportunities);
        };
        if last == 0 {
            return Err(ReplayError::Instant);
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
