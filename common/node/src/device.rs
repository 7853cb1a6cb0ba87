//! A device or robot outside the loop, as the loop sees it: its joint values mapped to
//! the paper's angles and checked, the newest sample kept, and each tick's judgement
//! of how fresh it is. Pure: the ROS 2 I/O that fills it is in `ros2`.
//!
//! The loop's tick stays the clock. Each tick takes the newest sample: fresh if it is
//! at most `stale_periods` periods old, stale (held, counted) if older, lost once the
//! device has been silent for `timeout_ms` (the master then renders zero force, the
//! slave holds its last safe reference). Whatever the device sends that is not a
//! well-formed message with finite, in-range values for the named joints is counted
//! and dropped before it reaches the slot.

use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use tactile_ros::msg::{Decode, JointState, WrenchStamped};
use tactile_scenario::{JointMapConfig, WatchConfig};

/// What a device or robot delivered and how the loop judged it, for the record and
/// the summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct DeviceCounters {
    /// Messages received on the device's topics.
    pub messages: u64,
    /// Messages dropped: not decodable, a named joint missing, a value not finite or
    /// out of range.
    pub rejected: u64,
    /// Ticks that took a fresh sample.
    pub fresh: u64,
    /// Ticks that held a stale sample.
    pub stale: u64,
    /// Ticks with the device lost (or not heard from yet).
    pub lost: u64,
    /// Times the device was lost.
    pub losses: u64,
    /// Messages published to the device (forces, joint commands).
    pub published: u64,
    /// Messages that could not be published.
    pub publish_errors: u64,
    /// Ticks whose force-torque reading was older than the timeout, or not there yet:
    /// zero force used, never a stale contact.
    pub force_lost: u64,
}

/// Why a message was dropped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Reject {
    /// Not a well-formed message of the topic's type.
    #[error("not a well-formed message: {0}")]
    Malformed(#[from] tactile_ros::CdrError),
    /// A named joint is not in the message (or has no position).
    #[error("joint {0:?} is missing")]
    Missing(String),
    /// A value is NaN or infinite.
    #[error("joint {0:?} is not finite")]
    NotFinite(String),
    /// A value outside the configured range.
    #[error("joint {joint:?} at {value} rad is outside {min}..={max}")]
    OutOfRange {
        /// The joint.
        joint: String,
        /// Its angle, rad (the paper's convention).
        value: f64,
        /// Smallest accepted.
        min: f64,
        /// Largest accepted.
        max: f64,
    },
    /// A force that is NaN or infinite.
    #[error("force is not finite")]
    ForceNotFinite,
}

/// Three named joints of a `JointState`, in the paper's convention.
#[derive(Debug, Clone)]
pub struct JointMap {
    names: [String; 3],
    cfg: JointMapConfig,
}

impl JointMap {
    /// The map for joints `names` under `cfg`.
    pub fn new(names: [String; 3], cfg: JointMapConfig) -> JointMap {
        JointMap { names, cfg }
    }

    /// The paper's angles from a CDR `JointState`.
    pub fn angles_cdr(&self, cdr: &[u8]) -> Result<[f64; 3], Reject> {
        self.angles(&JointState::from_cdr(cdr)?)
    }

    /// The paper's angles from a `JointState`: theta = sign raw unit + offset.
    pub fn angles(&self, js: &JointState) -> Result<[f64; 3], Reject> {
        let mut theta = [0.0; 3];
        for (i, name) in self.names.iter().enumerate() {
            let raw = js
                .name
                .iter()
                .position(|n| n == name)
                .and_then(|k| js.position.get(k))
                .ok_or_else(|| Reject::Missing(name.clone()))?;
            let t = self.cfg.sign[i] * raw * self.cfg.unit.radians() + self.cfg.offset[i];
            if !t.is_finite() {
                return Err(Reject::NotFinite(name.clone()));
            }
            let (min, max) = (self.cfg.min[i], self.cfg.max[i]);
            if !(min..=max).contains(&t) {
                return Err(Reject::OutOfRange {
                    joint: name.clone(),
                    value: t,
                    min,
                    max,
                });
            }
            theta[i] = t;
        }
        Ok(theta)
    }

    /// The driver's values for the paper's angles (the inverse map), for commands;
    /// each angle first clamped to the joint's `min..=max`, so a robot is never
    /// commanded where its readings would be refused.
    pub fn raw(&self, theta: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|i| {
            let t = theta[i].clamp(self.cfg.min[i], self.cfg.max[i]);
            (t - self.cfg.offset[i]) / (self.cfg.sign[i] * self.cfg.unit.radians())
        })
    }
}

/// A force from a CDR `WrenchStamped`, N; not finite is rejected.
pub fn force_cdr(cdr: &[u8]) -> Result<[f64; 3], Reject> {
    let w = WrenchStamped::from_cdr(cdr)?;
    if w.force.iter().all(|f| f.is_finite()) {
        Ok(w.force)
    } else {
        Err(Reject::ForceNotFinite)
    }
}

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

impl<T: Copy> Inbox<T> {
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
        self.latest.lock().ok().and_then(|l| *l)
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
    pub fn judge<T: Copy>(
        &mut self,
        latest: Option<Latest<T>>,
        now_ns: u64,
    ) -> (Reading<T>, Change) {
        let age = latest.map(|l| now_ns.saturating_sub(l.at_ns));
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
            (false, true) if latest.is_some() => {
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

/// A real master device, as the master's loop uses it: encoders in, force out.
pub trait HapticDevice {
    /// True once a good message has come.
    fn heard(&self) -> bool;
    /// The encoders' newest angles at this tick, judged.
    fn read(&mut self, now_ns: u64) -> (Reading<[f64; 3]>, Change);
    /// Sends the force to render, N, in the device's base frame.
    fn render(&mut self, force: [f64; 3], now_ns: u64);
    /// What it delivered and how it was judged.
    fn counters(&self) -> DeviceCounters;
    /// The first message dropped since the last call, for the log.
    fn take_reject(&self) -> Option<Reject>;
    /// Where it is read from, for messages.
    fn describe(&self) -> String;
}

/// A real slave robot, as the slave's loop uses it: joint references out, joint
/// angles and (when it has a sensor) the contact force in.
pub trait Robot {
    /// True once a good message has come.
    fn heard(&self) -> bool;
    /// The joints' newest angles at this tick, judged.
    fn read(&mut self, now_ns: u64) -> (Reading<[f64; 3]>, Change);
    /// The contact force at this tick, N in the paper's frame, if the robot has a
    /// force sensor (else the environment model gives it); zero when the sensor's
    /// newest reading is older than the timeout.
    fn force(&mut self, now_ns: u64) -> Option<[f64; 3]>;
    /// Sends the joint references, rad in the paper's convention.
    fn command(&mut self, theta_ref: [f64; 3], now_ns: u64);
    /// What it delivered and how it was judged.
    fn counters(&self) -> DeviceCounters;
    /// The first message dropped since the last call, for the log.
    fn take_reject(&self) -> Option<Reject>;
    /// Where it is read from, for messages.
    fn describe(&self) -> String;
}

/// Where a loop hands its state for the live view: takes it only every k-th sample,
/// and never blocks.
pub trait LiveSink<S> {
    /// True if sample `n` is one the live view publishes.
    fn due(&self, n: u64) -> bool;
    /// Hands the state over (dropped and counted if the publisher is behind).
    fn offer(&mut self, state: S);
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_ros::msg::{Header, Message};
    use tactile_scenario::AngleUnit;

    fn js(names: &[&str], pos: &[f64]) -> JointState {
        JointState {
            header: Header::at(1, "base"),
            name: names.iter().map(|s| s.to_string()).collect(),
            position: pos.to_vec(),
            ..JointState::default()
        }
    }

    fn map() -> JointMap {
        let cfg = JointMapConfig {
            sign: [1.0, -1.0, 1.0],
            offset: [0.0, 0.0, 0.5],
            unit: AngleUnit::Deg,
            ..JointMapConfig::default()
        };
        JointMap::new(["a".into(), "b".into(), "c".into()], cfg)
    }

    #[test]
    fn joints_are_found_by_name_and_mapped_both_ways() {
        let m = map();
        let got = m.angles(&js(&["x", "c", "b", "a"], &[9.0, 90.0, 45.0, 180.0]));
        let pi = std::f64::consts::PI;
        let want = [pi, -pi / 4.0, pi / 2.0 + 0.5];
        let t = got.expect("mapped");
        for i in 0..3 {
            assert!((t[i] - want[i]).abs() < 1e-12, "{t:?}");
        }
        let raw = m.raw(t);
        for (r, w) in raw.iter().zip([180.0, 45.0, 90.0]) {
            assert!((r - w).abs() < 1e-9, "{raw:?}");
        }
    }

    #[test]
    fn missing_non_finite_and_out_of_range_values_are_rejected() {
        let m = map();
        assert_eq!(
            m.angles(&js(&["a", "b"], &[0.0, 0.0])),
            Err(Reject::Missing("c".into()))
        );
        assert_eq!(
            m.angles(&js(&["a", "b", "c"], &[0.0, 0.0])),
            Err(Reject::Missing("c".into())),
            "a name without a position"
        );
        assert_eq!(
            m.angles(&js(&["a", "b", "c"], &[0.0, f64::NAN, 0.0])),
            Err(Reject::NotFinite("b".into()))
        );
        assert!(matches!(
            m.angles(&js(&["a", "b", "c"], &[400.0, 0.0, 0.0])),
            Err(Reject::OutOfRange { .. })
        ));
        assert!(matches!(
            m.angles_cdr(&[1, 2, 3]),
            Err(Reject::Malformed(_))
        ));
        let w = WrenchStamped {
            force: [0.0, f64::INFINITY, 0.0],
            ..WrenchStamped::default()
        };
        assert_eq!(force_cdr(&w.to_cdr()), Err(Reject::ForceNotFinite));
    }

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
    fn commands_stay_in_range_and_an_old_force_is_not_used() {
        let m = map();
        assert!(
            (m.raw([10.0, 0.0, 0.0])[0] - 180.0).abs() < 1e-9,
            "clamped to pi"
        );
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
