//! The operator (OP): where the hand puts the master's handle at each sample, a(n).
//!
//! Sources are the paper's validation path (joint angles), a circle or figure-eight in
//! the workspace, or positions from a CSV file. The file is read at the edge
//! ([`OperatorSource::load`]); everything after that is pure and indexed by sample, so
//! a run repeats exactly.

pub use crate::trajectory::OperatorError;
use crate::trajectory::Trajectory;
use nalgebra::{Quaternion, UnitQuaternion};
use std::path::Path;
use tactile_math::validation::{paper_joint_path, MOVE_S};
use tactile_scenario::{Operator, Scenario, ScenarioError};

/// No turn, `[x, y, z, w]`.
pub const IDENTITY: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

fn unit(r: [f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(r[3], r[0], r[1], r[2]))
}

/// What the operator commands at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// Joint angles of the master device, rad (the paper's path is given this way).
    Joints([f64; 3]),
    /// Tool position, m.
    Position([f64; 3]),
}

/// An operator written outside this crate (a Python function, through the Python
/// API): called once a sample, in a run's order, so it may keep state (a human model,
/// a scripted reaction to what the hand feels).
pub trait Operate: Send {
    /// Where the hand means the handle to be at sample `n` (time `t`, s), given the
    /// force it felt at the sample before (N, zero at first): a position, m. `None`
    /// holds the last target (the implementation says why, and stops the run).
    fn target(&mut self, n: u64, t: f64, felt: [f64; 3]) -> Option<[f64; 3]>;
}

/// An [`Operate`] in the master's loop: its targets, a missing or non-finite one
/// replaced by the last (the devices' home before the first).
pub struct Scripted {
    operate: Box<dyn Operate>,
    last: [f64; 3],
}

impl std::fmt::Debug for Scripted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Scripted {{ last: {:?} }}", self.last)
    }
}

impl Scripted {
    /// `operate`, starting from `home`.
    pub fn new(operate: Box<dyn Operate>, home: [f64; 3]) -> Self {
        Scripted {
            operate,
            last: home,
        }
    }

    /// The target at sample `n`, period `t_s`, the hand having felt `felt`.
    pub fn target(&mut self, n: u64, t_s: f64, felt: [f64; 3]) -> Target {
        match self.operate.target(n, n as f64 * t_s, felt) {
            Some(p) if p.iter().all(|x| x.is_finite()) => self.last = p,
            _ => {}
        }
        Target::Position(self.last)
    }
}

/// A ready trajectory.
#[derive(Debug, Clone, PartialEq)]
pub enum OperatorSource {
    /// The paper's three joint moves, played forwards then backwards if the run is longer.
    Paper,
    /// Closed curves: centre, size, period and the two axes of their plane.
    Curve {
        /// Circle or figure-eight.
        eight: bool,
        /// Centre, m.
        center: [f64; 3],
        /// Radius or half width, m.
        size: f64,
        /// Seconds per revolution.
        period_s: f64,
        /// Indices of the plane's two axes.
        axes: (usize, usize),
    },
    /// A minimum-jerk move from one point to another in `move_s`, then held.
    Press {
        /// Start, m.
        from: [f64; 3],
        /// End, m.
        to: [f64; 3],
        /// Seconds to get there.
        move_s: f64,
    },
    /// Positions from a file, held or looped after its last row.
    File(Trajectory),
}

/// Minimum-jerk progress at fraction `tau` of a move (Flash and Hogan, 1985): zero
/// velocity and acceleration at both ends.
pub fn min_jerk(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

/// The hand's way from the devices' home onto the trajectory: over `seconds` the
/// target goes from home (the joints at zero, the handle where they put it) to the
/// trajectory's own target along a minimum-jerk blend, so a trajectory that starts
/// elsewhere does not command the whole distance in one sample (a circle 3.6 cm off
/// home did, saturating the slave's torques), whichever hand holds the handle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Approach {
    /// The handle at home, m.
    home: [f64; 3],
    /// Seconds the blend takes.
    seconds: f64,
}

impl Approach {
    /// The approach for `source`, or `None` when there is nothing to approach: a zero
    /// duration, or a first target exactly at home. The second keeps a trajectory
    /// that starts at home (the paper's) bit for bit what it was: blending it would
    /// only slow its first second down.
    pub fn new(
        source: &OperatorSource,
        home: [f64; 3],
        seconds: f64,
        t_s: f64,
    ) -> Option<Approach> {
        let at_home = match source.target(0, t_s) {
            Target::Joints(theta) => theta == [0.0; 3],
            Target::Position(p) => p == home,
        } && source.rotation(0, t_s).is_none_or(|r| r == IDENTITY);
        (seconds > 0.0 && !at_home).then_some(Approach { home, seconds })
    }

    /// The target at time `t` of the run: home + s (a - home) with s the minimum-jerk
    /// progress, joints from zero and positions from the home position. Computed so
    /// even once s is 1 (a rounding's difference from `a`), as the impedance hand's
    /// runs in deploy/results/ were.
    /// A 6-DoF operator's orientation at time `t`: from none (the identity) to the
    /// trajectory's own along the same blend.
    pub fn apply_rotation(&self, r: [f64; 4], t: f64) -> [f64; 4] {
        let s = min_jerk(t / self.seconds);
        let q = UnitQuaternion::identity().slerp(&unit(r), s);
        [q.i, q.j, q.k, q.w]
    }

    /// The approach for a target not known before the run (a [`Scripted`]
    /// operator's), or `None` for a zero duration.
    pub fn from_home(home: [f64; 3], seconds: f64) -> Option<Approach> {
        (seconds > 0.0).then_some(Approach { home, seconds })
    }

    /// See [`Approach::apply_rotation`]; positions and joints.
    pub fn apply(&self, a: Target, t: f64) -> Target {
        let s = min_jerk(t / self.seconds);
        match a {
            Target::Joints(theta) => Target::Joints(theta.map(|q| s * q)),
            Target::Position(p) => {
                Target::Position([0, 1, 2].map(|i| self.home[i] + s * (p[i] - self.home[i])))
            }
        }
    }
}

fn plane_axes(plane: &str) -> (usize, usize) {
    match plane {
        "yz" => (1, 2),
        "xz" => (0, 2),
        _ => (0, 1),
    }
}

impl OperatorSource {
    /// Builds the source; a CSV path is relative to `base_dir` (the scenario's folder).
    pub fn load(op: &Operator, base_dir: &Path) -> Result<OperatorSource, OperatorError> {
        Ok(match op {
            Operator::Paper => OperatorSource::Paper,
            Operator::Circle {
                center,
                radius,
                period_s,
                plane,
            } => OperatorSource::Curve {
                eight: false,
                center: *center,
                size: *radius,
                period_s: *period_s,
                axes: plane_axes(plane),
            },
            Operator::FigureEight {
                center,
                size,
                period_s,
                plane,
            } => OperatorSource::Curve {
                eight: true,
                center: *center,
                size: *size,
                period_s: *period_s,
                axes: plane_axes(plane),
            },
            Operator::Press { from, to, move_s } => OperatorSource::Press {
                from: *from,
                to: *to,
                move_s: *move_s,
            },
            Operator::Csv { path, end } => {
                OperatorSource::File(Trajectory::read(&base_dir.join(path), *end)?)
            }
        })
    }

    /// What deserves a word before a run of `samples` at period `t_s`: a trajectory
    /// file that runs out before the run does, and what then happens.
    pub fn warnings(&self, samples: u64, t_s: f64) -> Vec<String> {
        match self {
            OperatorSource::File(f) => f.shortfall(samples, t_s).into_iter().collect(),
            _ => Vec::new(),
        }
    }

    /// A 6-DoF operator's orientation at sample `n` (`[x, y, z, w]`, relative to
    /// the operator's home); `None` for a 3-DoF source.
    pub fn rotation(&self, n: u64, t_s: f64) -> Option<[f64; 4]> {
        match self {
            OperatorSource::File(f) => f.rotation_at(n, t_s),
            _ => None,
        }
    }

    /// Whether the operator holds the clutch at sample `n` (always, without one).
    pub fn engaged(&self, n: u64, t_s: f64) -> bool {
        match self {
            OperatorSource::File(f) => f.engaged_at(n, t_s),
            _ => true,
        }
    }

    /// True if this source makes 6-DoF samples (an orientation or a clutch).
    pub fn six_dof(&self) -> bool {
        matches!(self, OperatorSource::File(f) if f.oriented() || f.clutched())
    }

    /// What a 6-DoF source needs of the rest of the scenario, or the first thing
    /// missing, naming the field: an arm that can turn its tool, a forward channel
    /// that carries the whole pose in one packet (equal delays), a codec that sends
    /// every sample (the deadband weighs positions only).
    pub fn check_six_dof(&self, sc: &Scenario) -> Result<(), ScenarioError> {
        if !self.six_dof() {
            return Ok(());
        }
        sc.check_six_dof("the operator's trajectory has an orientation or a clutch (a 6-DoF run)")
    }

    /// The target at sample `n` with sampling period `t_s`.
    pub fn target(&self, n: u64, t_s: f64) -> Target {
        let t = n as f64 * t_s;
        match self {
            OperatorSource::Paper => {
                // Forwards over the three moves, then back, so a long run stays smooth.
                let span = 3.0 * MOVE_S;
                let phase = t % (2.0 * span);
                let tp = if phase <= span {
                    phase
                } else {
                    2.0 * span - phase
                };
                Target::Joints(paper_joint_path(tp))
            }
            OperatorSource::Curve {
                eight,
                center,
                size,
                period_s,
                axes,
            } => {
                let w = 2.0 * std::f64::consts::PI * t / period_s;
                let (u, v) = if *eight {
                    (size * w.sin(), size * w.sin() * w.cos())
                } else {
                    (size * w.cos(), size * w.sin())
                };
                let mut p = *center;
                p[axes.0] += u;
                p[axes.1] += v;
                Target::Position(p)
            }
            OperatorSource::Press { from, to, move_s } => {
                let s = min_jerk(t / move_s);
                Target::Position([0, 1, 2].map(|i| from[i] + s * (to[i] - from[i])))
            }
            OperatorSource::File(f) => Target::Position(f.at(n, t_s)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_scenario::TrajectoryEnd;

    #[test]
    fn paper_path_returns_smoothly() {
        let s = OperatorSource::Paper;
        assert_eq!(s.target(0, 0.01), Target::Joints([0.0; 3]));
        let Target::Joints(end) = s.target(1200, 0.01) else {
            panic!("joints")
        };
        let Target::Joints(back) = s.target(1201, 0.01) else {
            panic!("joints")
        };
        assert!((end[2] - back[2]).abs() < 0.01);
        assert_eq!(s.target(2400, 0.01), Target::Joints([0.0; 3]));
    }

    #[test]
    fn a_press_moves_with_minimum_jerk_then_holds() {
        let s = OperatorSource::load(
            &Operator::Press {
                from: [0.0, -0.11, -0.035],
                to: [0.0, -0.11, -0.075],
                move_s: 1.0,
            },
            Path::new("."),
        )
        .expect("press");
        let z = |n: u64| match s.target(n, 1e-3) {
            Target::Position(p) => p[2],
            Target::Joints(_) => f64::NAN,
        };
        assert_eq!(z(0), -0.035);
        assert!((z(500) + 0.055).abs() < 1e-12, "halfway at half time");
        assert_eq!(z(1000), -0.075);
        assert_eq!(z(5000), -0.075);
        // Zero velocity at both ends, fastest in the middle (15/8 of the mean).
        let v = |n: u64| (z(n + 1) - z(n)) / 1e-3;
        assert!(v(0).abs() < 1e-6 && v(999).abs() < 1e-6);
        assert!((v(500).abs() - 1.875 * 0.04).abs() < 1e-4, "{}", v(500));
    }

    #[test]
    fn circle_and_csv() {
        let op = Operator::Circle {
            center: [0.0, -0.05, -0.1],
            radius: 0.02,
            period_s: 1.0,
            plane: "xz".into(),
        };
        let s = OperatorSource::load(&op, Path::new(".")).expect("circle");
        assert_eq!(s.target(0, 0.01), Target::Position([0.02, -0.05, -0.1]));
        let dir = std::env::temp_dir().join(format!("tactile-op-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        std::fs::write(dir.join("p.csv"), "x,y,z\n0,0,0\n1,1,1\n").expect("write");
        let csv = |path: &str, end| Operator::Csv {
            path: path.into(),
            end,
        };
        let s = OperatorSource::load(&csv("p.csv", TrajectoryEnd::Hold), &dir).expect("csv");
        assert_eq!(s.target(3, 0.01), Target::Position([1.0; 3]));
        assert_eq!(s.warnings(2, 0.01), Vec::<String>::new());
        assert_eq!(s.warnings(3, 0.01).len(), 1);
        let s = OperatorSource::load(&csv("p.csv", TrajectoryEnd::Loop), &dir).expect("csv");
        assert_eq!(s.target(2, 0.01), Target::Position([0.0; 3]));
        std::fs::write(dir.join("bad.csv"), "x,y,z\n0,0\n").expect("write");
        let e = OperatorSource::load(&csv("bad.csv", TrajectoryEnd::Hold), &dir)
            .expect_err("truncated");
        assert!(
            e.to_string()
                .contains("bad.csv: line 2: expected 3 columns"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
