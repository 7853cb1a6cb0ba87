//! `[task]`: what success is in a physics world (a body brought to a pose, a peg
//! inserted, a joint opened), so a run can say whether and when it succeeded. The
//! monitor that evaluates it each sample is `tactile-world`'s `TaskMonitor`.

use crate::shown::Num;
use crate::{finite3, invalid, positive, ScenarioError};
use serde::{Deserialize, Serialize};

/// The name a task uses for the tool body (no `[[environment.bodies]]` may take it).
pub const TOOL_BODY: &str = "tool";

fn hold() -> f64 {
    0.5
}

/// A task: its goal, met when held for `hold_s`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum TaskConfig {
    /// A body within `tolerance` of `position` (and, with `rotation`, within
    /// `angle_tolerance_deg` of it).
    Pose {
        /// The body (or `"tool"`).
        body: String,
        /// The target for its centre, m.
        position: [f64; 3],
        /// How near, m.
        tolerance: f64,
        /// The target orientation `[x, y, z, w]`; left out, any orientation.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rotation: Option<[f64; 4]>,
        /// How near in angle, degrees (with `rotation`; default 5).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        angle_tolerance_deg: Option<f64>,
        /// Seconds the goal must hold.
        #[serde(default = "hold")]
        hold_s: f64,
    },
    /// A peg's centre `depth` past the hole's mouth along `axis`, within
    /// `radial_tolerance` of the axis.
    Insert {
        /// The peg body (or `"tool"`, a peg tool).
        peg: String,
        /// The centre of the hole's mouth, m.
        mouth: [f64; 3],
        /// Into the hole (normalised on load).
        axis: [f64; 3],
        /// How deep the peg's centre must go past the mouth, m.
        depth: f64,
        /// How far off the axis the peg's centre may be, m.
        radial_tolerance: f64,
        /// Seconds the goal must hold.
        #[serde(default = "hold")]
        hold_s: f64,
    },
    /// A joint opened to `position` (rad or m from where it started): met while its
    /// position is at least `position` (at most, for a negative one).
    Joint {
        /// The joint.
        joint: String,
        /// How far it must open.
        position: f64,
        /// Seconds the goal must hold.
        #[serde(default = "hold")]
        hold_s: f64,
    },
}

impl TaskConfig {
    /// Seconds the goal must hold.
    pub fn hold_s(&self) -> f64 {
        match self {
            TaskConfig::Pose { hold_s, .. }
            | TaskConfig::Insert { hold_s, .. }
            | TaskConfig::Joint { hold_s, .. } => *hold_s,
        }
    }

    /// Checks the numbers and that what it names exists among `bodies` (and the tool)
    /// and `joints`; errors name `task.*`.
    pub fn validate(&self, bodies: &[&str], joints: &[&str]) -> Result<(), ScenarioError> {
        let hold = self.hold_s();
        if !hold.is_finite() || !(0.0..=3600.0).contains(&hold) {
            return Err(invalid(
                "task.hold_s",
                format!("{} s is outside 0 to 3600 s", Num(hold)),
            ));
        }
        let body = |field: &str, name: &str| {
            if name == TOOL_BODY || bodies.contains(&name) {
                return Ok(());
            }
            Err(invalid(
                field,
                format!(
                    "`{name}` is not a body: the bodies are {} (and \"{TOOL_BODY}\")",
                    crate::shown::listed(bodies.iter())
                ),
            ))
        };
        match self {
            TaskConfig::Pose {
                body: b,
                position,
                tolerance,
                rotation,
                angle_tolerance_deg,
                ..
            } => {
                body("task.body", b)?;
                finite3(position, "task.position")?;
                positive(*tolerance, "task.tolerance", false)?;
                if let Some(q) = rotation {
                    crate::world_check::quaternion(q, "task.rotation")?;
                }
                if let Some(a) = angle_tolerance_deg {
                    positive(*a, "task.angle_tolerance_deg", false)?;
                    if rotation.is_none() {
                        return Err(invalid(
                            "task.angle_tolerance_deg",
                            "has no meaning without task.rotation",
                        ));
                    }
                }
                Ok(())
            }
            TaskConfig::Insert {
                peg,
                mouth,
                axis,
                depth,
                radial_tolerance,
                ..
            } => {
                body("task.peg", peg)?;
                finite3(mouth, "task.mouth")?;
                crate::world_check::direction(axis, "task.axis")?;
                positive(*depth, "task.depth", false)?;
                positive(*radial_tolerance, "task.radial_tolerance", false)
            }
            TaskConfig::Joint {
                joint, position, ..
            } => {
                if !joints.contains(&joint.as_str()) {
                    return Err(invalid(
                        "task.joint",
                        format!(
                            "`{joint}` is not a joint: the joints are {}",
                            crate::shown::listed(joints.iter())
                        ),
                    ));
                }
                if !position.is_finite() || *position == 0.0 {
                    return Err(invalid(
                        "task.position",
                        format!(
                            "{} must be finite and not 0 (its sign says which way it opens)",
                            Num(*position)
                        ),
                    ));
                }
                Ok(())
            }
        }
    }
}
