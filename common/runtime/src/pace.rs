//! Tick-aware waiting: sleep until just before the next sample is due, then poll.
//!
//! A process that polls all the time is preempted by whatever else wants its CPU and
//! waits out a scheduler tick (the loop's old 4 ms tail); under SCHED_FIFO it hits the
//! kernel's real-time throttle instead. A process that sleeps between samples and
//! polls only around the instant a sample is due has neither problem (docs/07-latency.md,
//! "Waiting"). The master knows its ticks; the emulator and the
//! slave learn when samples arrive from the arrivals themselves, with a [`Pacer`],
//! which keeps working when arrivals drift (another host's clock) or jitter (a real
//! network). The loop's driver ([`crate::driver`]) is the one that sleeps with it.

use tactile_messages::clock::{now_ns, sleep_until_ns};

/// How long before a sample is due a node wakes, at most: timer wake-ups of an
/// ordinary thread come up to ~100 us late here (slack plus the VM's wake-up cost).
pub const DEFAULT_WAKE_EARLY_NS: u64 = 200_000;

/// The default wake-up margin at sampling period `t_s_ns`: 200 us, at most 40 % of
/// the period (so at 10 kHz a node sleeps 60 us of every 100).
pub fn default_wake_early_ns(t_s_ns: u64) -> u64 {
    (t_s_ns * 2 / 5).min(DEFAULT_WAKE_EARLY_NS)
}

/// Nanoseconds from now until `deadline` added to [`now_ns`]: the deadline on the
/// clock the pacer works in.
pub fn deadline_ns(deadline: std::time::Instant) -> u64 {
    now_ns().saturating_add(
        deadline
            .saturating_duration_since(std::time::Instant::now())
            .as_nanos()
            .min(u128::from(u64::MAX / 2)) as u64,
    )
}

/// Late arrivals in a row after which the predicted phase moves later by the least of
/// their lateness: long enough that jitter (which only ever delays) does not pull the
/// prediction late, short enough to follow a clock drifting by 100 ppm (0.1 us per
/// sample at 1 kHz) within a microsecond or two.
pub const LATE_WINDOW: u32 = 16;

/// Predicts when the next sample of a periodic stream arrives.
///
/// Sample n of a stream is due at `offset + n t_s`; the offset is the earliest seen
/// recently: an arrival earlier than predicted moves it earlier at once; arrivals
/// later than predicted move it later only when [`LATE_WINDOW`] of them in a row were
/// all late, and then by the least of their lateness (so jitter, which only delays,
/// and a stall of the sender, which delays a few samples, leave it alone). A sample
/// that was already waiting when the node woke says only that it came at or before
/// that moment, so the offset moves to make it due then (at least a quarter of the
/// margin earlier), until samples are again seen arriving. Sequence numbers, not the nearest tick, say which sample
/// an arrival is: after a stall the queued samples come in a burst, and rounding to
/// the nearest tick would take a late one for the next one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pacer {
    period_ns: u64,
    early_ns: u64,
    /// Predicted arrival of sample 0, ns (may be before the clock's start).
    offset_ns: Option<i128>,
    /// Highest sequence number seen.
    last_seq: u64,
    late_min_ns: i128,
    late_seen: u32,
}

impl Pacer {
    /// A pacer for a stream with one sample every `period_ns`, waking `early_ns` before
    /// each predicted arrival.
    pub fn new(period_ns: u64, early_ns: u64) -> Self {
        Pacer {
            period_ns: period_ns.max(1),
            early_ns,
            offset_ns: None,
            last_seq: 0,
            late_min_ns: i128::MAX,
            late_seen: 0,
        }
    }

    /// The predicted arrival of the next sample, once one sample has come.
    pub fn next_ns(&self) -> Option<u64> {
        let o = self.offset_ns?;
        let t = o + (i128::from(self.last_seq) + 1) * i128::from(self.period_ns);
        Some(u64::try_from(t).unwrap_or(0))
    }

    /// When to stop sleeping and start polling for the next sample.
    pub fn wake_ns(&self) -> Option<u64> {
        self.next_ns().map(|n| n.saturating_sub(self.early_ns))
    }

    /// Sleeps until [`Pacer::wake_ns`], but never past `limit_ns` (a deadline of the
    /// caller's) nor longer than two periods (a wrong prediction then costs a poll,
    /// and a stop request is seen soon); returns at once before the first sample or
    /// when that time is past. True when it slept to the wake-up, so that a sample
    /// found at the first poll was waiting.
    pub fn sleep(&self, limit_ns: u64) -> bool {
        let now = now_ns();
        let cap = now.saturating_add(2 * self.period_ns);
        match self.wake_ns() {
            Some(w) if w.min(limit_ns).min(cap) > now => {
                sleep_until_ns(w.min(limit_ns).min(cap));
                w <= cap
            }
            _ => false,
        }
    }

    /// Takes in the arrival of sample `seq` at `t_ns`; `was_waiting`: it was already
    /// there at the first poll, so it came at or before `t_ns`.
    pub fn arrived(&mut self, seq: u64, t_ns: u64, was_waiting: bool) {
        let due_of = |o: i128| o + i128::from(seq) * i128::from(self.period_ns);
        let t = i128::from(t_ns);
        self.last_seq = self.last_seq.max(seq);
        let Some(o) = self.offset_ns else {
            self.offset_ns = Some(t - due_of(0));
            self.last_seq = seq;
            return;
        };
        let late = t - due_of(o);
        let o = if was_waiting {
            // It came at or before t: due no later than t, and a step of at least a
            // quarter of the margin so that the wake-up soon precedes it again.
            self.reset_window();
            o + late.min(-i128::from((self.early_ns / 4).max(1_000)))
        } else if late < 0 {
            self.reset_window();
            o + late
        } else {
            self.late_min_ns = self.late_min_ns.min(late);
            self.late_seen += 1;
            if self.late_seen >= LATE_WINDOW {
                let shift = self.late_min_ns;
                self.reset_window();
                o + shift
            } else {
                o
            }
        };
        self.offset_ns = Some(o);
    }

    fn reset_window(&mut self) {
        self.late_min_ns = i128::MAX;
        self.late_seen = 0;
    }
}

/// Whether a receive that started at `called_ns` and returned at `got_ns` found its
/// sample already waiting (the first poll costs well under this).
pub fn was_waiting(called_ns: u64, got_ns: u64) -> bool {
    got_ns.saturating_sub(called_ns) < FIRST_POLL_NS
}

/// Longest a first poll that finds a sample takes (measured: 0.1 to 1 us).
pub const FIRST_POLL_NS: u64 = 2_000;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const T: u64 = 1_000_000;
    const EARLY: u64 = 200_000;

    /// Feeds arrivals the way a node sees them: a sample that came before the node
    /// woke is seen at the wake-up, as already waiting. Returns the predictions.
    fn follow(arrivals: &[u64]) -> Vec<u64> {
        let mut p = Pacer::new(T, EARLY);
        let mut predicted = Vec::new();
        for (n, &a) in arrivals.iter().enumerate() {
            let wake = p.wake_ns().unwrap_or(0);
            predicted.push(p.next_ns().unwrap_or(a));
            if a < wake {
                p.arrived(n as u64, wake, true);
            } else {
                p.arrived(n as u64, a, false);
            }
        }
        predicted
    }

    #[test]
    fn a_steady_stream_is_predicted_exactly() {
        let arrivals: Vec<u64> = (0..100).map(|n| 5_000_000 + n * T + 37_000).collect();
        let p = follow(&arrivals);
        assert!(p.iter().zip(&arrivals).all(|(p, a)| p == a));
    }

    #[test]
    fn lost_samples_keep_the_phase() {
        let mut p = Pacer::new(T, EARLY);
        for n in [0u64, 1, 2, 5, 6, 9, 30] {
            p.arrived(n, 1_000_000 + n * T + 10_000, false);
        }
        assert_eq!(p.next_ns(), Some(1_000_000 + 31 * T + 10_000));
    }

    #[test]
    fn a_sample_waiting_at_wake_up_walks_the_phase_earlier_until_seen_arriving() {
        // The prediction starts 1 ms late (a restarted peer): samples are found
        // waiting, and the wake-up moves earlier until it precedes them again.
        let mut p = Pacer::new(T, EARLY);
        p.arrived(0, 2 * T, false);
        let truth = |n: u64| 2 * T + n * T - 600_000;
        let mut caught_up = None;
        for n in 1..200 {
            let a = truth(n);
            let wake = p.wake_ns().expect("wake");
            if a < wake {
                p.arrived(n, wake, true);
            } else {
                caught_up.get_or_insert(n);
                p.arrived(n, a, false);
            }
        }
        let n = caught_up.expect("caught up");
        // 600 us behind less the 200 us margin, 50 us a step: 8 steps.
        assert!(n <= 10, "took {n} samples");
        assert_eq!(p.next_ns(), Some(truth(200)));
    }

    #[test]
    fn a_stalled_sender_leaves_the_phase_alone() {
        // The sender stalls 800 us on sample 10, then sends on time: the late sample
        // is taken for what it is (sample 10, late), and sample 11 is predicted on time.
        let mut p = Pacer::new(T, EARLY);
        for n in 0..10 {
            p.arrived(n, 5 * T + n * T, false);
        }
        p.arrived(10, 5 * T + 10 * T + 800_000, false);
        assert_eq!(p.next_ns(), Some(5 * T + 11 * T));
        // A burst of queued samples after a longer stall: the same.
        for n in 11..15 {
            p.arrived(n, 5 * T + 15 * T + 3_000, false);
        }
        assert_eq!(p.next_ns(), Some(5 * T + 15 * T));
    }

    proptest! {
        /// Jitter only delays: the prediction stays at or after the stream's phase and
        /// never later than the phase plus the jitter bound, so the node always wakes
        /// before the sample and polls at most margin + jitter.
        #[test]
        fn jitter_keeps_the_prediction_at_the_early_edge(
            jitter in proptest::collection::vec(0u64..150_000, 50..400),
            phase in 0u64..T,
        ) {
            let arrivals: Vec<u64> = jitter
                .iter()
                .enumerate()
                .map(|(n, j)| 10 * T + phase + n as u64 * T + j)
                .collect();
            let predicted = follow(&arrivals);
            for (n, (p, a)) in predicted.iter().zip(&arrivals).enumerate().skip(1) {
                let tick = 10 * T + phase + n as u64 * T;
                prop_assert!(*p >= tick, "sample {n}: predicted {p} before the tick {tick}");
                prop_assert!(*p <= tick + 150_000, "sample {n}: predicted {p}");
                prop_assert!(p - EARLY <= *a);
            }
        }

        /// A sender's clock running fast or slow by up to 200 ppm (two hosts), with
        /// jitter: the prediction follows within the window's worth of drift plus the
        /// jitter.
        #[test]
        fn drift_is_followed(
            ppm in -200i64..200,
            jitter in proptest::collection::vec(0u64..20_000, 2000),
        ) {
            let period = (T as i64 + T as i64 * ppm / 1_000_000) as u64;
            let arrivals: Vec<u64> = jitter
                .iter()
                .enumerate()
                .map(|(n, j)| 10 * T + n as u64 * period + j)
                .collect();
            let predicted = follow(&arrivals);
            let slack = 20_000 + u64::from(LATE_WINDOW + 2) * ppm.unsigned_abs() * T / 1_000_000;
            for (n, (p, a)) in predicted.iter().zip(&arrivals).enumerate().skip(100) {
                let tick = 10 * T + n as u64 * period;
                prop_assert!(p.abs_diff(tick) <= slack, "sample {n}: {p} vs tick {tick}, arrival {a}");
            }
        }
    }
}
