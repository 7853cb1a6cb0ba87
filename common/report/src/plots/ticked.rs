//! A linear axis with the ticks its plot chooses and no others: a sweep's categories
//! at 0, 1, 2, ..., a map's cells at their centres, the swept numbers themselves. With
//! plotters' own axis a category's axis got ticks at 0.5 and 1.5 as well, and a map
//! tick marks between its cells.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use std::ops::Range;

/// A linear axis over a range with its ticks given; no light grid.
#[derive(Debug, Clone)]
pub(crate) struct Ticked {
    range: (f64, f64),
    ticks: Vec<f64>,
}

impl Ticked {
    /// The axis from `lo` to `hi` with ticks at `ticks`.
    pub fn new((lo, hi): (f64, f64), ticks: Vec<f64>) -> Ticked {
        Ticked {
            range: (lo, hi),
            ticks,
        }
    }
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        RangedCoordf64::from(self.range()).map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.range.0..self.range.1
    }
}
