//! How a metric of `sweep.csv` reads on a figure's axis: in words, in the unit a
//! reader of the field expects (millimetres, millijoules, milliseconds of round trip,
//! microseconds of overhead), the values scaled to it. The tables keep the SI values
//! of `summary.json`; only the figures scale.

/// A metric as a figure shows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shown {
    /// What it is, in words.
    pub label: &'static str,
    /// Its unit on the axis (empty: a count or a ratio).
    pub unit: &'static str,
    /// The factor from the table's value to the axis's.
    pub scale: f64,
}

impl Shown {
    /// The axis's title: the words and the unit.
    pub fn axis(&self) -> String {
        match self.unit {
            "" => self.label.to_string(),
            u => format!("{} ({u})", self.label),
        }
    }
}

const MM: (&str, f64) = ("mm", 1e3);
const MJ: (&str, f64) = ("mJ", 1e3);
const N: (&str, f64) = ("N", 1.0);
const ONE: (&str, f64) = ("", 1.0);

/// The metric `name` of [`crate::sweep::METRICS`] as a figure shows it; `None` for a
/// name it does not know (a test keeps every metric known).
pub fn shown(name: &str) -> Option<Shown> {
    let (label, (unit, scale)) = match name {
        "samples_sent" => ("samples sent", ONE),
        "samples_lost" => ("samples lost", ONE),
        "deadline_misses" => ("deadline misses", ONE),
        "tracking_rms_m" => ("RMS tracking error", MM),
        "tracking_max_m" => ("max tracking error", MM),
        "force_max_n" => ("max environment force", N),
        "felt_rms_n" => ("RMS felt force", N),
        "felt_max_n" => ("max felt force", N),
        "round_trip_p50_ns" => ("p50 round trip", ("ms", 1e-6)),
        "round_trip_p99_ns" => ("p99 round trip", ("ms", 1e-6)),
        "overhead_p50_ns" => ("p50 system overhead", ("us", 1e-3)),
        "overhead_p99_ns" => ("p99 system overhead", ("us", 1e-3)),
        "position_rms_m" => ("RMS position error", MM),
        "force_rms_n" => ("RMS force tracking error", N),
        "max_penetration_m" => ("max penetration", MM),
        "force_swing_n" => ("contact force swing over the last second", N),
        "observer_min_j" => ("min channel energy", MJ),
        "side_observer_min_j" => ("min side observer energy", MJ),
        "dissipated_j" => ("energy dissipated by the control", MJ),
        "drift_max_m" => ("max position drift", MM),
        "packets_forward" => ("packets forward", ONE),
        "packets_backward" => ("packets backward", ONE),
        "failed" => ("share of runs failed", ONE),
        "felt_stiffness_n_per_m" => ("felt stiffness", ("N/m", 1.0)),
        "environment_stiffness_n_per_m" => ("environment stiffness", ("N/m", 1.0)),
        "stiffness_ratio" => ("felt / environment stiffness", ONE),
        "stiffness_ratio_converged" => {
            ("felt / environment stiffness once the model converged", ONE)
        }
        "model_convergence_ms" => ("model convergence time", ("ms", 1.0)),
        "models_sent" => ("models sent", ONE),
        "model_injected_j" => ("energy injected by model changes", MJ),
        "felt_step_max_n" => ("largest felt force step", N),
        "unfelt_depth_m" => ("depth unfelt at the first news of contact", MM),
        "unfelt_energy_j" => ("wall energy unfelt at the first news of contact", MJ),
        "task_success" => ("share of runs whose task succeeded", ONE),
        "task_completion_s" => ("task completion time", ("s", 1.0)),
        "task_peak_force_n" => ("peak contact force in the task", N),
        "task_rms_force_n" => ("RMS contact force in the task", N),
        "task_path_length_m" => ("tool path length", MM),
        "task_operator_energy_j" => ("operator's work", MJ),
        _ => return None,
    };
    Some(Shown { label, unit, scale })
}

/// [`shown`], or the name itself unscaled.
pub fn shown_or_name(name: &'static str) -> Shown {
    shown(name).unwrap_or(Shown {
        label: name,
        unit: "",
        scale: 1.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::METRICS;

    /// A metric added to the tables gets its words and unit here, or this fails.
    #[test]
    fn every_metric_has_its_words_and_unit() {
        for (name, _) in METRICS {
            let s = shown(name).unwrap_or_else(|| panic!("{name}: no words"));
            assert!(s.scale > 0.0 && !s.label.is_empty(), "{name}");
            // The unit agrees with the name's SI suffix (none: a count or a ratio).
            let want = [
                ("_n_per_m", "N/m"),
                ("_ms", "ms"),
                ("_m", "mm"),
                ("_j", "mJ"),
                ("_n", "N"),
                ("round_trip_p50_ns", "ms"),
                ("round_trip_p99_ns", "ms"),
                ("_ns", "us"),
                ("_s", "s"),
            ]
            .iter()
            .find(|(suffix, _)| name.ends_with(suffix))
            .map_or("", |(_, u)| *u);
            assert_eq!(s.unit, want, "{name}");
        }
        assert_eq!(
            shown("position_rms_m").map(|s| s.axis()),
            Some("RMS position error (mm)".to_string())
        );
        assert_eq!(shown("no_such_metric"), None);
    }
}
