//! `task` in summary.json: a physics scene's `[task]` (docs/16), whether and when it
//! succeeded (the slave's world counted it), and what it took: the contact force, the
//! tool's path and the operator's work, gathered from the rows (bounded memory).

use crate::trace::TraceRow;
use serde::Serialize;
use tactile_math::vec3::{distance, dot, norm};
use tactile_records::slave::TaskResult;

/// What the rows say about a task's effort, one row at a time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TaskFigures {
    peak_force_n: f64,
    force_sq: f64,
    steps: u64,
    path_m: f64,
    energy_j: f64,
    last_tool: Option<[f64; 3]>,
    last_handle: Option<[f64; 3]>,
}

impl TaskFigures {
    /// Adds one master sample's row: its slave step (the force h(n), the tool) if the
    /// slave took one, and the handle and the force the operator felt.
    pub fn add(&mut self, row: &TraceRow) {
        if row.stepped {
            let f = norm(row.h);
            self.peak_force_n = self.peak_force_n.max(f);
            self.force_sq += f * f;
            self.steps += 1;
            if let Some(p) = self.last_tool.replace(row.tool) {
                self.path_m += distance(p, row.tool);
            }
        }
        // The hand holds the handle against the rendered force: its work is the felt
        // force's, with the sign turned.
        if let Some(p) = self.last_handle.replace(row.handle) {
            let d = [0, 1, 2].map(|k| row.handle[k] - p[k]);
            self.energy_j -= dot(row.felt, d);
        }
    }
}

/// `task` in summary.json.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TaskSummary {
    /// Whether the goal was met and held for the task's `hold_s`.
    pub success: bool,
    /// Seconds from the start to the end of the first such hold; null if never.
    pub completion_s: Option<f64>,
    /// The distance to the goal at the end (m; rad for a hinge).
    pub final_distance: f64,
    /// The closest the run came to the goal.
    pub closest_distance: f64,
    /// The largest contact force the slave sent back, |h(n)|, N.
    pub peak_force_n: f64,
    /// Its RMS over the slave's steps, N.
    pub rms_force_n: f64,
    /// How far the slave's tool travelled, m (master frame).
    pub path_length_m: f64,
    /// The work the operator's hand did against the force it felt, J (net: what it
    /// put in less what the device gave back).
    pub operator_energy_j: f64,
}

impl TaskSummary {
    /// The summary of a task the slave's world counted (`result`) and its `figures`.
    pub fn new(result: &TaskResult, figures: &TaskFigures) -> TaskSummary {
        TaskSummary {
            success: result.success,
            completion_s: result.completion_s,
            final_distance: result.distance,
            closest_distance: result.closest,
            peak_force_n: figures.peak_force_n,
            rms_force_n: if figures.steps > 0 {
                (figures.force_sq / figures.steps as f64).sqrt()
            } else {
                0.0
            },
            path_length_m: figures.path_m,
            operator_energy_j: figures.energy_j,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_follow_their_definitions() {
        let mut f = TaskFigures::default();
        let mut row = TraceRow {
            stepped: true,
            ..TraceRow::default()
        };
        // Three steps: the tool 3 cm then 4 cm along two axes, forces 3, 4 and 0 N;
        // the handle pushed 1 cm into a felt 2 N (the hand does 0.02 J).
        for (k, (tool, h, handle)) in [
            ([0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
            ([0.03, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, -0.01]),
            ([0.03, 0.04, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -0.01]),
        ]
        .into_iter()
        .enumerate()
        {
            row.tool = tool;
            row.h = h;
            row.handle = handle;
            row.felt = if k == 1 { [0.0, 0.0, 2.0] } else { [0.0; 3] };
            f.add(&row);
        }
        let s = TaskSummary::new(&TaskResult::default(), &f);
        assert_eq!(s.peak_force_n, 4.0);
        assert!((s.rms_force_n - (25.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert!((s.path_length_m - 0.07).abs() < 1e-12);
        assert!((s.operator_energy_j - 0.02).abs() < 1e-12);
        // A row the slave took no step for adds nothing of the slave's.
        row.stepped = false;
        row.h = [100.0; 3];
        f.add(&row);
        assert_eq!(
            TaskSummary::new(&TaskResult::default(), &f).peak_force_n,
            4.0
        );
    }
}
