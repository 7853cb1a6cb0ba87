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

/// Largest `frac` tabled: the table then has at most `pi 2^15` entries.
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
            if made.len() < KEPT {
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

    /// Every entry, both signs, equals the iterations, for every tabled fraction and
    /// iteration count of a 16-bit word and the paper's, in both roundings.
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

    #[test]
    fn long_fractions_are_not_tabled() {
        let cfg = CordicConfig::new(24, MAX_FRAC + 1, Some(8), Rounding::Nearest).expect("config");
        assert!(Table::of(&Cordic::new(cfg).expect("cordic")).is_none());
    }
}
