//! The stretches of time a plot shades (the operator's clutch released), bounded: a
//! clutch that flaps every sample made one grey band per release, 500,000 bands and a
//! 45 MB SVG for 10^6 samples. Past the plot's pixel width, neighbouring stretches
//! closer than a resolution are merged (the gap between them shaded with them); the
//! resolution starts at the sample period and doubles until the bands fit, so only
//! the closest gaps are shaded over and a long engaged stretch between two releases
//! stays unshaded (merging pairwise whatever the gap drew 88 s of engaged clutch as
//! released). Memory and the file stay bounded, every release stays visible, and the
//! plot then says its bands were merged.

use super::WIDTH;

/// Stretches `(from, to)`, s, at most [`WIDTH`] of them.
#[derive(Debug, Clone, Default)]
pub struct Stretches {
    spans: Vec<(f64, f64)>,
    merged: bool,
    /// Gaps shorter than this, s, are shaded with their neighbours (0: none merged).
    resolution: f64,
}

impl Stretches {
    /// Marks the sample at `t` (period `t_s`): it extends the last stretch if it
    /// follows it (within the resolution merged at), else starts one.
    pub fn mark(&mut self, t: f64, t_s: f64) {
        match self.spans.last_mut() {
            Some((_, end)) if t - *end < (1.5 * t_s).max(self.resolution) => *end = end.max(t),
            _ => self.spans.push((t, t)),
        }
        if self.spans.len() > WIDTH as usize {
            self.merge(t_s);
        }
    }

    /// Merges neighbours closer than a resolution that starts at `t_s` and doubles
    /// until the stretches fit the width.
    fn merge(&mut self, t_s: f64) {
        self.merged = true;
        let mut r = self.resolution.max(t_s).max(f64::MIN_POSITIVE);
        while self.spans.len() > WIDTH as usize {
            if !r.is_finite() {
                // Gaps no resolution closes (times not numbers): one band.
                let (from, to) = (self.spans[0].0, self.spans[self.spans.len() - 1].1);
                self.spans = vec![(from, to)];
                break;
            }
            let mut out: Vec<(f64, f64)> = Vec::with_capacity(self.spans.len());
            for &(from, to) in &self.spans {
                match out.last_mut() {
                    Some((_, end)) if from - *end < r => *end = end.max(to),
                    _ => out.push((from, to)),
                }
            }
            self.spans = out;
            self.resolution = r;
            r *= 2.0;
        }
    }

    /// The stretches, in time order.
    pub fn spans(&self) -> &[(f64, f64)] {
        &self.spans
    }

    /// True once neighbours were merged to stay within the plot's width.
    pub fn merged(&self) -> bool {
        self.merged
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flapping_every_sample_stays_within_the_width() {
        let mut s = Stretches::default();
        for n in (0..1_000_000u64).step_by(2) {
            s.mark(n as f64 * 1e-3, 1e-3);
        }
        assert!(s.merged());
        assert!(s.spans().len() <= WIDTH as usize, "{}", s.spans().len());
        assert_eq!(s.spans()[0].0, 0.0);
        assert_eq!(s.spans().last().map(|x| x.1), Some(999.998));
        let mut few = Stretches::default();
        for n in [0u64, 1, 2, 10, 11] {
            few.mark(n as f64, 1.0);
        }
        assert_eq!(few.spans(), &[(0.0, 2.0), (10.0, 11.0)]);
        assert!(!few.merged());
    }

    /// Issue 51: one release from 1 s to 2 s, then 1,001 flaps at 90-92 s, merged
    /// pairwise into one band (1.0, 90.0): 88 s of engaged clutch drawn as released.
    #[test]
    fn merging_shades_no_long_engaged_stretch() {
        let mut s = Stretches::default();
        for k in 0..=1000u64 {
            s.mark(1.0 + k as f64 * 1e-3, 1e-3);
        }
        for k in 0..1001u64 {
            s.mark(90.0 + k as f64 * 2e-3, 1e-3);
        }
        assert!(s.merged());
        assert!(s.spans().len() <= WIDTH as usize, "{}", s.spans().len());
        assert_eq!(s.spans()[0], (1.0, 2.0), "{:?}", &s.spans()[..2]);
        assert!(
            s.spans()
                .iter()
                .all(|&(from, to)| to <= 2.0 || from >= 90.0),
            "{:?}",
            &s.spans()[..2]
        );
        assert_eq!(s.spans().last().map(|x| x.1), Some(92.0));
    }
}
