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

/// What the gate did with one value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Passed {
    /// Let through as it was.
    As([f64; 3]),
    /// Cut to the range, limit or step: this is what goes out.
    Cut([f64; 3]),
    /// Not let through: this (the last good value) goes out instead, or nothing.
    Held(Option<[f64; 3]>),
}

impl Passed {
    /// What goes out, if anything.
    pub fn value(self) -> Option<[f64; 3]> {
        match self {
            Passed::As(v) | Passed::Cut(v) => Some(v),
            Passed::Held(v) => v,
        }
    }
}

/// A robot's joint commands, in the driver's unit.
#[derive(Debug, Clone, PartialEq)]
pub struct JointGate {
    lo: [f64; 3],
    hi: [f64; 3],
    /// The largest step per period, driver units.
    step: [f64; 3],
    last: Option<[f64; 3]>,
}

impl JointGate {
    /// A gate for commands between `lo` and `hi` (per joint, either order) moving no
    /// more than `step` a period, all in the driver's unit.
    pub fn new(lo: [f64; 3], hi: [f64; 3], step: [f64; 3]) -> JointGate {
        JointGate {
            lo: [0, 1, 2].map(|i| lo[i].min(hi[i])),
            hi: [0, 1, 2].map(|i| lo[i].max(hi[i])),
            step: step.map(f64::abs),
            last: None,
        }
    }

    /// Where the robot is, so the first command steps from there.
    pub fn start_at(&mut self, raw: [f64; 3]) {
        if self.last.is_none() && self.inside(raw) {
            self.last = Some(raw);
        }
    }

    fn inside(&self, v: [f64; 3]) -> bool {
        (0..3).all(|i| v[i].is_finite() && self.lo[i] <= v[i] && v[i] <= self.hi[i])
    }

    /// The hold at the end: where the robot is (`raw`, measured), checked for finite
    /// and in range but not stepped, since commanding the measured angles moves nothing.
    pub fn hold(&mut self, raw: [f64; 3]) -> Passed {
        if !self.inside(raw) {
            return Passed::Held(self.last);
        }
        self.last = Some(raw);
        Passed::As(raw)
    }

    /// The command to send for `raw`.
    pub fn pass(&mut self, raw: [f64; 3]) -> Passed {
        if !self.inside(raw) {
            return Passed::Held(self.last);
        }
        let Some(last) = self.last else {
            self.last = Some(raw);
            return Passed::As(raw);
        };
        let cut = [0, 1, 2].map(|i| raw[i].clamp(last[i] - self.step[i], last[i] + self.step[i]));
        self.last = Some(cut);
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
