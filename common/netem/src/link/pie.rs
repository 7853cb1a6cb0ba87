//! PIE (RFC 8033): a FIFO whose arrivals are dropped at random with a probability
//! updated every `tupdate` from the queueing delay (here the sojourn time of the
//! packet last dequeued, the RFC's timestamp method, 0 once the queue is empty), its
//! deviation from the target weighted by alpha and its trend by beta, both scaled down
//! while the probability is small (the RFC's auto-tuning, §4.2), capped in steps of 2 %
//! above 10 %, decaying when the queue stays empty; a burst allowance lets the first
//! `max_burst` of a new congestion through. The updates run lazily, at the first call
//! at or past each `k * tupdate`: the same probabilities the RFC's timer gives. The
//! draws come from a seeded stream of the link's own.

use super::queue::{Bound, DropCause, Packet, Queue, Sub};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// The most updates [`Pie::catch_up`] runs at once (see there).
const MAX_CATCH_UP: u64 = 1_000_000;

/// PIE's parameters, RFC 8033's defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PieParams {
    /// The target queueing delay (QDELAY_REF), ns [15 ms].
    pub target_ns: u64,
    /// The drop probability's update period (T_UPDATE), ns [15 ms].
    pub tupdate_ns: u64,
    /// The weight of the deviation from the target, 1/s [0.125].
    pub alpha: f64,
    /// The weight of the delay's trend, 1/s [1.25].
    pub beta: f64,
    /// The burst allowance (MAX_BURST), ns [150 ms].
    pub max_burst_ns: u64,
    /// MEAN_PKTSIZE: no drop while the queue holds at most two of it, bytes [1000].
    pub mean_packet_bytes: u32,
}

impl Default for PieParams {
    fn default() -> PieParams {
        PieParams {
            target_ns: 15_000_000,
            tupdate_ns: 15_000_000,
            alpha: 0.125,
            beta: 1.25,
            max_burst_ns: 150_000_000,
            mean_packet_bytes: 1000,
        }
    }
}

/// PIE over one FIFO, bounded (drop-tail) by `bound` if set.
#[derive(Debug)]
pub struct Pie {
    q: Sub,
    params: PieParams,
    bound: Bound,
    rng: ChaCha8Rng,
    /// The drop probability.
    prob: f64,
    /// The queueing delay now and at the last update, s.
    qdelay: f64,
    qdelay_old: f64,
    /// The burst allowance left, ns.
    burst: u64,
    /// The next update's time, ns.
    next_update: u64,
}

impl Pie {
    /// PIE with `params`, refusing arrivals past `bound` (none: only the link's cap),
    /// drawing from `rng`.
    pub fn new(params: PieParams, bound: Bound, rng: ChaCha8Rng) -> Pie {
        Pie {
            q: Sub::default(),
            params,
            bound,
            rng,
            prob: 0.0,
            qdelay: 0.0,
            qdelay_old: 0.0,
            burst: params.max_burst_ns,
            next_update: 0,
        }
    }

    /// The drop probability now (for the checks).
    pub fn probability(&self) -> f64 {
        self.prob
    }

    /// Runs the updates due by `now`. At most [`MAX_CATCH_UP`] of them: a link idle
    /// that long (over four hours at the RFC's 15 ms), or a time from a peer's absurd
    /// sample number, would otherwise cost one update per period of the gap (a first
    /// number near 2^64 looped forever); the rest are skipped, the next due the first
    /// period after `now`.
    fn catch_up(&mut self, now: u64) {
        let period = self.params.tupdate_ns.max(1);
        let mut done = 0;
        while self.next_update <= now {
            if done == MAX_CATCH_UP {
                let behind = (now - self.next_update) / period + 1;
                self.next_update = self
                    .next_update
                    .saturating_add(behind.saturating_mul(period));
                if self.next_update <= now {
                    // Saturated at the end of time: no update is due ever again.
                    self.next_update = u64::MAX;
                }
                return;
            }
            self.update();
            done += 1;
            match self.next_update.checked_add(period) {
                Some(t) => self.next_update = t,
                None => return,
            }
        }
    }

    /// The RFC's `calculate_drop_prob`.
    fn update(&mut self) {
        let c = &self.params;
        let target = c.target_ns as f64 / 1e9;
        let mut p = c.alpha * (self.qdelay - target) + c.beta * (self.qdelay - self.qdelay_old);
        let scale = [
            (0.000_001, 2048.0),
            (0.000_01, 512.0),
            (0.000_1, 128.0),
            (0.001, 32.0),
            (0.01, 8.0),
            (0.1, 2.0),
        ];
        if let Some((_, s)) = scale.iter().find(|(below, _)| self.prob < *below) {
            p /= s;
        }
        if self.prob >= 0.1 && p > 0.02 {
            p = 0.02;
        }
        self.prob += p;
        if self.qdelay == 0.0 && self.qdelay_old == 0.0 {
            self.prob *= 0.98;
        }
        self.prob = self.prob.clamp(0.0, 1.0);
        self.burst = self.burst.saturating_sub(c.tupdate_ns);
        self.qdelay_old = self.qdelay;
    }

    /// The RFC's `drop_early`: a draw, unless the queue is short or the delay low.
    fn drop_early(&mut self) -> bool {
        let half = self.params.target_ns as f64 / 2e9;
        if (self.qdelay_old < half && self.prob < 0.2)
            || self.q.bytes <= 2 * u64::from(self.params.mean_packet_bytes)
        {
            return false;
        }
        self.rng.random::<f64>() < self.prob
    }
}

impl Queue for Pie {
    fn enqueue(&mut self, p: Packet, drops: &mut Vec<(Packet, DropCause)>) {
        self.catch_up(p.arrival_ns);
        let half = self.params.target_ns as f64 / 2e9;
        if self.prob == 0.0 && self.qdelay < half && self.qdelay_old < half {
            self.burst = self.params.max_burst_ns;
        }
        if self.burst == 0 && self.drop_early() {
            drops.push((p, DropCause::Aqm));
            return;
        }
        self.q.push_bounded(p, self.bound, drops);
    }

    fn dequeue(&mut self, now_ns: u64, _drops: &mut Vec<(Packet, DropCause)>) -> Option<Packet> {
        self.catch_up(now_ns);
        let p = self.q.pop()?;
        self.qdelay = if self.q.q.is_empty() {
            0.0
        } else {
            now_ns.saturating_sub(p.arrival_ns) as f64 / 1e9
        };
        Some(p)
    }

    fn len_packets(&self) -> usize {
        self.q.q.len()
    }

    fn len_bytes(&self) -> u64 {
        self.q.bytes
    }
}
