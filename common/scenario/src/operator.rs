//! `[operator]`: what the operator's hand does, a(n).

use crate::shown::Num;
use crate::{finite3, invalid, ScenarioError};
use serde::{Deserialize, Serialize};

/// The operator's motion, a(n).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Operator {
    /// The paper's validation path: three 4 s joint moves, played back and forth if the
    /// run is longer.
    #[default]
    Paper,
    /// A circle in a plane parallel to two axes.
    Circle {
        /// Centre, metres.
        center: [f64; 3],
        /// Radius, metres.
        radius: f64,
        /// Seconds per revolution.
        period_s: f64,
        /// Plane of the circle: `xy`, `yz` or `xz`.
        #[serde(default = "default_plane")]
        plane: String,
    },
    /// A figure-eight (Gerono lemniscate) in a plane parallel to two axes.
    FigureEight {
        /// Centre, metres.
        center: [f64; 3],
        /// Half width, metres.
        size: f64,
        /// Seconds per figure.
        period_s: f64,
        /// Plane: `xy`, `yz` or `xz`.
        #[serde(default = "default_plane")]
        plane: String,
    },
    /// A press: from one point to another along a minimum-jerk path in `move_s`
    /// seconds, then held there (into a wall, the hand keeps pushing).
    Press {
        /// Start, metres.
        from: [f64; 3],
        /// End, held, metres.
        to: [f64; 3],
        /// Seconds to get there.
        move_s: f64,
    },
    /// Positions from a CSV file. With header `x,y,z` each row is one sample; with
    /// header `t,x,y,z` each row is a point at `t` seconds (strictly increasing, from
    /// 0 or later) and the run takes the straight line between rows at its own rate,
    /// so a file recorded at any rate plays at its own speed.
    Csv {
        /// Path, relative to the scenario file's folder.
        path: String,
        /// What the hand does once the file has run out: `hold` or `loop`.
        #[serde(default)]
        end: TrajectoryEnd,
    },
}

/// What a trajectory file does after its last row.
///
/// `hold` is the default because a serious tool must not invent motion: a file that
/// is shorter than the run most often means the recording simply stopped, and
/// starting it again makes the hand jump from the last point back to the first in one
/// sample (a two-row file looped moved the handle a centimetre every sample, which is
/// how the old silent loop was found). A loop is something to ask for, with a file
/// that ends where it starts. Either way a file shorter than the run warns at load.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TrajectoryEnd {
    /// Stay at the last point until the run ends.
    #[default]
    Hold,
    /// Start again from the first row (untimed files: every `rows` samples; timed
    /// files: every `t` of the last row, which should repeat the first row's point).
    Loop,
}

impl TrajectoryEnd {
    /// The value as a scenario file spells it.
    pub fn name(self) -> &'static str {
        match self {
            TrajectoryEnd::Hold => "hold",
            TrajectoryEnd::Loop => "loop",
        }
    }
}

fn default_plane() -> String {
    "xy".into()
}

impl Operator {
    /// Checks the ranges; errors name `operator.*`.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        match self {
            Operator::Paper => {}
            Operator::Circle {
                center,
                radius,
                period_s,
                plane,
            }
            | Operator::FigureEight {
                center,
                size: radius,
                period_s,
                plane,
            } => {
                finite3(center, "operator.center")?;
                if !radius.is_finite() || *radius <= 0.0 || *radius > 1.0 {
                    return Err(invalid(
                        "operator.radius",
                        format!("{} m is outside (0, 1] m", Num(*radius)),
                    ));
                }
                if !period_s.is_finite() || *period_s <= 0.0 {
                    return Err(invalid(
                        "operator.period_s",
                        format!("{} must be positive", Num(*period_s)),
                    ));
                }
                if !["xy", "yz", "xz"].contains(&plane.as_str()) {
                    return Err(invalid(
                        "operator.plane",
                        format!("{plane:?} is not xy, yz or xz"),
                    ));
                }
            }
            Operator::Press { from, to, move_s } => {
                finite3(from, "operator.from")?;
                finite3(to, "operator.to")?;
                if !move_s.is_finite() || *move_s <= 0.0 {
                    return Err(invalid(
                        "operator.move_s",
                        format!("{} must be positive", Num(*move_s)),
                    ));
                }
            }
            Operator::Csv { path, .. } => {
                if path.is_empty() {
                    return Err(invalid("operator.path", "is empty"));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Scenario;

    fn operator(toml: &str) -> Result<Operator, ScenarioError> {
        Scenario::from_toml_str(&format!(
            "[operator]\nkind = \"csv\"\npath = \"a.csv\"\n{toml}"
        ))
        .map(|s| s.operator)
    }

    #[test]
    fn a_trajectory_file_holds_unless_told_to_loop() {
        let csv = |end| Operator::Csv {
            path: "a.csv".into(),
            end,
        };
        assert_eq!(operator("").expect("valid"), csv(TrajectoryEnd::Hold));
        assert_eq!(
            operator("end = \"loop\"").expect("valid"),
            csv(TrajectoryEnd::Loop)
        );
        let e = operator("end = \"repeat\"").expect_err("no such end");
        assert!(e.to_string().contains("repeat"), "{e}");
        // What a run's scenario.toml holds reads back the same.
        let s = Scenario {
            operator: csv(TrajectoryEnd::Loop),
            ..Scenario::default()
        };
        assert_eq!(
            Scenario::from_toml_str(&s.to_toml()).expect("round trip"),
            s
        );
    }
}
