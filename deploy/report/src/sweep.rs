//! A sweep's table: the swept keys (axes) and their values, every combination of
//! them, and the row of `sweep.csv` each run's summary gives. A row is a view of the
//! run's `summary.json`, picked by the JSON pointers in [`METRICS`], so the table
//! never says anything the summaries do not.

use tactile_scenario::overrides::{split_values, Set};

/// The columns of `sweep.csv` after the swept keys: a name, and where the value is in
/// a run's `summary.json` (a JSON pointer).
pub const METRICS: [(&str, &str); 22] = [
    ("samples_sent", "/samples_sent"),
    ("samples_lost", "/samples_lost"),
    ("deadline_misses", "/deadline_misses"),
    ("tracking_rms_m", "/tracking_rms_m"),
    ("tracking_max_m", "/master/motion/tracking_max_m"),
    ("force_max_n", "/master/motion/force_max_n"),
    ("felt_rms_n", "/master/motion/felt_rms_n"),
    ("felt_max_n", "/master/motion/felt_max_n"),
    ("round_trip_p50_ns", "/round_trip_ns/p50"),
    ("round_trip_p99_ns", "/round_trip_ns/p99"),
    ("overhead_p50_ns", "/overhead_ns/p50"),
    ("overhead_p99_ns", "/overhead_ns/p99"),
    ("position_rms_m", "/tracking/position_rms_m"),
    ("force_rms_n", "/tracking/force_rms_n"),
    ("max_penetration_m", "/contact/max_penetration_m"),
    ("force_swing_n", "/contact/force_swing_n"),
    ("observer_min_j", "/passivity/observer_min_j"),
    ("side_observer_min_j", "/passivity/side_observer_min_j"),
    ("dissipated_j", "/passivity/dissipated_j"),
    ("drift_max_m", "/passivity/drift_max_m"),
    ("packets_forward", "/packets/forward"),
    ("packets_backward", "/packets/backward"),
];

/// One swept key and its values, each already a `--set`.
#[derive(Debug, Clone)]
pub struct Axis {
    /// The key as written.
    pub key: String,
    /// The values as written, in order.
    pub values: Vec<String>,
    /// `KEY=VALUE` for each value.
    pub sets: Vec<Set>,
}

/// Parses `KEY=V1,V2,...` (a value with commas inside brackets or quotes stays one).
pub fn axis(arg: &str) -> Result<Axis, String> {
    let (key, list) = arg
        .split_once('=')
        .ok_or_else(|| format!("--set {arg:?}: expected KEY=V1,V2,..."))?;
    let values = split_values(list);
    let sets = values
        .iter()
        .map(|v| Set::parse(&format!("{}={v}", key.trim())))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Axis {
        key: key.trim().to_string(),
        values,
        sets,
    })
}

/// Every combination of the axes' values, the first axis varying slowest; each
/// combination is the index of the value on every axis.
pub fn combinations(axes: &[Axis]) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new()];
    for a in axes {
        out = out
            .into_iter()
            .flat_map(|c| {
                (0..a.values.len()).map(move |i| {
                    let mut c = c.clone();
                    c.push(i);
                    c
                })
            })
            .collect();
    }
    out
}

/// The combination as `KEY=VALUE` pairs, for progress lines.
pub fn describe(axes: &[Axis], combo: &[usize]) -> String {
    let parts: Vec<String> = axes
        .iter()
        .zip(combo)
        .map(|(a, &i)| format!("{}={}", a.key, a.values[i]))
        .collect();
    parts.join(" ")
}

/// One run's values of [`METRICS`], from its summary as JSON.
pub fn values(summary: &serde_json::Value) -> Vec<Option<f64>> {
    METRICS
        .iter()
        .map(|(_, p)| summary.pointer(p).and_then(serde_json::Value::as_f64))
        .collect()
}

/// The header of `sweep.csv`.
pub fn header(axes: &[Axis]) -> String {
    let mut cols: Vec<String> = vec!["run".into()];
    cols.extend(axes.iter().map(|a| csv_field(&a.key)));
    cols.extend(METRICS.iter().map(|(n, _)| n.to_string()));
    cols.join(",") + "\n"
}

/// One run's line of `sweep.csv`.
pub fn row(k: usize, axes: &[Axis], combo: &[usize], values: &[Option<f64>]) -> String {
    let mut cols: Vec<String> = vec![k.to_string()];
    cols.extend(
        axes.iter()
            .zip(combo)
            .map(|(a, &i)| csv_field(&a.values[i])),
    );
    cols.extend(
        values
            .iter()
            .map(|v| v.map_or_else(String::new, |x| format!("{x}"))),
    );
    cols.join(",") + "\n"
}

/// A CSV field, quoted when it holds a comma or a quote.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn combinations_cover_every_pair_once() {
        let axes = [
            axis("network.forward.delay=[0,0,0],[5,5,5],[10,10,10]").expect("a"),
            axis("mode=realtime,lockstep").expect("b"),
        ];
        assert_eq!(axes[0].values.len(), 3);
        let c = combinations(&axes);
        assert_eq!(c.len(), 6);
        let mut seen = c.clone();
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), 6);
        assert_eq!(c[0], [0, 0]);
        assert_eq!(c[1], [0, 1]);
        assert_eq!(
            describe(&axes, &c[5]),
            "network.forward.delay=[10,10,10] mode=lockstep"
        );
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(csv_field("[1,2]"), "\"[1,2]\"");
        assert_eq!(csv_field("tdpa"), "tdpa");
    }
}
