//! A trajectory file's columns, filled and checked one row at a time as the file is
//! read: a row's values go straight where they are played from (about 24 bytes a row
//! for `x,y,z`, 65 with a time, an orientation and the clutch), so a large file costs
//! about its rows' values, not its text plus a vector per row (a 126 MB file took
//! 1.47 GB that way), and the number of rows is capped.

use nalgebra::{Quaternion, UnitQuaternion};
use tactile_scenario::shown::Num;
use tactile_scenario::MAX_POSITION_M;

/// How far a file's quaternion's norm may be from one (rounding in a recorder's
/// output); it is normalized when read.
pub const UNIT_TOLERANCE: f64 = 1e-3;

/// Most rows a trajectory file may have: 2^22 (70 min at 1 kHz, 7 min at 10 kHz, one
/// row per sample), at most 273 MB of values with every column; a longer run loops
/// or holds its file.
pub const MAX_ROWS: usize = 1 << 22;

/// A row that cannot be: its line and what is wrong with it.
#[derive(Debug, Clone, PartialEq)]
pub struct RowProblem {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub problem: String,
}

/// The columns of a file with header number `which` (index bits: 1 timed, 2
/// oriented, 4 clutched), each row checked as it comes.
#[derive(Debug, Default)]
pub struct Columns {
    timed: bool,
    oriented: bool,
    clutched: bool,
    /// Each row's time, s (a timed file).
    pub times: Vec<f64>,
    /// Each row's position, m.
    pub points: Vec<[f64; 3]>,
    /// Each row's orientation (an oriented file), each on the same side as the row
    /// before so a slerp takes the short way.
    pub rotations: Vec<UnitQuaternion<f64>>,
    /// Each row's clutch (a clutched file; true: engaged).
    pub engaged: Vec<bool>,
}

impl Columns {
    /// Empty columns for a file with header number `which`.
    pub fn new(which: usize) -> Columns {
        Columns {
            timed: which & 1 != 0,
            oriented: which & 2 != 0,
            clutched: which & 4 != 0,
            ..Columns::default()
        }
    }

    /// True for a file with a time column.
    pub fn timed(&self) -> bool {
        self.timed
    }

    /// True for a file with an orientation.
    pub fn oriented(&self) -> bool {
        self.oriented
    }

    /// True for a file with the clutch's column.
    pub fn clutched(&self) -> bool {
        self.clutched
    }

    /// Checks row `r` (at `line`) and takes in its values.
    pub fn push(&mut self, line: usize, r: &[f64]) -> Result<(), RowProblem> {
        let bad = |problem: String| RowProblem { line, problem };
        if self.points.len() >= MAX_ROWS {
            return Err(bad(format!(
                "more than {MAX_ROWS} rows, the most a trajectory file may have (a longer run loops or holds it: operator.end)"
            )));
        }
        let k = usize::from(self.timed);
        let point = [r[k], r[k + 1], r[k + 2]];
        // The bound of every position a scenario gives (an operator's `from`, an
        // object's `point`): a file's positions were taken at any size. Checked
        // before any column takes the row in.
        if let Some(i) = point.iter().position(|x| x.abs() > MAX_POSITION_M) {
            return Err(bad(format!(
                "{} = {} m is beyond {MAX_POSITION_M} m, the bound of every position in the arm's space",
                ["x", "y", "z"][i],
                Num(point[i])
            )));
        }
        if self.timed {
            self.push_time(r[0]).map_err(bad)?;
        }
        if self.oriented {
            self.push_rotation(&r[k + 3..k + 7]).map_err(bad)?;
        }
        if self.clutched {
            let v = r[if self.oriented { k + 7 } else { k + 3 }];
            if v != 1.0 && v != 0.0 {
                return Err(bad(format!(
                    "engaged = {}: it is 1 (clutch held) or 0 (released)",
                    Num(v)
                )));
            }
            self.engaged.push(v == 1.0);
        }
        self.points.push(point);
        Ok(())
    }

    /// The time column: from 0 or later, strictly increasing (each already finite:
    /// the CSV parser refuses anything else).
    fn push_time(&mut self, t: f64) -> Result<(), String> {
        match self.times.last() {
            None if t < 0.0 => Err(format!(
                "t = {} s is before 0 (times start at 0 or later)",
                Num(t)
            )),
            Some(&prev) if t <= prev => Err(format!(
                "t = {} s is not after the previous row's {} s (times must increase strictly)",
                Num(t),
                Num(prev)
            )),
            _ => {
                self.times.push(t);
                Ok(())
            }
        }
    }

    /// `q` is `qx, qy, qz, qw`: a unit quaternion (within [`UNIT_TOLERANCE`]),
    /// normalized, on the same side as the row before.
    fn push_rotation(&mut self, q: &[f64]) -> Result<(), String> {
        let quat = Quaternion::new(q[3], q[0], q[1], q[2]);
        let norm = quat.norm();
        if (norm - 1.0).abs() > UNIT_TOLERANCE {
            return Err(format!(
                "the quaternion (qx, qy, qz, qw) = ({}, {}, {}, {}) has norm {}; an orientation is a unit quaternion (within {UNIT_TOLERANCE})",
                Num(q[0]), Num(q[1]), Num(q[2]), Num(q[3]), Num(norm)
            ));
        }
        let mut u = UnitQuaternion::new_normalize(quat);
        if self
            .rotations
            .last()
            .is_some_and(|p| p.coords.dot(&u.coords) < 0.0)
        {
            u = UnitQuaternion::new_unchecked(-u.into_inner());
        }
        self.rotations.push(u);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file's positions were taken at any size (the operator's `from` and `to` are
    /// bounded at 10 m): and a time of 1e300 was shown in 301 digits.
    #[test]
    fn positions_beyond_the_bound_are_refused_and_numbers_shown_short() {
        let mut c = Columns::new(1);
        c.push(2, &[0.0, 0.0, 0.0, 10.0]).expect("10 m");
        let e = c.push(3, &[1.0, 0.0, -1e300, 0.0]).expect_err("1e300 m");
        assert_eq!(e.line, 3);
        assert!(
            e.problem.starts_with("y = -1e300 m is beyond 10 m"),
            "{}",
            e.problem
        );
        let e = c
            .push(3, &[-1e300, 0.0, 0.0, 0.0])
            .expect_err("before the last");
        assert!(
            e.problem.starts_with("t = -1e300 s is not after"),
            "{}",
            e.problem
        );
    }

    #[test]
    fn rows_past_the_cap_are_refused_naming_the_line() {
        let mut c = Columns::new(0);
        c.points = vec![[0.0; 3]; MAX_ROWS];
        let e = c
            .push(MAX_ROWS + 2, &[0.0, 0.0, 0.0])
            .expect_err("too many");
        assert_eq!(e.line, MAX_ROWS + 2);
        assert!(
            e.problem.contains("more than 4194304 rows"),
            "{}",
            e.problem
        );
    }
}
