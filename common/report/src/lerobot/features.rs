//! The dataset's features: which trace values make each vector, their names and
//! units, described once in [`Layout`] so the Parquet columns, `info.json` and the
//! statistics cannot disagree.

use crate::trace::TraceRow;
use tactile_messages::samples::Flags;
use tactile_records::slave::ArmJoints;

/// The paper's arm's joints, in its three-angle columns' order.
pub const PAPER_JOINTS: [&str; 3] = ["waist", "shoulder", "elbow"];

/// The float features, in the data file's column order.
pub const FEATURES: [&str; 5] = [
    "observation.state",
    "action",
    "observation.effort",
    "observation.force",
    "observation.network",
];

/// The entries' names and units of every feature, for one arm.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The slave's joint names (a URDF's, or the paper arm's three).
    pub joints: Vec<String>,
    /// A joint's unit: rad, or m for a prismatic one (a URDF's joint types are not
    /// read here: "rad or m").
    pub joint_unit: &'static str,
}

/// One frame's vectors, in [`FEATURES`]' order.
pub type Frame = [Vec<f32>; 5];

const AXES: [&str; 3] = ["x", "y", "z"];
const QUAT: [&str; 4] = ["x", "y", "z", "w"];

/// `prefix.axis` for each axis, with `unit` each.
fn named(prefix: &str, axes: &[&str], unit: &str, out: &mut Vec<(String, String)>) {
    out.extend(
        axes.iter()
            .map(|a| (format!("{prefix}.{a}"), unit.to_string())),
    );
}

impl Layout {
    /// The paper's arm, or a URDF arm of these joints.
    pub fn new(joints: Option<Vec<String>>) -> Layout {
        match joints {
            Some(joints) => Layout {
                joints,
                joint_unit: "rad or m",
            },
            None => Layout {
                joints: PAPER_JOINTS.iter().map(|s| s.to_string()).collect(),
                joint_unit: "rad",
            },
        }
    }

    /// Each feature's entries as (name, unit), in [`FEATURES`]' order.
    pub fn entries(&self) -> [Vec<(String, String)>; 5] {
        let joints = |unit: &str| -> Vec<(String, String)> {
            self.joints
                .iter()
                .map(|j| (j.clone(), unit.to_string()))
                .collect()
        };
        let mut state = Vec::new();
        named("master.handle", &AXES, "m", &mut state);
        named("master.rotation", &QUAT, "1", &mut state);
        state.extend(joints(self.joint_unit));
        let torque = if self.joint_unit == "rad" {
            "N m"
        } else {
            "N m or N"
        };
        let mut force = Vec::new();
        named("master.felt", &AXES, "N", &mut force);
        named("slave.force", &AXES, "N", &mut force);
        named("slave.torque", &AXES, "N m", &mut force);
        let network = [
            ("forward_delay_ms", "ms"),
            ("backward_delay_ms", "ms"),
            ("forward_substituted", "0 or 1"),
            ("backward_substituted", "0 or 1"),
            ("answer_lost", "0 or 1"),
            ("round_trip_ms", "ms"),
        ]
        .map(|(n, u)| (n.to_string(), u.to_string()))
        .to_vec();
        [
            state,
            joints(self.joint_unit),
            joints(torque),
            force,
            network,
        ]
    }
}

/// The slave's joints and force as last recorded: a sample whose slave did not step
/// (its v(n) lost) holds them, the values at or before the sample, as frames are
/// chosen (the trace's zeros there are no value the slave had).
#[derive(Debug, Clone, PartialEq)]
pub struct Held {
    q_ref: Vec<f64>,
    q: Vec<f64>,
    tau: Vec<f64>,
    torque: [f64; 3],
    /// h(n), the environment's force at the slave, N.
    force: [f64; 3],
}

impl Held {
    /// Zeros for `dof` joints, before the slave's first step.
    pub fn new(dof: usize) -> Held {
        Held {
            q_ref: vec![0.0; dof],
            q: vec![0.0; dof],
            tau: vec![0.0; dof],
            torque: [0.0; 3],
            force: [0.0; 3],
        }
    }

    /// Takes the slave's part of a row where the slave stepped: a URDF arm's joints,
    /// or the paper arm's from the row; joints of another count than the layout's are
    /// ignored.
    pub fn take(&mut self, row: &TraceRow, joints: Option<&ArmJoints>) {
        if row.stepped {
            self.force = row.h;
        }
        match joints {
            Some(j) if j.q.len() == self.q.len() => {
                self.q_ref.copy_from_slice(&j.q_ref);
                self.q.copy_from_slice(&j.q);
                self.tau.copy_from_slice(&j.tau);
                self.torque = j.torque;
            }
            Some(_) => {}
            None if row.stepped && self.q.len() == 3 => {
                self.q_ref.copy_from_slice(&row.theta_ref);
                self.q.copy_from_slice(&row.theta_sd);
                self.tau.copy_from_slice(&row.u);
            }
            None => {}
        }
    }
}

fn f32s<'a>(it: impl IntoIterator<Item = &'a f64>) -> Vec<f32> {
    it.into_iter().map(|&x| x as f32).collect()
}

fn flag(b: bool) -> f32 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// The frame of sample `row` (with the joints `held` as of it), `t_s` the sample
/// period in seconds.
pub fn frame(row: &TraceRow, rotation: Option<[f64; 4]>, held: &Held, t_s: f64) -> Frame {
    let rotation = rotation.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    let state = f32s(row.handle.iter().chain(&rotation).chain(&held.q));
    let force = f32s(row.felt.iter().chain(&held.force).chain(&held.torque));
    let ms = |d: &[u32; 3]| (f64::from(d.iter().copied().max().unwrap_or(0)) * t_s * 1e3) as f32;
    let network = vec![
        ms(&row.delay_f),
        ms(&row.delay_b),
        flag(row.flags_f.contains(Flags::SUBSTITUTED)),
        flag(row.flags_b.contains(Flags::SUBSTITUTED)),
        flag(!row.received),
        (row.round_trip_ns as f64 * 1e-6) as f32,
    ];
    [state, f32s(&held.q_ref), f32s(&held.tau), force, network]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_of_a_frame_has_a_name() {
        let layout = Layout::new(Some(vec!["a".into(), "b".into()]));
        let f = frame(&TraceRow::default(), None, &Held::new(2), 1e-3);
        for (v, names) in f.iter().zip(layout.entries()) {
            assert_eq!(v.len(), names.len(), "{names:?}");
        }
        let paper = Layout::new(None);
        let f = frame(&TraceRow::default(), None, &Held::new(3), 1e-3);
        for (v, names) in f.iter().zip(paper.entries()) {
            assert_eq!(v.len(), names.len(), "{names:?}");
        }
    }

    #[test]
    fn a_row_without_a_step_holds_the_joints() {
        let mut held = Held::new(3);
        let mut row = TraceRow {
            stepped: true,
            theta_sd: [0.1, 0.2, 0.3],
            ..TraceRow::default()
        };
        held.take(&row, None);
        row.stepped = false;
        row.theta_sd = [0.0; 3];
        held.take(&row, None);
        let f = frame(&row, None, &held, 1e-3);
        assert_eq!(f[0][7..], [0.1f32, 0.2, 0.3]);
    }
}
