//! The stretches of time a plot shades (the operator's clutch released), bounded: a
//! clutch that flaps every sample made one grey band per release, 500,000 bands and a
//! 45 MB SVG for 10^6 samples. Past the plot's pixel width, neighbouring stretches are
//! merged pairwise (the gap between two, by then under a pixel or so, shaded with
//! them), so the memory and the file stay bounded and every release stays visible;
//! the plot then says its bands were merged.

use super::WIDTH;

/// Stretches `(from, to)`, s, at most [`WIDTH`] of them.
#[derive(Debug, Clone, Default)]
pub struct Stretches {
    spans: Vec<(f64, f64)>,
    merged: bool,
}

impl Stretches {
    /// Marks the sample at `t` (period `t_s`): it extends the last stretch if it
    /// follows it, else starts one.
    pub fn mark(&mut self, t: f64, t_s: f64) {
        match self.spans.last_mut() {
            Some((_, end)) if t - *end < 1.5 * t_s => *end = end.max(t),
            _ => self.spans.push((t, t)),
        }
        if self.spans.len() > WIDTH as usize {
            self.spans = self
                .spans
                .chunks(2)
                .map(|c| (c[0].0, c[c.len() - 1].1))
                .collect();
            self.merged = true;
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
}
