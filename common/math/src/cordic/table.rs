//! The rotation's outputs for every folded angle code, for the short words a
//! simulation runs most: a lookup instead of the iterations, the same integers.
//!
//! With `frac <= 14` a folded angle is one of at most 51,477 codes, so the datapath's
//! sine and cosine codes for all of them fit a table of 412 kB at most (206 kB for the
//! paper's `frac = 13`) that stays in the core's second-level cache. The table is
//! made from [`Cordic::rotate`] itself, so it holds the datapath's integers, not an
//! approximation of them; the negation for a folded angle is applied afterwards,
//! which gives the same integers because the saturation is symmetric
//! (`clamp(-v) = -clamp(v)`). Tests compare every entry, both signs, with the
//! iterations. The RTL comparisons keep using the iterations.

use super::{Cordic, CordicConfig};
use std::sync::{Arc, Mutex};

/// Largest `frac` tabled: the table then has at most 51,477 entries (`pi 2^14`).
pub(super) const MAX_FRAC: u32 = 14;

/// `(sin, cos)` codes of `rotate(z, 0)` for `z` in `[-reach, reach]`.
#[derive(Clone)]
pub(super) struct Table {
    reach: i64,
    codes: Arc<[[i32; 2]]>,
}

impl std::fmt::Debug for Table {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Table")
            .field("entries", &self.codes.len())
            .finish()
    }
}

/// Tables made so far in this process, by format: an engine made again (per test case,
/// per run of a sweep in one process) takes its format's table instead of making it
/// again (about a millisecond). At most [`KEPT`] formats are kept, so a process that
/// tries formats without end holds a bounded amount.
static MADE: Mutex<Vec<(CordicConfig, Table)>> = Mutex::new(Vec::new());

/// Formats whose tables a process keeps.
const KEPT: usize = 4;

impl Table {
    /// The table of `c`'s rotation, or `None` for a fraction too long to table.
    pub(super) fn of(c: &Cordic) -> Option<Table> {
        if c.cfg.frac > MAX_FRAC {
            return None;
        }
        // A poisoned lock only costs the sharing.
        if let Ok(made) = MADE.lock() {
            if let Some((_, t)) = made.iter().find(|(cfg, _)| *cfg == c.cfg) {
                return Some(t.clone());
            }
        }
        let t = Table::make(c);
        if let Ok(mut made) = MADE.lock() {
            // Another thread may have made the same meanwhile: one slot a format.
            if made.len() < KEPT && !made.iter().any(|(cfg, _)| *cfg == c.cfg) {
                made.push((c.cfg, t.clone()));
            }
        }
        Some(t)
    }

    fn make(c: &Cordic) -> Table {
        // A folded angle is within pi/2 and its rounding; two codes of margin.
        let reach = c.half_pi + 2;
        let codes = (-reach..=reach)
            .map(|z| {
                let (s, c) = c.rotate(z, 0);
                // Saturated to +-2^(frac+1) <= 2^15: exact in an i32.
                [s as i32, c as i32]
            })
            .collect();
        Table { reach, codes }
    }

    /// `rotate(z, flip)`'s codes, if `z` is in the table.
    #[inline(always)]
    pub(super) fn get(&self, z: i64, flip: i64) -> Option<(i64, i64)> {
        let i = usize::try_from(z + self.reach).ok()?;
        let [s, c] = *self.codes.get(i)?;
        Some(((i64::from(s) ^ flip) - flip, (i64::from(c) ^ flip) - flip))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cordic::Rounding;

    /// Every entry, both signs, equals the iterations, for fractions from 1 to the
    /// longest tabled and a few iteration counts each, in both roundings.
    #[test]
    fn every_entry_is_the_datapaths_own() {
        let mut configs = vec![];
        for rounding in [Rounding::Nearest, Rounding::Truncate] {
            for frac in [1, 5, 9, 12, 13] {
                for iterations in [1, frac / 2 + 1, frac + 2] {
                    configs.push((16, frac, iterations, rounding));
                }
            }
            configs.push((20, MAX_FRAC, MAX_FRAC + 2, rounding));
        }
        for (word, frac, iterations, rounding) in configs {
            let cfg = CordicConfig::new(word, frac, Some(iterations), rounding).expect("config");
            let c = Cordic::new(cfg).expect("cordic");
            let t = Table::make(&c);
            assert_eq!(Table::of(&c).map(|k| k.codes), Some(t.codes.clone()));
            for z in -t.reach..=t.reach {
                for flip in [0, -1] {
                    assert_eq!(t.get(z, flip), Some(c.rotate(z, flip)), "{cfg:?} z {z}");
                }
            }
            assert_eq!(t.get(t.reach + 1, 0), None);
            assert_eq!(t.get(-t.reach - 1, -1), None);
        }
    }

    /// Every angle the fast path takes folds into the table: swept over the whole
    /// range, densest near the fold's edges (+-pi/2, +-pi), in both roundings, each
    /// found in the table and equal to the iterations; `sin_cos` gives the same.
    #[test]
    fn every_folded_angle_is_in_the_table() {
        use std::f64::consts::{FRAC_PI_2, PI};
        for rounding in [Rounding::Nearest, Rounding::Truncate] {
            let cfg = CordicConfig::new(16, 13, None, rounding).expect("config");
            let c = Cordic::new(cfg).expect("cordic");
            let t = c.table.clone().expect("tabled");
            let mut angles: Vec<f32> = (-40_000..=40_000).map(|k| k as f32 * 1e-4).collect();
            for edge in [-PI, -FRAC_PI_2, FRAC_PI_2, PI, 2.0 * PI, 1e3 * PI] {
                let e = edge as f32;
                let mut below = e;
                let mut above = e;
                for _ in 0..64 {
                    angles.extend([below, above]);
                    below = f32::from_bits(below.to_bits() - 1);
                    above = f32::from_bits(above.to_bits() + 1);
                }
            }
            for a in angles {
                let (z, flip) = c.fold(i64::from(super::super::floor_code(
                    c.angle_prefloor(f64::from(a)),
                )));
                let want = c.rotate(z, flip);
                assert_eq!(t.get(z, flip), Some(want), "{rounding:?} angle {a}");
                let xy = c.xy_out;
                assert_eq!(c.sin_cos(a), (want.0 as f32 * xy, want.1 as f32 * xy));
            }
        }
    }

    #[test]
    fn long_fractions_are_not_tabled() {
        let cfg = CordicConfig::new(24, MAX_FRAC + 1, Some(8), Rounding::Nearest).expect("config");
        assert!(Table::of(&Cordic::new(cfg).expect("cordic")).is_none());
    }
}
