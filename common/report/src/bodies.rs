//! A physics world's bodies in a report (`engine = "physics"`, docs/16): `bodies.csv`,
//! the moving bodies' poses as a table beside `trace.csv`, and `task.svg`, the
//! `[task]`'s measure over the run with its target and the moment of success.
//!
//! The slave's record holds the moving (dynamic and kinematic) bodies' poses each
//! sample, in turns of 16 where a scene has more (`tactile_records::slave::WorldSample`);
//! the static bodies never move and are where the scenario puts them.

use crate::plots::{self, PlotResult, Thinned};
use crate::Error;
use plotters::style::RGBColor;
use std::io::Write as _;
use std::path::Path;
use tactile_records::slave::{BodyPose, WorldSample};
use tactile_scenario::world::{BodyKind, Engine, JointKind};
use tactile_scenario::{Scenario, TaskConfig, TOOL_BODY};

/// The bodies' table's file name in a report folder.
pub const BODIES_FILE: &str = "bodies.csv";

/// The task's plot's file name.
pub const TASK_PLOT: &str = "task.svg";

/// `bodies.csv`'s header.
pub const HEADER: &str = "sample,body,x,y,z,qx,qy,qz,qw";

/// The moving bodies' names, in the order the record holds their poses: the
/// scenario's `[[environment.bodies]]` less the static ones.
pub fn moving_names(scenario: &Scenario) -> Vec<String> {
    scenario
        .environment
        .bodies
        .iter()
        .filter(|b| b.kind != BodyKind::Static)
        .map(|b| b.name.clone())
        .collect()
}

/// Appends `bodies.csv`'s rows of one sample to `line`: the tool, then each moving
/// body the sample holds (a body past `names` is a damaged row's: left out).
pub fn rows(line: &mut String, n: u64, names: &[String], w: &WorldSample) {
    use std::fmt::Write as _;
    let mut put = |name: &str, p: &BodyPose| {
        let [x, y, z] = p.position;
        let [qx, qy, qz, qw] = p.rotation;
        let _ = writeln!(line, "{n},{name},{x},{y},{z},{qx},{qy},{qz},{qw}");
    };
    put(TOOL_BODY, &w.tool);
    for (k, p) in w.poses() {
        if let Some(name) = names.get(k) {
            put(name, p);
        }
    }
}

/// `bodies.csv` as a report streams it (written under its partial name, renamed when
/// whole).
pub(crate) struct BodiesCsv {
    w: std::io::BufWriter<std::fs::File>,
    names: Vec<String>,
    line: String,
}

impl BodiesCsv {
    /// Starts `out/bodies.csv` for a physics scenario; any other removes an old one.
    pub(crate) fn create(out: &Path, scenario: &Scenario) -> Result<Option<BodiesCsv>, Error> {
        let path = out.join(BODIES_FILE);
        if scenario.environment.engine != Engine::Physics {
            let _ = std::fs::remove_file(&path);
            return Ok(None);
        }
        let f = std::fs::File::create(crate::out::partial(&path))
            .map_err(Error::io(format!("writing {}", path.display())))?;
        let mut w = std::io::BufWriter::with_capacity(1 << 16, f);
        writeln!(w, "{HEADER}").map_err(Error::io(format!("writing {BODIES_FILE}")))?;
        Ok(Some(BodiesCsv {
            w,
            names: moving_names(scenario),
            line: String::with_capacity(1024),
        }))
    }

    /// One sample's rows.
    pub(crate) fn add(&mut self, n: u64, world: &WorldSample) -> Result<(), Error> {
        self.line.clear();
        rows(&mut self.line, n, &self.names, world);
        self.w
            .write_all(self.line.as_bytes())
            .map_err(Error::io(format!("writing {BODIES_FILE}")))
    }

    /// Flushes the table and gives it its name.
    pub(crate) fn finish(mut self, out: &Path) -> Result<(), Error> {
        let path = out.join(BODIES_FILE);
        self.w
            .flush()
            .and_then(|()| std::fs::rename(crate::out::partial(&path), &path))
            .map_err(Error::io(format!("writing {BODIES_FILE}")))
    }
}

/// How a task's measure is drawn: its unit's scale, the axis' name and the target
/// line's value and name.
struct Measure {
    scale: f64,
    y_desc: String,
    target: f64,
    target_label: String,
}

impl Measure {
    fn of(task: &TaskConfig, scenario: &Scenario) -> Measure {
        match task {
            TaskConfig::Pose {
                body, tolerance, ..
            } => Measure {
                scale: 1e3,
                y_desc: format!("`{body}` to its target (mm)"),
                target: tolerance * 1e3,
                target_label: format!("tolerance {} mm", tolerance * 1e3),
            },
            TaskConfig::Insert { peg, .. } => Measure {
                scale: 1e3,
                y_desc: format!("`{peg}`: depth to go or radial miss (mm)"),
                target: 0.0,
                target_label: "inserted (0)".into(),
            },
            TaskConfig::Joint {
                joint, position, ..
            } => {
                let revolute = scenario
                    .environment
                    .joints
                    .iter()
                    .any(|j| j.name == *joint && j.kind == JointKind::Revolute);
                let (scale, unit) = if revolute {
                    (180.0 / std::f64::consts::PI, "deg")
                } else {
                    (1e3, "mm")
                };
                Measure {
                    scale,
                    y_desc: format!("`{joint}` still to open ({unit})"),
                    target: 0.0,
                    target_label: format!("opened by {} {unit}", position.abs() * scale),
                }
            }
        }
    }
}

/// A task's measure over a run, thinned to the plot's width as the other time
/// series are, and the moment it succeeded.
#[derive(Debug, Clone, Default)]
pub struct TaskSeries {
    distance: Thinned,
    success_s: Option<f64>,
    t_end: f64,
}

impl TaskSeries {
    /// A series for a scenario with a `[task]`; None without one.
    pub fn of(scenario: &Scenario) -> Option<TaskSeries> {
        scenario.task.as_ref().map(|_| TaskSeries::default())
    }

    /// Adds sample `n` (at `t` s) of a world's record.
    pub fn add(&mut self, t: f64, world: Option<&WorldSample>) {
        self.t_end = self.t_end.max(t);
        let Some(task) = world.and_then(|w| w.task) else {
            self.distance.push(t, f64::NAN);
            return;
        };
        self.distance.push(t, task.distance);
        if task.success && self.success_s.is_none() {
            self.success_s = Some(t);
        }
    }

    /// Writes `out/task.svg`: the measure, the target line and, if it succeeded, a
    /// band over the hold that ended at the moment of success: `completion_s`, the
    /// slave's own count (its world's time after the step), else the first sample
    /// the record says succeeded. A run whose record holds no task state (a
    /// record without the world) writes none and removes an old one.
    pub fn write(&self, out: &Path, scenario: &Scenario, completion_s: Option<f64>) -> PlotResult {
        let path = out.join(TASK_PLOT);
        let Some(task) = &scenario.task else {
            return Ok(());
        };
        let m = Measure::of(task, scenario);
        let points: Vec<(f64, f64)> = self
            .distance
            .points()
            .into_iter()
            .map(|(t, d)| (t, d * m.scale))
            .collect();
        if points.is_empty() {
            let _ = std::fs::remove_file(&path);
            return Ok(());
        }
        let target = vec![(0.0, m.target), (self.t_end, m.target)];
        let lines = [
            (
                "distance to the goal".to_string(),
                RGBColor(31, 119, 180),
                true,
                points,
            ),
            (m.target_label, RGBColor(214, 39, 40), false, target),
        ];
        // The hold that made it a success, ending at the moment of success.
        let success_s = self.success_s.map(|t| completion_s.unwrap_or(t));
        let (band, label) = match success_s {
            Some(t) => (
                vec![((t - task.hold_s()).max(0.0), t)],
                format!("held {} s: success at {t:.3} s", task.hold_s()),
            ),
            None => (Vec::new(), String::new()),
        };
        let outcome = match success_s {
            Some(_) => "succeeded",
            None => "did not succeed",
        };
        plots::whole_svg(&path, |p| {
            plots::time_series(
                p,
                (&format!("Task progress: {outcome}"), &m.y_desc),
                &lines,
                (&band, &label),
            )
        })
    }
}

/// Removes an old `task.svg` (a report whose scenario has no task).
pub(crate) fn remove_task_plot(out: &Path) -> Result<(), Error> {
    crate::out::remove_if_there(&out.join(TASK_PLOT))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_records::slave::TaskSample;

    fn push_box() -> Scenario {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../deploy/scenarios/push-box.toml");
        let text = std::fs::read_to_string(path).expect("push-box.toml");
        Scenario::from_toml_str(&text).expect("push-box")
    }

    /// A sample's rows: the tool, then each body the row holds by its name among the
    /// moving ones; an index past them (a damaged row's) is left out.
    #[test]
    fn a_samples_rows_name_the_tool_and_the_moving_bodies() {
        let names = moving_names(&push_box());
        assert_eq!(names, ["box"]);
        let mut w = WorldSample {
            bodies: 2,
            ..WorldSample::default()
        };
        w.poses[0].position = [0.5, -0.25, 0.125];
        let mut line = String::new();
        rows(&mut line, 7, &names, &w);
        assert_eq!(
            line,
            "7,tool,0,0,0,0,0,0,1\n7,box,0.5,-0.25,0.125,0,0,0,1\n"
        );
    }

    /// A task plot has a line to draw or is not written: a run whose record holds no
    /// task state leaves no blank task.svg (an old one is removed).
    #[test]
    fn a_task_plot_is_drawn_from_the_record_or_not_at_all() {
        let dir = tempfile::tempdir().expect("tempdir");
        let scenario = push_box();
        let path = dir.path().join(TASK_PLOT);
        std::fs::write(&path, "old").expect("old plot");
        let mut none = TaskSeries::of(&scenario).expect("a task");
        none.add(0.0, None);
        none.write(dir.path(), &scenario, None).expect("written");
        assert!(!path.exists());
        let mut s = TaskSeries::of(&scenario).expect("a task");
        for n in 0..1000 {
            let t = n as f64 * 1e-3;
            let w = WorldSample {
                task: Some(TaskSample {
                    distance: 0.05 - 5e-5 * n as f64,
                    met: n >= 800,
                    success: n >= 900,
                }),
                ..WorldSample::default()
            };
            s.add(t, Some(&w));
        }
        s.write(dir.path(), &scenario, Some(0.901))
            .expect("written");
        let svg = std::fs::read_to_string(&path).expect("task.svg");
        for want in [
            "Task progress: succeeded",
            "tolerance 10 mm",
            "success at 0.901 s",
        ] {
            assert!(svg.contains(want), "{want}");
        }
    }
}
