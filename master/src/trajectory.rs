//! Trajectory files: positions from a CSV, played at the run's rate.
//!
//! A file with header `x,y,z` is one row per sample (what a file recorded at the
//! run's own rate holds); one with header `t,x,y,z` gives each point a time, and the
//! run takes the straight line between the rows around each sample's time, so a file
//! recorded at 100 Hz plays at its own speed in a 1 kHz run instead of ten times too
//! fast. What happens after the last row is the scenario's `end`: held or looped.
//! A 6-DoF operator's file adds the tool's orientation, `qx,qy,qz,qw` (a unit
//! quaternion relative to the operator's home, slerped between timed rows), and may
//! add `engaged` (1 while the operator holds the clutch, 0 while released; between
//! timed rows the earlier row's).
//! Reading is at the edge ([`Trajectory::read`]); [`Trajectory::at`] is pure.

use crate::trajectory_rows::{Columns, RowProblem};
use nalgebra::UnitQuaternion;
use std::path::Path;
use tactile_scenario::{csv, TrajectoryEnd};
use thiserror::Error;

pub use crate::trajectory_rows::{MAX_ROWS, UNIT_TOLERANCE};

/// The headers a trajectory file may have: with or without a time column, an
/// orientation, a clutch (index bits: 1 timed, 2 oriented, 4 clutched).
const HEADERS: [&[&str]; 8] = [
    &["x", "y", "z"],
    &["t", "x", "y", "z"],
    &["x", "y", "z", "qx", "qy", "qz", "qw"],
    &["t", "x", "y", "z", "qx", "qy", "qz", "qw"],
    &["x", "y", "z", "engaged"],
    &["t", "x", "y", "z", "engaged"],
    &["x", "y", "z", "qx", "qy", "qz", "qw", "engaged"],
    &["t", "x", "y", "z", "qx", "qy", "qz", "qw", "engaged"],
];

/// A trajectory file that cannot be used.
#[derive(Debug, Error)]
pub enum OperatorError {
    /// The file could not be read (missing, not a regular file, too large).
    #[error(transparent)]
    Read(#[from] tactile_runtime::files::FileError),
    /// The file's content is malformed.
    #[error("{path}: {source}")]
    Csv {
        /// The file.
        path: String,
        /// Where and what.
        source: csv::CsvError,
    },
    /// The file has a header but no rows.
    #[error("{path}: no positions after the header")]
    NoRows {
        /// The file.
        path: String,
    },
    /// A value that cannot be: a time before 0 or not after the row before, a
    /// quaternion that is not a rotation, an `engaged` other than 0 or 1.
    #[error("{path}: line {line}: {problem}")]
    Row {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        problem: String,
    },
}

/// A trajectory file's points, ready to play.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// The file, as errors and warnings name it.
    pub shown: String,
    /// Each row's time, s, for a timed file; `None` for one row per sample.
    times: Option<Vec<f64>>,
    /// Each row's position, m (never empty).
    points: Vec<[f64; 3]>,
    /// Each row's orientation, for a file with one.
    rotations: Option<Vec<UnitQuaternion<f64>>>,
    /// Each row's clutch, for a file with one (true: engaged).
    engaged: Option<Vec<bool>>,
    /// After the last row.
    end: TrajectoryEnd,
}

impl Trajectory {
    /// Reads and checks the file at `full`, a line at a time (its text is never held
    /// whole; at most [`MAX_TRAJECTORY_BYTES`](tactile_runtime::files::MAX_TRAJECTORY_BYTES)
    /// and [`MAX_ROWS`] rows).
    pub fn read(full: &Path, end: TrajectoryEnd) -> Result<Trajectory, OperatorError> {
        let shown = full.display().to_string();
        let file = tactile_runtime::files::open_bounded(
            full,
            "trajectory",
            tactile_runtime::files::MAX_TRAJECTORY_BYTES,
        )
        .map_err(OperatorError::Read)?;
        let lines = csv::reader_lines(std::io::BufReader::new(file));
        Trajectory::from_lines(lines, shown, end)
    }

    /// Parses a file's text; `shown` names the file in errors.
    pub fn parse(
        text: &str,
        shown: String,
        end: TrajectoryEnd,
    ) -> Result<Trajectory, OperatorError> {
        Trajectory::from_lines(csv::text_lines(text), shown, end)
    }

    /// The rows of numbered `lines`, checked one at a time.
    fn from_lines<S: AsRef<str>>(
        lines: impl Iterator<Item = Result<(usize, S), csv::CsvError>>,
        shown: String,
        end: TrajectoryEnd,
    ) -> Result<Trajectory, OperatorError> {
        let csv_error = |source| OperatorError::Csv {
            path: shown.clone(),
            source,
        };
        let mut rows = csv::Rows::new(lines, &HEADERS).map_err(csv_error)?;
        let mut c = Columns::new(rows.which);
        while let Some((line, r)) = rows.next_row().map_err(csv_error)? {
            c.push(line, r)
                .map_err(|RowProblem { line, problem }| OperatorError::Row {
                    path: shown.clone(),
                    line,
                    problem,
                })?;
        }
        if c.points.is_empty() {
            return Err(OperatorError::NoRows { path: shown });
        }
        Ok(Trajectory {
            shown,
            times: c.timed().then(|| std::mem::take(&mut c.times)),
            rotations: c.oriented().then(|| std::mem::take(&mut c.rotations)),
            engaged: c.clutched().then(|| std::mem::take(&mut c.engaged)),
            points: c.points,
            end,
        })
    }

    /// True if the file gives an orientation (a 6-DoF operator).
    pub fn oriented(&self) -> bool {
        self.rotations.is_some()
    }

    /// True if the file gives the clutch.
    pub fn clutched(&self) -> bool {
        self.engaged.is_some()
    }

    /// The orientation at sample `n` (`None` for a file without one) as `[x, y, z, w]`.
    pub fn rotation_at(&self, n: u64, t_s: f64) -> Option<[f64; 4]> {
        let r = self.rotations.as_ref()?;
        let q = match self.locate(n, t_s) {
            Row::At(k) => r[k],
            Row::Between(k, w) => r[k].slerp(&r[k + 1], w),
        };
        Some([q.i, q.j, q.k, q.w])
    }

    /// Whether the operator holds the clutch at sample `n` (always, for a file
    /// without the column).
    pub fn engaged_at(&self, n: u64, t_s: f64) -> bool {
        self.engaged
            .as_ref()
            .is_none_or(|e| match self.locate(n, t_s) {
                Row::At(k) | Row::Between(k, _) => e[k],
            })
    }

    /// Where sample `n` falls among the rows.
    fn locate(&self, n: u64, t_s: f64) -> Row {
        let rows = self.points.len();
        let Some(times) = &self.times else {
            let k = match self.end {
                TrajectoryEnd::Hold => n.min(rows as u64 - 1),
                TrajectoryEnd::Loop => n % rows as u64,
            };
            return Row::At(k as usize);
        };
        let last = times[times.len() - 1];
        let t = n as f64 * t_s;
        let t = match self.end {
            TrajectoryEnd::Loop if last > 0.0 => t % last,
            _ => t,
        };
        // The first row at or after t; before the first row, the first point.
        let k = times.partition_point(|&tk| tk < t);
        if k == 0 || (k < times.len() && times[k] == t) {
            // On a row's time, its point exactly (before the first, the first).
            return Row::At(k);
        }
        if k == times.len() {
            return Row::At(k - 1);
        }
        let (t0, t1) = (times[k - 1], times[k]);
        Row::Between(k - 1, ((t - t0) / (t1 - t0)).clamp(0.0, 1.0))
    }

    /// The position at sample `n` of a run with sampling period `t_s`: a timed
    /// file's straight line between the rows around the sample's time.
    pub fn at(&self, n: u64, t_s: f64) -> [f64; 3] {
        match self.locate(n, t_s) {
            Row::At(k) => self.points[k],
            Row::Between(k, w) => {
                let (a, b) = (self.points[k], self.points[k + 1]);
                [0, 1, 2].map(|i| a[i] + w * (b[i] - a[i]))
            }
        }
    }

    /// What the run will do once the file has run out, when that is before the run
    /// ends (`samples` at period `t_s`); `None` when the file covers the run.
    pub fn shortfall(&self, samples: u64, t_s: f64) -> Option<String> {
        let end = self.end.name();
        match &self.times {
            None => {
                let rows = self.points.len() as u64;
                if rows >= samples {
                    return None;
                }
                let what = match self.end {
                    TrajectoryEnd::Hold => format!("its last row is held from sample {rows} on"),
                    TrajectoryEnd::Loop => {
                        format!("it starts again from its first row at sample {rows}, every {rows} samples")
                    }
                };
                Some(format!(
                    "operator.path: {} has {rows} rows (one per sample) for a run of {samples} samples: {what} (end = \"{end}\")",
                    self.shown
                ))
            }
            Some(times) => {
                let last = times[times.len() - 1];
                let run_end = (samples - 1) as f64 * t_s;
                if last >= run_end {
                    return None;
                }
                let what = match self.end {
                    TrajectoryEnd::Loop if last > 0.0 => format!(
                        "it starts again from t = 0 at sample {}, every {last} s",
                        first_sample_at(last, t_s)
                    ),
                    _ => format!(
                        "its last point is held from sample {} on",
                        first_sample_after(last, t_s)
                    ),
                };
                Some(format!(
                    "operator.path: {} ends at t = {last} s, before the run's last sample at {run_end} s: {what} (end = \"{end}\")",
                    self.shown
                ))
            }
        }
    }
}

/// Where a sample falls among a file's rows.
#[derive(Debug, Clone, Copy)]
enum Row {
    /// On row k (or held at it).
    At(usize),
    /// Between row k and the next, at this fraction of the way.
    Between(usize, f64),
}

/// The first sample whose time, computed as the run computes it, is at or after `t`.
fn first_sample_at(t: f64, t_s: f64) -> u64 {
    let mut n = (t / t_s).floor().max(0.0) as u64;
    while (n as f64) * t_s < t {
        n += 1;
    }
    while n > 0 && ((n - 1) as f64) * t_s >= t {
        n -= 1;
    }
    n
}

/// The first sample whose time is after `t`.
fn first_sample_after(t: f64, t_s: f64) -> u64 {
    let n = first_sample_at(t, t_s);
    if (n as f64) * t_s > t {
        n
    } else {
        n + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(text: &str, end: TrajectoryEnd) -> Trajectory {
        Trajectory::parse(text, "traj.csv".into(), end).expect("valid")
    }

    #[test]
    fn untimed_rows_hold_or_loop_after_the_last() {
        let text = "x,y,z\n0,0,0\n0.01,0,0\n";
        let hold = file(text, TrajectoryEnd::Hold);
        let x = |t: &Trajectory, n| t.at(n, 1e-3)[0];
        assert_eq!(
            [x(&hold, 0), x(&hold, 1), x(&hold, 2), x(&hold, 999)],
            [0.0, 0.01, 0.01, 0.01]
        );
        let lp = file(text, TrajectoryEnd::Loop);
        assert_eq!(
            [x(&lp, 0), x(&lp, 1), x(&lp, 2), x(&lp, 3)],
            [0.0, 0.01, 0.0, 0.01]
        );
        let w = hold.shortfall(1000, 1e-3).expect("shorter than the run");
        assert!(
            w.contains("2 rows") && w.contains("held from sample 2"),
            "{w}"
        );
        let w = lp.shortfall(1000, 1e-3).expect("shorter than the run");
        assert!(w.contains("again from its first row at sample 2"), "{w}");
        assert_eq!(hold.shortfall(2, 1e-3), None);
    }

    #[test]
    fn timed_rows_are_resampled_linearly() {
        // Rows every 10 ms, run at 1 kHz: samples in between lie on the line.
        let t = file(
            "t,x,y,z\n0,0,0,0\n0.01,0.01,-0.02,0\n0.02,0.01,0,0\n",
            TrajectoryEnd::Hold,
        );
        let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12);
        assert_eq!(t.at(0, 1e-3), [0.0; 3]);
        assert!(
            close(t.at(3, 1e-3), [0.003, -0.006, 0.0]),
            "{:?}",
            t.at(3, 1e-3)
        );
        assert!(close(t.at(10, 1e-3), [0.01, -0.02, 0.0]));
        assert!(close(t.at(15, 1e-3), [0.01, -0.01, 0.0]));
        assert_eq!(t.at(20, 1e-3), [0.01, 0.0, 0.0]);
        assert_eq!(t.at(500, 1e-3), [0.01, 0.0, 0.0], "held");
        let w = t.shortfall(1000, 1e-3).expect("20 ms of a 1 s run");
        assert!(w.contains("held from sample 21"), "{w}");
        assert_eq!(t.shortfall(21, 1e-3), None);
    }

    #[test]
    fn timed_rows_loop_and_may_start_late() {
        let t = file("t,x,y,z\n0.005,1,0,0\n0.01,2,0,0\n", TrajectoryEnd::Loop);
        let x = |n| t.at(n, 1e-3)[0];
        assert_eq!(
            [x(0), x(4), x(5)],
            [1.0, 1.0, 1.0],
            "the first point until 5 ms"
        );
        assert!((x(7) - 1.4).abs() < 1e-12);
        assert_eq!(x(10), 1.0, "again from t = 0");
        assert!((x(17) - 1.4).abs() < 1e-12);
        let w = t.shortfall(100, 1e-3).expect("loops");
        assert!(w.contains("from t = 0 at sample 10, every 0.01 s"), "{w}");
        // A single timed row is a point, held or looped.
        let one = file("t,x,y,z\n0,1,2,3\n", TrajectoryEnd::Loop);
        assert_eq!(one.at(7, 1e-3), [1.0, 2.0, 3.0]);
    }

    #[test]
    fn bad_times_name_the_line() {
        let bad = |text: &str| {
            Trajectory::parse(text, "traj.csv".into(), TrajectoryEnd::Hold)
                .expect_err("bad times")
                .to_string()
        };
        let e = bad("t,x,y,z\n0,0,0,0\n0.01,0,0,0\n0.01,0,0,0\n");
        assert!(
            e.starts_with("traj.csv: line 4: t = 0.01 s is not after"),
            "{e}"
        );
        let e = bad("t,x,y,z\n0,0,0,0\n\n-1,0,0,0\n");
        assert!(
            e.starts_with("traj.csv: line 4: t = -1 s is not after"),
            "{e}"
        );
        let e = bad("t,x,y,z\n-0.5,0,0,0\n");
        assert!(e.contains("line 2: t = -0.5 s is before 0"), "{e}");
        let e = bad("t,x,y,z\n0,0,0,0\nnan,0,0,0\n");
        assert!(
            e.contains("line 3, column 1 (t)") && e.contains("not a finite number"),
            "{e}"
        );
        let e = bad("t,x,y\n0,0,0\n");
        assert!(e.contains("expected x,y,z or t,x,y,z"), "{e}");
    }

    #[test]
    fn orientations_slerp_the_short_way_and_the_clutch_steps() {
        // 90 degrees about z at t = 1 s, given with the opposite sign (the same
        // orientation): the slerp takes the short way, 45 degrees at 0.5 s.
        let h = std::f64::consts::FRAC_PI_4;
        let text = format!(
            "t,x,y,z,qx,qy,qz,qw,engaged\n0,0,0,0,0,0,0,1,1\n1,0,0,0,0,0,{},{},0\n",
            -h.sin(),
            -h.cos()
        );
        let f = file(&text, TrajectoryEnd::Hold);
        assert!(f.oriented() && f.clutched());
        let q = f.rotation_at(500, 1e-3).expect("oriented");
        let want = [0.0, 0.0, (h / 2.0).sin(), (h / 2.0).cos()];
        for k in 0..4 {
            assert!((q[k] - want[k]).abs() < 1e-12, "{q:?} vs {want:?}");
        }
        // The clutch between rows is the earlier row's.
        assert!(f.engaged_at(999, 1e-3) && !f.engaged_at(1000, 1e-3));
        // A quaternion a little off unit is normalized; an untimed file steps.
        let f = file(
            "x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1.0004\n",
            TrajectoryEnd::Hold,
        );
        assert_eq!(f.rotation_at(7, 1e-3), Some([0.0, 0.0, 0.0, 1.0]));
        assert!(f.engaged_at(7, 1e-3) && !f.clutched());
        assert_eq!(
            file("x,y,z\n0,0,0\n", TrajectoryEnd::Hold).rotation_at(0, 1e-3),
            None
        );
    }

    #[test]
    fn a_quaternion_that_is_no_rotation_or_a_clutch_not_0_or_1_names_its_line() {
        let bad = |text: &str| {
            Trajectory::parse(text, "traj.csv".into(), TrajectoryEnd::Hold)
                .expect_err("invalid")
                .to_string()
        };
        let e = bad("x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1\n0,0,0,0,0,0,0\n");
        assert!(e.starts_with("traj.csv: line 3: the quaternion"), "{e}");
        assert!(e.contains("has norm 0"), "{e}");
        let e = bad("x,y,z,engaged\n0,0,0,0.5\n");
        assert!(e.starts_with("traj.csv: line 2: engaged = 0.5"), "{e}");
    }

    #[test]
    fn first_samples_at_and_after_a_time() {
        assert_eq!(first_sample_at(0.01, 1e-3), 10);
        assert_eq!(first_sample_after(0.01, 1e-3), 11);
        assert_eq!(first_sample_at(0.0105, 1e-3), 11);
        assert_eq!(first_sample_after(0.0105, 1e-3), 11);
        assert_eq!(first_sample_at(0.0, 1e-3), 0);
    }
}
