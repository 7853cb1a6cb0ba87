//! A rate over time: `time_ms,rate_bps` rows, each rate holding from its time until
//! the next row's, the last one on for good (a measured link's capacity, a handover's
//! outage as a rate of 0).

use crate::ReplayError;

/// Most rows a rate trace may hold (as a Mahimahi trace's opportunities).
pub const MAX_STEPS: usize = super::MAX_OPPORTUNITIES;

/// A rate over time, bit/s, in steps.
#[derive(Debug, Clone, PartialEq)]
pub struct RateSteps {
    /// Each step's start, ns; the first is 0, increasing.
    t_ns: Vec<u64>,
    /// Each step's rate, bit/s: finite, non-negative; the last positive.
    bps: Vec<f64>,
}

impl RateSteps {
    /// Parses `time_ms,rate_bps` (that header, then a row a step: whole milliseconds
    /// from 0, increasing; rates from 0 to 10^12 bit/s, the last above 0, so the link
    /// never stops for good). The error names the line.
    pub fn parse(text: &str) -> Result<RateSteps, ReplayError> {
        let mut lines = text.lines().enumerate();
        match lines.next() {
            Some((_, h)) if h.trim().replace(' ', "") == "time_ms,rate_bps" => {}
            Some((_, h)) => return Err(ReplayError::RateHeader(h.to_string())),
            None => return Err(ReplayError::NoSteps),
        }
        let (mut t_ns, mut bps) = (Vec::new(), Vec::<f64>::new());
        for (k, raw) in lines {
            let line = k + 1;
            let row = raw.trim();
            if row.is_empty() {
                continue;
            }
            let bad = |why: &'static str| ReplayError::RateRow {
                line,
                text: row.to_string(),
                why,
            };
            let Some((t, r)) = row.split_once(',') else {
                return Err(bad("expected 2 columns (time_ms,rate_bps)"));
            };
            let t: u64 = t
                .trim()
                .parse()
                .map_err(|_| bad("time_ms is no whole number of ms"))?;
            let r: f64 = r.trim().parse().map_err(|_| bad("rate_bps is no number"))?;
            if !r.is_finite() || !(0.0..=1e12).contains(&r) {
                return Err(bad("rate_bps is outside 0..=1e12"));
            }
            let t = t
                .checked_mul(1_000_000)
                .ok_or(bad("time_ms is too large"))?;
            match t_ns.last() {
                None if t != 0 => return Err(bad("the first row's time_ms must be 0")),
                Some(&last) if t <= last => return Err(bad("time_ms does not increase")),
                _ => {}
            }
            if t_ns.len() == MAX_STEPS {
                return Err(ReplayError::TooLong {
                    line,
                    max: MAX_STEPS,
                });
            }
            t_ns.push(t);
            bps.push(r);
        }
        match bps.last() {
            None => Err(ReplayError::NoSteps),
            Some(&r) if r <= 0.0 => Err(ReplayError::Stops),
            Some(_) => Ok(RateSteps { t_ns, bps }),
        }
    }

    /// When `bits` sent from `start` ns are all out, ns; `cursor` is the step the last
    /// call ended in (times only move forward, so the walk is short).
    pub fn finish(&self, cursor: &mut u64, start: u64, bits: f64) -> u64 {
        let mut i = (*cursor as usize).min(self.t_ns.len() - 1);
        while i + 1 < self.t_ns.len() && self.t_ns[i + 1] <= start {
            i += 1;
        }
        let (mut now, mut left) = (start, bits);
        loop {
            let rate = self.bps[i];
            let end = self.t_ns.get(i + 1).copied();
            let room = end.map_or(f64::INFINITY, |e| rate * (e - now) as f64 / 1e9);
            if rate > 0.0 && left <= room {
                *cursor = i as u64;
                return now.saturating_add((left * 1e9 / rate).ceil() as u64);
            }
            left -= room;
            // The last step's rate is positive, so the walk ends there at the latest.
            now = end.unwrap_or(now);
            i += 1;
        }
    }
}
