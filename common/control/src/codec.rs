//! Fewer packets and the receiver's guess for the ones not sent: the perceptual
//! deadband codec at each sender and the predictors (the paper's CPD/JPD blocks) at
//! each receiver, as pure per-sample state machines.
//!
//! Deadband (Hinterseer, Hirche, Chaudhuri, Steinbach, Buss, "Perception-based data
//! reduction and transmission of haptic data in telepresence and teleaction systems",
//! IEEE TSP 56(2), 2008): a sample is sent only when it differs from the last one sent
//! by more than a fraction k of that one (Weber's law: the just noticeable difference
//! grows with the magnitude), plus an absolute floor near zero. Velocity-adaptive
//! (Kammerl, Vittorias, Nitsch, Faerber, Steinbach, Hirche, "Perception-based data
//! reduction for haptic force-feedback signals using velocity-adaptive deadbands",
//! Presence 19(5), 2010): the fraction grows with the speed of the device, k (1 + |v| /
//! v_ref), since a moving hand perceives less. Positions are compared relative to the
//! device's home (the workspace's origin for the hand), forces as they are.
//!
//! A sample not sent still crosses the processes as the loop's clock, flagged
//! `Flags::UNSENT`: the network (the emulator's channel) carries no packet for it, and
//! the receiver fills it with its predictor, exactly as for a packet that is late.

use tactile_math::vec3::{distance, norm};
use tactile_messages::samples::LATE_WINDOW;
use tactile_scenario::{CodecConfig, CodecKind, PredictorConfig, PredictorKind};

/// One sender's deadband.
#[derive(Debug, Clone)]
pub struct Deadband {
    cfg: CodecConfig,
    floor: f64,
    origin: [f64; 3],
    last: Option<[f64; 3]>,
}

impl Deadband {
    /// A codec measuring values from `origin` (the device's home for positions, zero
    /// for forces); `default_floor` stands in for a floor left at 0.
    pub fn new(cfg: &CodecConfig, origin: [f64; 3], default_floor: f64) -> Self {
        Deadband {
            cfg: cfg.clone(),
            floor: if cfg.floor > 0.0 {
                cfg.floor
            } else {
                default_floor
            },
            origin,
            last: None,
        }
    }

    /// Whether `value` goes on the network; `speed` is the local device's speed, m/s
    /// (used by the adaptive kind). The first value is always sent, and so is one that
    /// is not finite (the receiver must see it to reject it).
    pub fn send(&mut self, value: [f64; 3], speed: f64) -> bool {
        let k = match self.cfg.kind {
            CodecKind::None => {
                self.last = Some(value);
                return true;
            }
            CodecKind::Deadband => self.cfg.k,
            CodecKind::Adaptive => self.cfg.k * (1.0 + speed.abs() / self.cfg.v_ref),
        };
        let send = match self.last {
            None => true,
            Some(last) => {
                let rel = |v: [f64; 3]| [0, 1, 2].map(|i| v[i] - self.origin[i]);
                let d = distance(value, last);
                // A NaN distance (a non-finite value) is sent: the receiver rejects it.
                d.is_nan() || d > k * norm(rel(last)) + self.floor
            }
        };
        if send {
            self.last = Some(value);
        }
        send
    }
}

/// What the predictor made of one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Estimate {
    /// A fresh value, accepted.
    Fresh([f64; 3]),
    /// No fresh value: the prediction.
    Predicted([f64; 3]),
    /// A fresh value that is not physically possible, rejected: the prediction.
    Rejected([f64; 3]),
    /// No fresh value, and a guess from outside ([`Guess`]) that is not physically
    /// possible (what a received value would be refused for): the last value held.
    Refused([f64; 3]),
}

impl Estimate {
    /// The value to use.
    pub fn value(self) -> [f64; 3] {
        match self {
            Estimate::Fresh(v)
            | Estimate::Predicted(v)
            | Estimate::Rejected(v)
            | Estimate::Refused(v) => v,
        }
    }
}

/// Most accepted values a [`Guess`] is shown, oldest first: enough for any
/// polynomial or filter over the last tens of milliseconds at 1 kHz, and a bound on
/// the memory a long run holds.
pub const HISTORY: usize = 64;

/// A guess made outside this crate (a Python function, through the Python API), in
/// place of the predictor's kind's. The predictor still decides what is accepted
/// (finite, physically possible), when a guess is needed and how far ahead
/// (`horizon_s`); a guess that is `None` holds the last value, as the kinds' do, and
/// one that a received value would be refused for (not finite, larger than
/// `max_rate` allows, further from the last value than `max_rate` allows over the
/// samples guessed ahead) is refused ([`Estimate::Refused`]) and holds it too.
pub trait Guess: Send {
    /// The value at the sender's sample `to`, for the receiver's sample `n`, from
    /// `history`: the values accepted so far, `(sender's sample, value)`, oldest first,
    /// the last [`HISTORY`] of them (never empty).
    fn guess(&mut self, n: u64, to: u64, history: &[(u64, [f64; 3])]) -> Option<[f64; 3]>;
}

/// A [`Guess`] and the history it is shown.
struct Custom {
    guess: Box<dyn Guess>,
    history: std::collections::VecDeque<(u64, [f64; 3])>,
}

impl std::fmt::Debug for Custom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Custom {{ history: {} values }}", self.history.len())
    }
}

impl Custom {
    /// `at`'s value accepted: the last one replaced if it is of the same sample (the
    /// real value of a sample the channel first stood in for), else appended.
    fn accept(&mut self, at: u64, v: [f64; 3]) {
        match self.history.back_mut() {
            Some(last) if last.0 == at => *last = (at, v),
            _ => {
                if self.history.len() == HISTORY {
                    self.history.pop_front();
                }
                self.history.push_back((at, v));
            }
        }
    }
}

/// A receiver's predictor over three axes; time is the sender's sample number.
#[derive(Debug)]
pub struct Predictor {
    cfg: PredictorConfig,
    t_s: f64,
    max_rate: f64,
    last: Option<(u64, [f64; 3])>,
    before: Option<(u64, [f64; 3])>,
    arrived_at: u64,
    kalman: [Kalman; 3],
    custom: Option<Custom>,
}

/// A constant-velocity Kalman filter on one axis.
#[derive(Debug, Clone, Copy, Default)]
struct Kalman {
    x: [f64; 2],
    p: [[f64; 2]; 2],
    at: Option<u64>,
}

impl Kalman {
    /// Moves the state to sample `n` (dt seconds per sample).
    fn predict_to(&mut self, n: u64, t_s: f64, q: f64) {
        let Some(at) = self.at else { return };
        if n <= at {
            return;
        }
        let dt = (n - at) as f64 * t_s;
        let [x, v] = self.x;
        self.x = [x + dt * v, v];
        let p = self.p;
        // P = F P F^T + Q, F = [[1, dt], [0, 1]], Q for white acceleration of density q.
        let p00 = p[0][0] + dt * (p[1][0] + p[0][1]) + dt * dt * p[1][1];
        let p01 = p[0][1] + dt * p[1][1];
        let p11 = p[1][1];
        let (d2, d3) = (dt * dt, dt * dt * dt);
        self.p = [
            [p00 + q * d3 / 3.0, p01 + q * d2 / 2.0],
            [p01 + q * d2 / 2.0, p11 + q * dt],
        ];
        self.at = Some(n);
    }

    fn update(&mut self, n: u64, z: f64, t_s: f64, q: f64, r: f64) {
        if self.at.is_none() {
            self.x = [z, 0.0];
            self.p = [[r, 0.0], [0.0, 1.0]];
            self.at = Some(n);
            return;
        }
        self.predict_to(n, t_s, q);
        let s = self.p[0][0] + r;
        let k = [self.p[0][0] / s, self.p[1][0] / s];
        let y = z - self.x[0];
        self.x = [self.x[0] + k[0] * y, self.x[1] + k[1] * y];
        let p = self.p;
        self.p = [
            [(1.0 - k[0]) * p[0][0], (1.0 - k[0]) * p[0][1]],
            [p[1][0] - k[1] * p[0][0], p[1][1] - k[1] * p[0][1]],
        ];
    }

    /// The position at sample n without changing the filter.
    fn peek(&self, n: u64, t_s: f64) -> f64 {
        match self.at {
            Some(at) if n > at => self.x[0] + (n - at) as f64 * t_s * self.x[1],
            _ => self.x[0],
        }
    }
}

impl Predictor {
    /// A predictor for samples of period `t_s`; `default_rate` stands in for a
    /// `max_rate` left at 0.
    pub fn new(cfg: &PredictorConfig, t_s: f64, default_rate: f64) -> Self {
        Predictor {
            cfg: cfg.clone(),
            t_s,
            max_rate: if cfg.max_rate > 0.0 {
                cfg.max_rate
            } else {
                default_rate
            },
            last: None,
            before: None,
            arrived_at: 0,
            kalman: [Kalman::default(); 3],
            custom: None,
        }
    }

    /// Guesses with `guess` from now on, in place of the kind's (its history
    /// starts empty: call before the first sample).
    pub fn set_guess(&mut self, guess: Box<dyn Guess>) {
        self.custom = Some(Custom {
            guess,
            history: std::collections::VecDeque::with_capacity(HISTORY),
        });
    }

    /// True once a value has been accepted.
    pub fn has_value(&self) -> bool {
        self.last.is_some()
    }

    /// The receiver's sample `n`: `fresh` is the value that arrived with the sender's
    /// sample number, or `None` when nothing new came (not sent, late, lost). A gap is
    /// filled as the sender's signal would have gone on since the last value arrived
    /// (filling, not compensating the network's delay).
    pub fn estimate(&mut self, n: u64, fresh: Option<(u64, [f64; 3])>) -> Estimate {
        if let Some((at, v)) = fresh {
            // A sender that started again (its numbers far behind the last) starts a
            // new signal.
            if self
                .last
                .is_some_and(|(t, _)| at.saturating_add(LATE_WINDOW) < t)
            {
                self.reset();
            }
            if at <= n && self.possible(at, v) {
                self.accept(at, v);
                self.arrived_at = n;
                return Estimate::Fresh(v);
            }
            return Estimate::Rejected(self.predict(n).0);
        }
        match self.predict(n) {
            (v, false) => Estimate::Predicted(v),
            (v, true) => Estimate::Refused(v),
        }
    }

    fn reset(&mut self) {
        self.last = None;
        self.before = None;
        self.kalman = [Kalman::default(); 3];
        if let Some(c) = &mut self.custom {
            c.history.clear();
        }
    }

    /// Finite, no larger than `max_rate` allows over a second, and no faster from the
    /// last accepted value than `max_rate` (a value of the same sample as the last, the
    /// real one of a sample the channel first stood in for, is measured from the one
    /// before). A value older than the last accepted one (a reordered packet) is not
    /// possible, nor one from after the receiver's present sample (checked by the
    /// caller).
    fn possible(&self, at: u64, v: [f64; 3]) -> bool {
        if !v.iter().all(|x| x.is_finite()) || norm(v) > self.max_rate {
            return false;
        }
        let reference = match self.last {
            Some((t, _)) if at == t => self.before,
            other => other,
        };
        match reference {
            None => true,
            Some((t, last)) if at > t => {
                let dt = (at - t) as f64 * self.t_s;
                distance(v, last) <= self.max_rate * dt
            }
            Some(_) => false,
        }
    }

    fn accept(&mut self, at: u64, v: [f64; 3]) {
        if let Some(c) = &mut self.custom {
            c.accept(at, v);
        }
        if self.last.is_some_and(|(t, _)| t == at) {
            // The real value of a sample the channel first stood in for replaces it.
            self.last = Some((at, v));
            if self.cfg.kind == PredictorKind::Kalman {
                self.kalman = [Kalman::default(); 3];
                if let Some((t0, x0)) = self.before {
                    self.feed(t0, x0);
                }
                self.feed(at, v);
            }
            return;
        }
        self.before = self.last;
        self.last = Some((at, v));
        if self.cfg.kind == PredictorKind::Kalman {
            self.feed(at, v);
        }
    }

    fn feed(&mut self, at: u64, v: [f64; 3]) {
        let (q, r) = (self.cfg.process_noise, self.cfg.measurement_noise);
        for (i, k) in self.kalman.iter_mut().enumerate() {
            k.update(at, v[i], self.t_s, q, r);
        }
    }

    /// The guess for the receiver's sample `n`: the sender's signal at its sample
    /// number of the last value plus the samples since that value arrived.
    /// The value at the receiver's sample `n`, and whether a guess from outside was
    /// refused for it.
    fn predict(&mut self, n: u64) -> ([f64; 3], bool) {
        let Some((t1, x1)) = self.last else {
            return ([0.0; 3], false);
        };
        let horizon = (self.cfg.horizon_s / self.t_s).round() as u64;
        let to = t1 + n.saturating_sub(self.arrived_at).min(horizon);
        if let Some(c) = &mut self.custom {
            let history = c.history.make_contiguous();
            return match c.guess.guess(n, to, history) {
                Some(g) if self.possible_guess((t1, x1), to, g) => (g, false),
                Some(_) => (x1, true),
                None => (x1, false),
            };
        }
        let n = to;
        let guess = match self.cfg.kind {
            PredictorKind::Hold => x1,
            PredictorKind::Linear => match self.before {
                Some((t0, x0)) if n > t1 && t1 > t0 => {
                    let s = (n - t1) as f64 / (t1 - t0) as f64;
                    [0, 1, 2].map(|i| x1[i] + s * (x1[i] - x0[i]))
                }
                _ => x1,
            },
            PredictorKind::Kalman => [0, 1, 2].map(|i| self.kalman[i].peek(n, self.t_s)),
        };
        if guess.iter().all(|x| x.is_finite()) {
            (guess, false)
        } else {
            (x1, false)
        }
    }

    /// A guess for the sender's sample `to` is held to what a received value is:
    /// finite, within `max_rate` over a second, and no further from the last accepted
    /// value `(t1, x1)` than `max_rate` allows over the samples between them (one at
    /// least). A guess of 1e300 N was rendered at the device's full force where the
    /// same value received was refused.
    fn possible_guess(&self, (t1, x1): (u64, [f64; 3]), to: u64, g: [f64; 3]) -> bool {
        let dt = to.saturating_sub(t1).max(1) as f64 * self.t_s;
        g.iter().all(|x| x.is_finite())
            && norm(g) <= self.max_rate
            && distance(g, x1) <= self.max_rate * dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deadband(kind: CodecKind, k: f64) -> Deadband {
        Deadband::new(
            &CodecConfig {
                kind,
                k,
                floor: 0.01,
                ..CodecConfig::default()
            },
            [0.0; 3],
            0.0,
        )
    }

    #[test]
    fn deadband_sends_what_a_person_would_notice() {
        let mut d = deadband(CodecKind::Deadband, 0.1);
        assert!(d.send([1.0, 0.0, 0.0], 0.0), "the first is sent");
        // Within 10 % of 1 N (plus the 0.01 floor): not sent.
        assert!(!d.send([1.1, 0.0, 0.0], 0.0));
        assert!(!d.send([1.0, 0.1, 0.0], 0.0));
        // Just beyond: sent, and the reference moves.
        assert!(d.send([1.12, 0.0, 0.0], 0.0));
        assert!(!d.send([1.22, 0.0, 0.0], 0.0));
        // A non-finite value is always sent (the receiver rejects it).
        assert!(d.send([f64::NAN, 0.0, 0.0], 0.0));
        // Adaptive: at v_ref the band doubles.
        let mut a = deadband(CodecKind::Adaptive, 0.1);
        assert!(a.send([1.0, 0.0, 0.0], 0.0));
        assert!(!a.send([1.15, 0.0, 0.0], 0.05));
        assert!(a.send([1.15, 0.0, 0.0], 0.0));
        let mut none = deadband(CodecKind::None, 0.1);
        assert!((0..10).all(|_| none.send([1.0; 3], 0.0)));
    }

    fn predictor(kind: PredictorKind) -> Predictor {
        Predictor::new(
            &PredictorConfig {
                kind,
                ..PredictorConfig::default()
            },
            1e-3,
            10.0,
        )
    }

    /// A ramp at 0.1 m/s sampled every 10th sample: hold lags, linear and Kalman are
    /// exact on a straight line (Kalman after it has learnt the velocity).
    #[test]
    fn predictors_fill_the_gaps_of_a_ramp() {
        let x = |n: u64| [1e-4 * n as f64, 0.0, 0.0];
        let mut errs = Vec::new();
        for kind in [
            PredictorKind::Hold,
            PredictorKind::Linear,
            PredictorKind::Kalman,
        ] {
            let mut p = predictor(kind);
            let mut worst = 0.0f64;
            for n in 0..2000u64 {
                let fresh = (n % 10 == 0).then(|| (n, x(n)));
                let e = p.estimate(n, fresh);
                if n > 500 {
                    worst = worst.max((e.value()[0] - x(n)[0]).abs());
                }
            }
            errs.push(worst);
        }
        assert!(
            (errs[0] - 9e-4).abs() < 1e-12,
            "hold lags 9 samples: {}",
            errs[0]
        );
        assert!(errs[1] < 1e-12, "linear: {}", errs[1]);
        assert!(errs[2] < 1e-5, "kalman: {}", errs[2]);
    }

    #[test]
    fn impossible_values_are_rejected() {
        let mut p = predictor(PredictorKind::Hold);
        assert_eq!(
            p.estimate(0, Some((0, [0.1; 3]))),
            Estimate::Fresh([0.1; 3])
        );
        // 1 m in one sample at 1 kHz is 1000 m/s.
        assert_eq!(
            p.estimate(1, Some((1, [1.1; 3]))),
            Estimate::Rejected([0.1; 3])
        );
        assert_eq!(
            p.estimate(2, Some((2, [f64::INFINITY; 3]))),
            Estimate::Rejected([0.1; 3])
        );
        // A reordered, older packet is not used.
        let mut q = predictor(PredictorKind::Hold);
        q.estimate(5, Some((5, [0.1; 3])));
        assert_eq!(
            q.estimate(6, Some((3, [0.1001; 3]))),
            Estimate::Rejected([0.1; 3])
        );
        // A plausible one is.
        assert_eq!(
            p.estimate(3, Some((3, [0.1001; 3]))),
            Estimate::Fresh([0.1001; 3])
        );
    }

    /// Each call's `(n, to, history)`.
    type Seen = std::sync::Arc<std::sync::Mutex<Vec<(u64, u64, Vec<(u64, [f64; 3])>)>>>;

    /// A guess that records what it was shown and answers with a fixed value, or
    /// nothing.
    struct Shown {
        seen: Seen,
        answer: Option<[f64; 3]>,
    }

    impl Guess for Shown {
        fn guess(&mut self, n: u64, to: u64, history: &[(u64, [f64; 3])]) -> Option<[f64; 3]> {
            self.seen
                .lock()
                .expect("not poisoned")
                .push((n, to, history.to_vec()));
            self.answer
        }
    }

    fn shown(answer: Option<[f64; 3]>) -> (Predictor, Seen) {
        let seen = std::sync::Arc::default();
        let mut p = predictor(PredictorKind::Linear);
        p.set_guess(Box::new(Shown {
            seen: std::sync::Arc::clone(&seen),
            answer,
        }));
        (p, seen)
    }

    #[test]
    fn a_guess_from_outside_sees_a_bounded_history_and_is_checked() {
        let (mut p, seen) = shown(Some([2.5e-3; 3]));
        // More values than the history holds, each accepted, then a gap.
        for k in 0..100u64 {
            let v = [k as f64 * 1e-5; 3];
            assert_eq!(p.estimate(k, Some((k, v))), Estimate::Fresh(v));
        }
        // The real value of sample 99 replaces the one the channel stood in for.
        p.estimate(100, Some((99, [2e-3; 3])));
        assert_eq!(p.estimate(101, None), Estimate::Predicted([2.5e-3; 3]));
        let seen = seen.lock().expect("not poisoned");
        let (n, to, history) = &seen[0];
        assert_eq!((*n, *to), (101, 100));
        assert_eq!(history.len(), HISTORY);
        assert_eq!(history[0].0, 100 - HISTORY as u64);
        assert_eq!(history[HISTORY - 1], (99, [2e-3; 3]));
        // Nothing holds the last value.
        let (mut p, _) = shown(None);
        p.estimate(0, Some((0, [0.1; 3])));
        assert_eq!(p.estimate(1, None), Estimate::Predicted([0.1; 3]));
    }

    /// A guess is held to what a received value is: one that is not finite, larger
    /// than `max_rate` allows, or further from the last value than `max_rate` allows
    /// over the samples guessed ahead is refused, the last value held; within them it
    /// is taken.
    #[test]
    fn a_guess_a_received_value_would_be_refused_for_is_refused() {
        let max_rate = predictor(PredictorKind::Hold).max_rate;
        let t_s = predictor(PredictorKind::Hold).t_s;
        for (answer, taken) in [
            ([f64::NAN, 0.0, 0.0], false),
            ([1e300, 0.0, 0.0], false),
            ([0.1 + 1.01 * max_rate * t_s, 0.1, 0.1], false),
            ([0.1 + 0.99 * max_rate * t_s, 0.1, 0.1], true),
        ] {
            let (mut p, _) = shown(Some(answer));
            p.estimate(0, Some((0, [0.1; 3])));
            let want = match taken {
                true => Estimate::Predicted(answer),
                false => Estimate::Refused([0.1; 3]),
            };
            assert_eq!(p.estimate(1, None), want, "{answer:?}");
        }
        // Two samples ahead, twice the change.
        let (mut p, _) = shown(Some([0.1 + 1.9 * max_rate * t_s, 0.1, 0.1]));
        p.estimate(0, Some((0, [0.1; 3])));
        p.estimate(1, None);
        assert!(matches!(p.estimate(2, None), Estimate::Predicted(_)));
    }
}
