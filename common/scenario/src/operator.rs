//! `[operator]`: what the operator's hand does, a(n).

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
    /// Positions from a CSV file with header `x,y,z`, one row per sample (looped).
    Csv {
        /// Path, relative to the scenario file's folder.
        path: String,
    },
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
                        format!("{radius} m is outside (0, 1] m"),
                    ));
                }
                if !period_s.is_finite() || *period_s <= 0.0 {
                    return Err(invalid(
                        "operator.period_s",
                        format!("{period_s} must be positive"),
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
                        format!("{move_s} must be positive"),
                    ));
                }
            }
            Operator::Csv { path } => {
                if path.is_empty() {
                    return Err(invalid("operator.path", "is empty"));
                }
            }
        }
        Ok(())
    }
}
