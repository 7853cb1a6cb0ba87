//! Mahimahi's delivery traces (`traces/` of Mahimahi, read by mm-link's
//! `LinkQueue`): one millisecond timestamp a line, non-decreasing, each an
//! opportunity to send [`OPPORTUNITY_BYTES`], looped.

use crate::ReplayError;

/// Bytes one trace line lets through: mm-link's `PACKET_SIZE`, the largest TUN
/// payload (an MTU of 1500 and the 4-byte TUN header).
pub const OPPORTUNITY_BYTES: u32 = 1504;

/// Most opportunities a trace may hold (the longest Mahimahi ships has 505,078): a
/// larger file is refused as it is read, before its lines are kept, so a trace of
/// 10^8 lines takes no more memory than this many (8 bytes each).
pub const MAX_OPPORTUNITIES: usize = 10_000_000;

/// A trace's delivery opportunities, ms from the link's start, looped with the last
/// line's time as the period (mm-link's `repeat`, its default).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Opportunities {
    times_ms: Vec<u64>,
    period_ms: u64,
}

impl Opportunities {
    /// Parses a trace as mm-link does (`LinkQueue`'s constructor): whole milliseconds,
    /// non-decreasing, at least one, the last after 0; blank lines are skipped (mm-link
    /// refuses them). The error names the line.
    pub fn parse(text: &str) -> Result<Opportunities, ReplayError> {
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
            if times.len() == MAX_OPPORTUNITIES {
                return Err(ReplayError::TooLong {
                    line: k + 1,
                    max: MAX_OPPORTUNITIES,
                });
            }
            times.push(v);
        }
        let Some(&last) = times.last() else {
            return Err(ReplayError::NoOpportunities);
        };
        if last == 0 {
            return Err(ReplayError::Instant);
        }
        Ok(Opportunities {
            times_ms: times,
            period_ms: last,
        })
    }

    /// Opportunity `k` (counted over the loops), ms: mm-link's `schedule_[k % len] +
    /// base`, its base advanced by the period at each wrap.
    pub fn time_ms(&self, k: u64) -> u64 {
        let len = self.times_ms.len() as u64;
        self.times_ms[(k % len) as usize].saturating_add((k / len).saturating_mul(self.period_ms))
    }

    /// The first opportunity after `ms`, found directly (an idle link skips the
    /// opportunities it would burn with nothing to send, without walking them).
    pub fn first_after(&self, ms: u64) -> u64 {
        let len = self.times_ms.len() as u64;
        let loops = ms / self.period_ms;
        let within = ms - loops * self.period_ms;
        let i = self.times_ms.partition_point(|&t| t <= within) as u64;
        loops.saturating_mul(len).saturating_add(i)
    }

    /// The opportunities in one loop.
    pub fn len(&self) -> usize {
        self.times_ms.len()
    }

    /// Never true: a trace has at least one opportunity.
    pub fn is_empty(&self) -> bool {
        self.times_ms.is_empty()
    }

    /// One loop's length, ms.
    pub fn period_ms(&self) -> u64 {
        self.period_ms
    }
}
