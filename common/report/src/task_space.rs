//! A URDF arm's figures in the task space (`task_space` in summary.json): the tool
//! against the target the slave was given after the master's workspace map (scale,
//! rotation between the bases, clutch offsets, workspace box), position and
//! orientation, in the arm's base frame. The trace's `tool` against `v` cannot say
//! this: v(n) is the master's position, which knows neither the clutch's offsets nor
//! the box, so a run with a clutch measured that way reads as centimetres off a robot
//! that follows within a fraction of a millimetre.
//!
//! Released stretches (the operator's clutch open) are not mixed into the tracking
//! error: the robot holds its reference there while the master moves freely. They are
//! counted on their own (samples, seconds, engages) with how far the tool strayed from
//! the reference it held.

use crate::joints::angle_deg;
use crate::trace::TraceRow;
use serde::Serialize;
use tactile_math::vec3::{distance, norm};
use tactile_records::slave::ArmJoints;
use tactile_scenario::Scenario;

/// `task_space` in summary.json (a URDF arm's runs only).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct TaskSpace {
    /// RMS distance of the tool from its position target over the engaged steps, m,
    /// in the arm's base frame (the robot's metres, not the master's); null without
    /// an engaged step.
    pub position_rms_m: Option<f64>,
    /// Largest such distance, m.
    pub position_max_m: Option<f64>,
    /// RMS angle between the tool's orientation and its target over the engaged
    /// steps, degrees.
    pub rotation_rms_deg: Option<f64>,
    /// Largest such angle, degrees.
    pub rotation_max_deg: Option<f64>,
    /// Engaged steps compared (the slave's steps on v(n) with its joints recorded).
    pub engaged_samples: u64,
    /// Steps with the clutch released (left out of the figures above).
    pub released_samples: u64,
    /// Their time, s (`released_samples` times the sample period).
    pub released_s: f64,
    /// Engages after a release.
    pub engages: u64,
    /// Largest distance of the tool from the reference it held while released, m.
    pub held_max_m: Option<f64>,
    /// Largest force of the environment at the robot's tool, before `force_scale`, N
    /// (`slave.motion`'s `force_max_n` is h(n), after it).
    pub robot_force_max_n: f64,
    /// The scenario's `slave.arm.force_scale` the robot's force was taken back through.
    pub force_scale: f64,
}

/// The running sums of [`TaskSpace`].
#[derive(Debug, Clone, Default)]
pub struct TaskSpaceSums {
    figures: TaskSpace,
    t_s: f64,
    position_sq: f64,
    rotation_sq: f64,
    was_released: bool,
}

impl TaskSpaceSums {
    /// Sums for `scenario`'s arm; `None` when the slave is the paper's arm (no map:
    /// its tracking error is the trace's `tool` against `reference`).
    pub fn of(scenario: &Scenario) -> Option<Self> {
        let arm = scenario.slave.arm.as_ref()?;
        Some(TaskSpaceSums {
            figures: TaskSpace {
                force_scale: arm.force_scale,
                ..TaskSpace::default()
            },
            t_s: scenario.t_s(),
            ..TaskSpaceSums::default()
        })
    }

    /// Adds one step of the arm (rows come in sample order).
    pub fn add(&mut self, row: &TraceRow, j: &ArmJoints) {
        let f = &mut self.figures;
        // h(n) = force_scale times the environment's force (turned into the master's
        // axes, a rotation: the length is kept).
        f.robot_force_max_n = f.robot_force_max_n.max(norm(row.h) / f.force_scale);
        let d = distance(j.tool_position, j.target_position);
        if j.released {
            f.released_samples += 1;
            f.held_max_m = Some(f.held_max_m.unwrap_or(0.0).max(d));
            self.was_released = true;
            return;
        }
        if std::mem::take(&mut self.was_released) {
            f.engages += 1;
        }
        let a = angle_deg(j.target_rotation, j.tool_rotation);
        f.engaged_samples += 1;
        f.position_max_m = Some(f.position_max_m.unwrap_or(0.0).max(d));
        f.rotation_max_deg = Some(f.rotation_max_deg.unwrap_or(0.0).max(a));
        self.position_sq += d * d;
        self.rotation_sq += a * a;
    }

    /// The figures, the sums closed.
    pub fn finish(&self) -> TaskSpace {
        let mut f = self.figures;
        f.released_s = f.released_samples as f64 * self.t_s;
        if f.engaged_samples > 0 {
            let k = f.engaged_samples as f64;
            f.position_rms_m = Some((self.position_sq / k).sqrt());
            f.rotation_rms_deg = Some((self.rotation_sq / k).sqrt());
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joints(tool: [f64; 3], target: [f64; 3], released: bool) -> ArmJoints {
        ArmJoints {
            tool_position: tool,
            target_position: target,
            target_rotation: [0.0, 0.0, 0.0, 1.0],
            tool_rotation: [0.0, 0.0, 0.0, 1.0],
            released,
            ..ArmJoints::default()
        }
    }

    #[test]
    fn releases_are_counted_apart_from_the_tracking_error() {
        let mut s = TaskSpaceSums {
            figures: TaskSpace {
                force_scale: 0.5,
                ..TaskSpace::default()
            },
            t_s: 1e-3,
            ..TaskSpaceSums::default()
        };
        let row = TraceRow {
            h: [0.0, 3.0, 4.0],
            ..TraceRow::default()
        };
        // Engaged 3 mm and 4 mm off, released 1 m off (left out), engaged 0 mm off.
        let steps = [
            ([0.003, 0.0, 0.0], false),
            ([0.0, 0.004, 0.0], false),
            ([1.0, 0.0, 0.0], true),
            ([0.0, 0.0, 0.0], true),
            ([0.0, 0.0, 0.0], false),
        ];
        for (tool, released) in steps {
            s.add(&row, &joints(tool, [0.0; 3], released));
        }
        let f = s.finish();
        assert_eq!(f.engaged_samples, 3);
        assert_eq!((f.released_samples, f.engages), (2, 1));
        assert!((f.released_s - 2e-3).abs() < 1e-15);
        assert_eq!(f.held_max_m, Some(1.0));
        assert_eq!(f.position_max_m, Some(0.004));
        let rms = ((9e-6 + 16e-6) / 3.0f64).sqrt();
        assert!((f.position_rms_m.unwrap_or(0.0) - rms).abs() < 1e-15);
        assert_eq!(f.rotation_max_deg, Some(0.0));
        assert_eq!(f.robot_force_max_n, 10.0);
    }
}
