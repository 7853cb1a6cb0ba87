//! Evaluating a `[task]` each sample: the distance to the goal, whether it is met,
//! and when it was first met and held for `hold_s` (the completion time).

use crate::{PhysicsWorld, Sensed};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use tactile_scenario::{TaskConfig, TOOL_BODY};

/// Degrees a pose task's orientation may be off when the scenario does not say.
pub const ANGLE_TOLERANCE_DEG: f64 = 5.0;

/// The task's state after one sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TaskProgress {
    /// How far from the goal: m for a pose or an insertion (the larger of the
    /// position's and the radial miss, for an insertion its depth still to go),
    /// rad or m still to open for a joint; 0 when met.
    pub distance: f64,
    /// Whether the goal is met in this sample.
    pub met: bool,
    /// Whether it has been met and held for `hold_s` at some point of the run.
    pub success: bool,
    /// Seconds from the start to the end of the first hold, once succeeded.
    pub completion_s: Option<f64>,
}

/// What the task refers to, resolved once against the world's names.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Subject {
    Tool,
    Body(usize),
    Joint(usize),
}

/// Evaluates a task over a run, sample by sample.
#[derive(Debug, Clone)]
pub struct TaskMonitor {
    task: TaskConfig,
    subject: Subject,
    met_since: Option<f64>,
    progress: TaskProgress,
}

fn quat(q: &[f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]))
}

impl TaskMonitor {
    /// The monitor of `task` in `world` (None: it names a body or joint the world
    /// does not have, which the scenario's check refuses before).
    pub fn new(task: &TaskConfig, world: &PhysicsWorld) -> Option<TaskMonitor> {
        let body = |name: &str| {
            if name == TOOL_BODY {
                Some(Subject::Tool)
            } else {
                world
                    .body_names()
                    .iter()
                    .position(|n| n == name)
                    .map(Subject::Body)
            }
        };
        let subject = match task {
            TaskConfig::Pose { body: b, .. } => body(b)?,
            TaskConfig::Insert { peg, .. } => body(peg)?,
            TaskConfig::Joint { joint, .. } => {
                Subject::Joint(world.joint_names().iter().position(|n| n == joint)?)
            }
        };
        Some(TaskMonitor {
            task: task.clone(),
            subject,
            met_since: None,
            progress: TaskProgress::default(),
        })
    }

    /// Takes the sample that ended at `time_s` and returns the progress.
    pub fn update(&mut self, sensed: &Sensed, time_s: f64) -> TaskProgress {
        let (distance, met) = self.measure(sensed);
        let p = &mut self.progress;
        p.distance = distance;
        p.met = met;
        if met {
            let since = *self.met_since.get_or_insert(time_s);
            if !p.success && time_s - since >= self.task.hold_s() - 1e-9 {
                p.success = true;
                p.completion_s = Some(time_s);
            }
        } else {
            self.met_since = None;
        }
        *p
    }

    /// The progress so far.
    pub fn progress(&self) -> TaskProgress {
        self.progress
    }

    fn pose<'a>(&self, s: &'a Sensed) -> Option<&'a crate::Pose> {
        match self.subject {
            Subject::Tool => Some(&s.tool),
            Subject::Body(i) => s.poses.get(i),
            Subject::Joint(_) => None,
        }
    }

    fn measure(&self, s: &Sensed) -> (f64, bool) {
        match (&self.task, self.subject) {
            (TaskConfig::Joint { position, .. }, Subject::Joint(j)) => {
                let q = s.joint_positions.get(j).copied().unwrap_or(0.0);
                let to_go = (position - q) * position.signum();
                (to_go.max(0.0), to_go <= 0.0)
            }
            (
                TaskConfig::Pose {
                    position,
                    tolerance,
                    rotation,
                    angle_tolerance_deg,
                    ..
                },
                _,
            ) => {
                let Some(p) = self.pose(s) else {
                    return (f64::INFINITY, false);
                };
                let d = (Vector3::from(p.position) - Vector3::from(*position)).norm();
                let turned_ok = rotation.is_none_or(|r| {
                    let tol = angle_tolerance_deg
                        .unwrap_or(ANGLE_TOLERANCE_DEG)
                        .to_radians();
                    quat(&p.rotation).angle_to(&quat(&r)) <= tol
                });
                (d, d <= *tolerance && turned_ok)
            }
            (
                TaskConfig::Insert {
                    mouth,
                    axis,
                    depth,
                    radial_tolerance,
                    ..
                },
                _,
            ) => {
                let Some(p) = self.pose(s) else {
                    return (f64::INFINITY, false);
                };
                let a = Vector3::from(*axis).normalize();
                let r = Vector3::from(p.position) - Vector3::from(*mouth);
                let along = r.dot(&a);
                let radial = (r - a * along).norm();
                let to_go = (depth - along).max(0.0);
                (
                    to_go.max((radial - radial_tolerance).max(0.0)),
                    to_go == 0.0 && radial <= *radial_tolerance,
                )
            }
            _ => (f64::INFINITY, false),
        }
    }
}
