//! What the operator's hand is rendered, and how a change of it is rendered: never a
//! step. A force the master switches on (the clutch's spring at a release, the loop's
//! force at an engage or when answers come back after the loop broke) takes over from
//! the force felt before it along a straight blend over `[master] switch_ramp_s`, as a
//! real device's force rises from zero at its start. The blend of two forces inside
//! the force limit stays inside it, so the one gate after it is unchanged.

/// Which force the hand is rendered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Rendering {
    /// The loop's force (the control's, from the slave or MMT's model).
    Loop,
    /// The clutch is released: its spring towards home, or nothing.
    Clutch,
    /// The loop is broken (no answers past the peer timeout): zero, at once.
    Broken,
}

/// The blend from the force felt at the last change of [`Rendering`] to the new one's.
#[derive(Debug, Clone)]
pub(crate) struct Switch {
    now: Rendering,
    /// The force felt when the rendering last changed, N.
    from: [f64; 3],
    /// Samples of the blend done, and in all.
    done: u32,
    len: u32,
}

impl Switch {
    /// A blend of `ramp_s` seconds at a sample every `t_s` seconds; the loop's force
    /// rendered to begin with.
    pub(crate) fn new(ramp_s: f64, t_s: f64) -> Self {
        // The scenario bounds ramp_s to 0..=10 s and t_s is positive: a few thousand
        // samples at most.
        let len = (ramp_s / t_s).round().clamp(0.0, f64::from(u32::MAX)) as u32;
        Switch {
            now: Rendering::Loop,
            from: [0.0; 3],
            done: len,
            len,
        }
    }

    /// The force to render now, N: `to`, the force of `mode`, blended in from
    /// `felt` (the force rendered last sample) if `mode` is new.
    pub(crate) fn render(&mut self, mode: Rendering, to: [f64; 3], felt: [f64; 3]) -> [f64; 3] {
        if mode != self.now {
            self.now = mode;
            self.from = felt;
            self.done = 0;
        }
        if self.done >= self.len || mode == Rendering::Broken {
            return to;
        }
        self.done += 1;
        let a = f64::from(self.done) / f64::from(self.len);
        [0, 1, 2].map(|i| self.from[i] + a * (to[i] - self.from[i]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A switch at full strength takes `len` equal steps; the force it blends from is
    /// the one felt at the switch, and once done the mode's force is rendered as it is.
    #[test]
    fn a_switched_force_takes_over_in_equal_steps() {
        let mut s = Switch::new(0.1, 0.01);
        assert_eq!(
            s.render(Rendering::Loop, [1.0, 0.0, 0.0], [0.0; 3]),
            [1.0, 0.0, 0.0]
        );
        let mut felt = [1.0, 0.0, 0.0];
        let mut steps = Vec::new();
        for _ in 0..10 {
            let f = s.render(Rendering::Clutch, [0.0, 0.0, 3.0], felt);
            steps.push(((f[0] - felt[0]).powi(2) + (f[2] - felt[2]).powi(2)).sqrt());
            felt = f;
        }
        assert!(
            (felt[2] - 3.0).abs() < 1e-12 && felt[0].abs() < 1e-12,
            "{felt:?}"
        );
        let first = steps[0];
        assert!(steps.iter().all(|d| (d - first).abs() < 1e-9), "{steps:?}");
        assert!((first - 10f64.sqrt() / 10.0).abs() < 1e-9, "{first}");
        assert_eq!(
            s.render(Rendering::Clutch, [0.0, 0.0, 2.0], felt),
            [0.0, 0.0, 2.0]
        );
    }

    /// The loop breaking renders zero at once; its return blends up from zero.
    #[test]
    fn a_broken_loop_is_zero_at_once_and_its_return_ramps() {
        let mut s = Switch::new(0.004, 0.001);
        assert_eq!(s.render(Rendering::Broken, [0.0; 3], [2.0; 3]), [0.0; 3]);
        let f = s.render(Rendering::Loop, [2.0, 0.0, 0.0], [0.0; 3]);
        assert!((f[0] - 0.5).abs() < 1e-12, "{f:?}");
    }

    /// No ramp: every switch at once.
    #[test]
    fn a_zero_ramp_switches_at_once() {
        let mut s = Switch::new(0.0, 0.001);
        assert_eq!(s.render(Rendering::Clutch, [3.0; 3], [0.0; 3]), [3.0; 3]);
    }
}
