//! The one gate every value passes on its way to hardware, after its conversion into
//! the driver's unit: a robot's joint command must be finite and inside the joints'
//! range (else it is not sent: the last good command goes again, counted) and move no
//! joint further in a period than its velocity limit allows (else the step is cut to
//! the limit, counted); a force for the operator's hand must be finite (else zero,
//! and the ramp starts again), inside the device's limit and change no faster than its
//! rate allows (else cut, counted), and it rises from zero over the ramp time at the
//! start and after every discontinuity (the device or the loop back from a loss), as
//! OpenHaptics' force ramping does.
//!
//! The step is cut rather than refused: a target that jumps (a delayed network, an
//! operator's quick move) is then reached at the robot's velocity limit, where holding
//! would leave the robot stuck until the target came back near it.

/// What the gate did with one value: three joints or a force (`[f64; 3]`), or an
/// arm's joints (`tactile_math::joints::Joints`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Passed<V = [f64; 3]> {
    /// Let through as it was.
    As(V),
    /// Cut to the range, limit or step: this is what goes out.
    Cut(V),
    /// Not let through: this (the last good value) goes out instead, or nothing.
    Held(Option<V>),
}

impl<V> Passed<V> {
    /// What goes out, if anything.
    pub fn value(self) -> Option<V> {
        match self {
            Passed::As(v) | Passed::Cut(v) => Some(v),
            Passed::Held(v) => v,
        }
    }
}

/// A robot's joint commands, in the driver's unit: three joints (`[f64; 3]`, the
/// paper's arm) or any number (`Joints`, an arm from its URDF).
#[derive(Debug, Clone, PartialEq)]
pub struct JointGate<V = [f64; 3]> {
    lo: V,
    hi: V,
    /// The largest step per period, driver units.
    step: V,
    last: Option<V>,
}

impl<V: Clone + PartialEq + AsRef<[f64]> + AsMut<[f64]>> JointGate<V> {
    /// A gate for commands between `lo` and `hi` (per joint, either order) moving no
    /// more than `step` a period, all in the driver's unit (all three of one length).
    pub fn new(lo: V, hi: V, step: V) -> JointGate<V> {
        let (mut low, mut high, mut step) = (lo.clone(), hi, step);
        for (i, l) in low.as_mut().iter_mut().enumerate() {
            let h = &mut high.as_mut()[i];
            (*l, *h) = (l.min(*h), l.max(*h));
        }
        step.as_mut().iter_mut().for_each(|s| *s = s.abs());
        JointGate {
            lo: low,
            hi: high,
            step,
            last: None,
        }
    }

    /// Where the robot is, so the first command steps from there.
    pub fn start_at(&mut self, raw: V) {
        if self.last.is_none() && self.inside(&raw) {
            self.last = Some(raw);
        }
    }

    /// Finite, of the gate's length and in range.
    fn inside(&self, v: &V) -> bool {
        let (v, lo, hi) = (v.as_ref(), self.lo.as_ref(), self.hi.as_ref());
        v.len() == lo.len()
            && (0..v.len()).all(|i| v[i].is_finite() && lo[i] <= v[i] && v[i] <= hi[i])
    }

    /// The hold at the end: where the robot is (`raw`, measured), checked for finite
    /// and in range but not stepped, since commanding the measured angles moves nothing.
    pub fn hold(&mut self, raw: V) -> Passed<V> {
        if !self.inside(&raw) {
            return Passed::Held(self.last.clone());
        }
        self.last = Some(raw.clone());
        Passed::As(raw)
    }

    /// The command to send for `raw`.
    pub fn pass(&mut self, raw: V) -> Passed<V> {
        if !self.inside(&raw) {
            return Passed::Held(self.last.clone());
        }
        let Some(last) = self.last.as_ref() else {
            self.last = Some(raw.clone());
            return Passed::As(raw);
        };
        let mut cut = raw.clone();
        for (i, c) in cut.as_mut().iter_mut().enumerate() {
            let (l, s) = (last.as_ref()[i], self.step.as_ref()[i]);
            *c = c.clamp(l - s, l + s);
        }
        self.last = Some(cut.clone());
        if cut == raw {
            Passed::As(raw)
        } else {
            Passed::Cut(cut)
        }
    }
}

/// The force rendered on a haptic device, in the device's frame, N.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceGate {
    limit: f64,
    /// The largest change per period, N.
    step: f64,
    /// Periods the ramp takes from zero to full force.
    ramp_periods: u64,
    /// Periods since the ramp started (None: not started yet).
    ramped: Option<u64>,
    /// Ramps started so far.
    ramps: u64,
    last: [f64; 3],
}

impl ForceGate {
    /// A gate for forces within `limit` per axis, changing at most `rate` N/s, rising
    /// over `ramp_s` at each start, at a loop period of `t_s` s.
    pub fn new(limit: f64, rate: f64, ramp_s: f64, t_s: f64) -> ForceGate {
        ForceGate {
            limit: limit.abs(),
            step: (rate * t_s).abs(),
            ramp_periods: (ramp_s / t_s).round().max(0.0) as u64,
            ramped: None,
            ramps: 0,
            last: [0.0; 3],
        }
    }

    /// The force starts again from zero (a discontinuity: the device or the loop back
    /// from a loss).
    pub fn restart(&mut self) {
        if self.ramped != Some(0) {
            self.ramps += 1;
        }
        self.ramped = Some(0);
    }

    /// Ramps started so far: the first, and one for each restart or non-finite force
    /// (a ramp not yet begun is not started twice).
    pub fn ramps(&self) -> u64 {
        self.ramps
    }

    /// The ramp's factor now, 0 to 1.
    fn factor(&self) -> f64 {
        match (self.ramped, self.ramp_periods) {
            (_, 0) => 1.0,
            (None, _) => 0.0,
            (Some(k), n) => (k as f64 / n as f64).min(1.0),
        }
    }

    /// The force to render for `f` this period.
    pub fn pass(&mut self, f: [f64; 3]) -> Passed {
        if self.ramped.is_none() {
            self.restart();
        }
        if f.iter().any(|x| !x.is_finite()) {
            // Down to zero at the rate, and the ramp starts again.
            self.restart();
            let last = self.last;
            self.last = last.map(|x| x - x.clamp(-self.step, self.step));
            return Passed::Held(Some(self.last));
        }
        let k = self.factor();
        if let Some(r) = &mut self.ramped {
            *r = r.saturating_add(1);
        }
        let want = f.map(|x| (x * k).clamp(-self.limit, self.limit));
        let last = self.last;
        let out = [0, 1, 2].map(|i| want[i].clamp(last[i] - self.step, last[i] + self.step));
        self.last = out;
        let scaled = f.map(|x| x * k);
        if out == scaled {
            Passed::As(out)
        } else {
            Passed::Cut(out)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Whatever comes in, what goes out is finite, in range and within a step of
        /// the last command sent.
        #[test]
        fn no_joint_command_leaves_the_range_or_the_step(
            cmds in proptest::collection::vec(
                proptest::array::uniform3(prop_oneof![
                    -1e6f64..1e6,
                    Just(f64::NAN),
                    Just(f64::INFINITY),
                    Just(f64::NEG_INFINITY),
                ]),
                1..200,
            ),
        ) {
            let mut g = JointGate::new([-180.0; 3], [180.0; 3], [2.0; 3]);
            g.start_at([0.0; 3]);
            let mut last = [0.0; 3];
            for c in cmds {
                if let Some(v) = g.pass(c).value() {
                    for i in 0..3 {
                        prop_assert!(v[i].is_finite() && (-180.0..=180.0).contains(&v[i]));
                        prop_assert!((v[i] - last[i]).abs() <= 2.0 + 1e-12);
                    }
                    last = v;
                }
            }
        }

        /// The force on the hand stays finite, within the limit and the rate, and
        /// starts from zero.
        #[test]
        fn no_force_leaves_the_limit_or_the_rate(
            fs in proptest::collection::vec(
                proptest::array::uniform3(prop_oneof![-1e9f64..1e9, Just(f64::NAN)]),
                1..300,
            ),
        ) {
            let mut g = ForceGate::new(3.3, 1000.0, 0.05, 1e-3);
            let mut last = [0.0; 3];
            for f in fs {
                let v = g.pass(f).value().expect("a force always goes out");
                for i in 0..3 {
                    prop_assert!(v[i].is_finite() && v[i].abs() <= 3.3);
                    prop_assert!((v[i] - last[i]).abs() <= 1.0 + 1e-12);
                }
                last = v;
            }
        }
    }

    #[test]
    fn an_arms_command_of_another_length_is_held() {
        let mut g = JointGate::new(vec![-1.0; 7], vec![1.0; 7], vec![0.1; 7]);
        assert_eq!(g.pass(vec![0.0; 7]), Passed::As(vec![0.0; 7]));
        assert_eq!(g.pass(vec![0.0; 6]), Passed::Held(Some(vec![0.0; 7])));
        let mut v = vec![0.05; 7];
        v[6] = 0.5;
        let mut cut = vec![0.05; 7];
        cut[6] = 0.1;
        assert_eq!(g.pass(v), Passed::Cut(cut));
    }

    #[test]
    fn a_bad_joint_command_is_held_and_a_big_step_is_cut() {
        let mut g = JointGate::new([-10.0; 3], [10.0; 3], [1.0; 3]);
        assert_eq!(
            g.pass([f64::NAN, 0.0, 0.0]),
            Passed::Held(None),
            "nothing good yet"
        );
        assert_eq!(g.pass([1.0, 2.0, 3.0]), Passed::As([1.0, 2.0, 3.0]));
        assert_eq!(
            g.pass([1.0, 2.0, 99.0]),
            Passed::Held(Some([1.0, 2.0, 3.0]))
        );
        assert_eq!(
            g.pass([f64::NEG_INFINITY, 2.0, 3.0]).value(),
            Some([1.0, 2.0, 3.0])
        );
        assert_eq!(g.pass([5.0, 2.0, 3.0]), Passed::Cut([2.0, 2.0, 3.0]));
        // The hold at the end goes to the measured angles in one step, if they are good.
        assert_eq!(g.hold([-4.0, 2.0, 3.0]), Passed::As([-4.0, 2.0, 3.0]));
        assert_eq!(
            g.hold([f64::NAN, 2.0, 3.0]),
            Passed::Held(Some([-4.0, 2.0, 3.0]))
        );
    }

    #[test]
    fn a_force_ramps_up_at_the_start_and_again_after_a_restart() {
        let mut g = ForceGate::new(10.0, 1e6, 0.01, 1e-3);
        let ramp: Vec<f64> = (0..12)
            .map(|_| g.pass([1.0, 0.0, 0.0]).value().expect("f")[0])
            .collect();
        assert_eq!(ramp[0], 0.0);
        assert!((ramp[5] - 0.5).abs() < 1e-12, "{ramp:?}");
        assert_eq!(ramp[11], 1.0);
        assert_eq!(g.ramps(), 1);
        g.restart();
        assert_eq!(g.pass([1.0, 0.0, 0.0]).value(), Some([0.0; 3]));
        assert_eq!(g.pass([f64::NAN, 0.0, 0.0]), Passed::Held(Some([0.0; 3])));
        assert_eq!(g.pass([f64::NAN, 0.0, 0.0]), Passed::Held(Some([0.0; 3])));
        assert_eq!(g.ramps(), 3, "the start, the restart, the first NaN");
        // From a force, down to zero at the rate.
        let mut g = ForceGate::new(10.0, 1000.0, 0.0, 1e-3);
        for _ in 0..5 {
            g.pass([3.0, 0.0, 0.0]);
        }
        let down: Vec<f64> = (0..4)
            .map(|_| g.pass([f64::NAN; 3]).value().expect("f")[0])
            .collect();
        assert_eq!(down, [2.0, 1.0, 0.0, 0.0]);
    }
}
