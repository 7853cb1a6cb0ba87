//! How fresh a device's newest sample is at each tick of the loop, and what came and
//! was dropped. Pure: the subscriptions that fill an [`Inbox`] are in
//! [`crate::ros_devices`].
//!
//! The loop's tick stays the clock. Each tick takes the newest sample: fresh if it is
//! at most `stale_periods` periods old, stale (held, counted) if older, lost once the
//! device has been silent for `timeout_ms` (the master then renders zero force, the
//! slave holds its last safe reference). Whatever the device sends that is not a
//! well-formed message with finite, in-range values for the named joints is counted
//! and dropped before it reaches the slot.

use crate::map::Reject;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use tactile_records::device::DeviceCounters;
use tactile_scenario::WatchConfig;

/// The newest accepted value of a device's topic and when it arrived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Latest<T> {
    /// The value.
    pub value: T,
    /// Arrival time, CLOCK_MONOTONIC ns.
    pub at_ns: u64,
}

/// What a subscriber fills and the loop reads: the newest accepted value, and counts
/// of what came and what was dropped (filled from the transport's threads).
#[derive(Debug)]
pub struct Inbox<T> {
    latest: Mutex<Option<Latest<T>>>,
    messages: AtomicU64,
    rejected: AtomicU64,
    /// The first rejection of each second, for the log.
    last_reject: Mutex<Option<Reject>>,
}

impl<T: Clone> Inbox<T> {
    /// An empty inbox.
    pub fn new() -> Arc<Inbox<T>> {
        Arc::new(Inbox {
            latest: Mutex::new(None),
            messages: AtomicU64::new(0),
            rejected: AtomicU64::new(0),
            last_reject: Mutex::new(None),
        })
    }

    /// One message's outcome, arriving at `at_ns`.
    pub fn offer(&self, got: Result<T, Reject>, at_ns: u64) {
        self.messages.fetch_add(1, Ordering::Relaxed);
        match got {
            Ok(value) => {
                if let Ok(mut l) = self.latest.lock() {
                    *l = Some(Latest { value, at_ns });
                }
            }
            Err(e) => {
                self.rejected.fetch_add(1, Ordering::Relaxed);
                if let Ok(mut r) = self.last_reject.lock() {
                    r.get_or_insert(e);
                }
            }
        }
    }

    /// The newest accepted value.
    pub fn latest(&self) -> Option<Latest<T>> {
        self.latest.lock().ok().and_then(|l| l.clone())
    }

    /// Messages received and rejected so far.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.messages.load(Ordering::Relaxed),
            self.rejected.load(Ordering::Relaxed),
        )
    }

    /// The first rejection since the last call (for a once-a-second log line).
    pub fn take_reject(&self) -> Option<Reject> {
        self.last_reject.lock().ok().and_then(|mut r| r.take())
    }
}

/// How fresh the device's newest sample is at a tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reading<T> {
    /// Within `stale_periods`.
    Fresh(T),
    /// Older, but the device is not lost yet: the value is held.
    Stale(T),
    /// Silent past the timeout, or never heard from.
    Lost,
}

impl<T> Reading<T> {
    /// The same judgement of `f` of the value.
    pub fn map<U>(self, f: impl FnOnce(T) -> U) -> Reading<U> {
        match self {
            Reading::Fresh(t) => Reading::Fresh(f(t)),
            Reading::Stale(t) => Reading::Stale(f(t)),
            Reading::Lost => Reading::Lost,
        }
    }
}

/// Judges each tick's sample and counts the judgements.
#[derive(Debug, Clone)]
pub struct Watch {
    stale_ns: u64,
    timeout_ns: u64,
    lost: bool,
    counters: DeviceCounters,
}

/// What changed at a tick, for the record's events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Change {
    /// Nothing.
    None,
    /// The device was just lost.
    Lost,
    /// The device is back after a loss.
    Back,
}

impl Watch {
    /// A watch for a loop of period `t_s_ns`.
    pub fn new(cfg: &WatchConfig, t_s_ns: u64) -> Watch {
        Watch {
            stale_ns: u64::from(cfg.stale_periods) * t_s_ns,
            timeout_ns: (cfg.timeout_ms * 1e6) as u64,
            lost: false,
            counters: DeviceCounters::default(),
        }
    }

    /// Judges `latest` at `now_ns`.
    pub fn judge<T: Clone>(
        &mut self,
        latest: Option<Latest<T>>,
        now_ns: u64,
    ) -> (Reading<T>, Change) {
        let heard = latest.is_some();
        let age = latest.as_ref().map(|l| now_ns.saturating_sub(l.at_ns));
        let reading = match (latest, age) {
            (Some(l), Some(a)) if a <= self.stale_ns => Reading::Fresh(l.value),
            (Some(l), Some(a)) if a <= self.timeout_ns => Reading::Stale(l.value),
            _ => Reading::Lost,
        };
        let was_lost = self.lost;
        self.lost = matches!(reading, Reading::Lost);
        match reading {
            Reading::Fresh(_) => self.counters.fresh += 1,
            Reading::Stale(_) => self.counters.stale += 1,
            Reading::Lost => self.counters.lost += 1,
        }
        let change = match (was_lost, self.lost) {
            (false, true) if heard => {
                self.counters.losses += 1;
                Change::Lost
            }
            (true, false) => Change::Back,
            _ => Change::None,
        };
        (reading, change)
    }

    /// A force-torque reading at this tick: the newest if it is within the timeout,
    /// else zero force, counted.
    pub fn force(&mut self, latest: Option<Latest<[f64; 3]>>, now_ns: u64) -> [f64; 3] {
        match latest {
            Some(l) if now_ns.saturating_sub(l.at_ns) <= self.timeout_ns => l.value,
            _ => {
                self.counters.force_lost += 1;
                [0.0; 3]
            }
        }
    }

    /// True if a value that arrived at `at_ns` is within the timeout at `now_ns`.
    pub fn fresh(&self, at_ns: u64, now_ns: u64) -> bool {
        now_ns.saturating_sub(at_ns) <= self.timeout_ns
    }

    /// Counts what the gate did with a command.
    pub fn gated<V>(&mut self, p: &crate::gate::Passed<V>) {
        match p {
            crate::gate::Passed::As(_) => {}
            crate::gate::Passed::Cut(_) => self.counters.limited += 1,
            crate::gate::Passed::Held(_) => self.counters.gated += 1,
        }
    }

    /// The force gate's ramps so far.
    pub fn ramps(&mut self, ramps: u64) {
        self.counters.ramps = ramps;
    }

    /// Notes the end's zero or hold: sent, and heard by a subscriber.
    pub fn released(&mut self, heard: bool) {
        self.counters.released = heard;
    }

    /// Counts one publication and its outcome.
    pub fn published(&mut self, ok: bool) {
        if ok {
            self.counters.published += 1;
        } else {
            self.counters.publish_errors += 1;
        }
    }

    /// The counters, with the inboxes' message counts `(messages, rejected)` added.
    pub fn counters(&self, inboxes: &[(u64, u64)]) -> DeviceCounters {
        let mut c = self.counters;
        for (m, r) in inboxes {
            c.messages += m;
            c.rejected += r;
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sample_ages_from_fresh_to_stale_to_lost_and_comes_back() {
        let cfg = WatchConfig {
            stale_periods: 2,
            timeout_ms: 10.0,
        };
        let ms = 1_000_000;
        let mut w = Watch::new(&cfg, ms);
        let l = Some(Latest {
            value: 1.0,
            at_ns: 100 * ms,
        });
        assert_eq!(
            w.judge::<f64>(None, 0),
            (Reading::Lost, Change::None),
            "never heard"
        );
        assert_eq!(w.judge(l, 102 * ms).0, Reading::Fresh(1.0));
        assert_eq!(w.judge(l, 103 * ms).0, Reading::Stale(1.0));
        assert_eq!(w.judge(l, 110 * ms).0, Reading::Stale(1.0));
        assert_eq!(w.judge(l, 111 * ms), (Reading::Lost, Change::Lost));
        assert_eq!(w.judge(l, 112 * ms), (Reading::Lost, Change::None));
        let l2 = Some(Latest {
            value: 2.0,
            at_ns: 112 * ms,
        });
        assert_eq!(w.judge(l2, 112 * ms), (Reading::Fresh(2.0), Change::Back));
        let c = w.counters(&[(5, 1)]);
        assert_eq!((c.fresh, c.stale, c.lost, c.losses), (2, 2, 3, 1));
        assert_eq!((c.messages, c.rejected), (5, 1));
    }

    #[test]
    fn an_old_force_is_not_used() {
        let mut w = Watch::new(&WatchConfig::default(), 1_000_000);
        let l = Some(Latest {
            value: [1.0, 2.0, 3.0],
            at_ns: 0,
        });
        assert_eq!(w.force(l, 50_000_000), [1.0, 2.0, 3.0]);
        assert_eq!(w.force(l, 150_000_000), [0.0; 3]);
        assert_eq!(w.force(None, 0), [0.0; 3]);
        assert_eq!(w.counters(&[]).force_lost, 2);
    }

    #[test]
    fn an_inbox_keeps_the_newest_good_value_and_counts_the_bad() {
        let inbox = Inbox::new();
        inbox.offer(Ok(1.0), 5);
        inbox.offer(Err(Reject::NotFinite("a".into())), 6);
        inbox.offer(Ok(2.0), 7);
        assert_eq!(
            inbox.latest(),
            Some(Latest {
                value: 2.0,
                at_ns: 7
            })
        );
        assert_eq!(inbox.counts(), (3, 1));
        assert_eq!(inbox.take_reject(), Some(Reject::NotFinite("a".into())));
        assert_eq!(inbox.take_reject(), None);
    }
}
