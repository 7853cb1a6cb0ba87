//! A sweep's tables: the swept keys (axes) and their values, every combination of
//! them, the row of `sweep.csv` each run's summary gives and the row of
//! `sweep-summary.csv` each combination's runs give. A row is a view of the runs'
//! `summary.json`, picked by the JSON pointers in [`METRICS`], so the tables never
//! say anything the summaries do not.

use tactile_scenario::overrides::{split_values, Set};

/// The metrics of `sweep.csv` after the swept keys and the seed: a name, and where the value is in
/// a run's `summary.json` (a JSON pointer). `failed` is 1 for a run that failed (a
/// node died or froze, a wait ran out) and 0 otherwise: a failed run's other values
/// are what it ran before it failed, so a table never passes one off as whole (in
/// `sweep-summary.csv`, `failed_mean` is the share of the seeds' runs that failed).
/// The transparency metrics and MMT's come after it: they were added later, and
/// coming last they leave the earlier columns of a table as they were.
pub const METRICS: [(&str, &str); 39] = [
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
    ("failed", "/failed"),
    (
        "felt_stiffness_n_per_m",
        "/transparency/felt_stiffness_n_per_m",
    ),
    (
        "environment_stiffness_n_per_m",
        "/transparency/environment_stiffness_n_per_m",
    ),
    ("stiffness_ratio", "/transparency/stiffness_ratio"),
    (
        "stiffness_ratio_converged",
        "/transparency/stiffness_ratio_converged",
    ),
    ("model_convergence_ms", "/transparency/model_convergence_ms"),
    ("models_sent", "/mmt/models_sent"),
    ("model_injected_j", "/mmt/injected_j"),
    ("felt_step_max_n", "/contact/felt_step_max_n"),
    ("unfelt_depth_m", "/transparency/unfelt_depth_m"),
    ("unfelt_energy_j", "/transparency/unfelt_energy_j"),
    // A physics scene's task (docs/16): columns of their own only in a sweep with a
    // task ([`columns`]), so every other table is as it was.
    ("task_success", "/task/success"),
    ("task_completion_s", "/task/completion_s"),
    ("task_peak_force_n", "/task/peak_force_n"),
    ("task_rms_force_n", "/task/rms_force_n"),
    ("task_path_length_m", "/task/path_length_m"),
    ("task_operator_energy_j", "/task/operator_energy_j"),
];

/// Where the task's metrics start in [`METRICS`].
pub const TASK_METRICS: usize = 33;

/// How many of [`METRICS`] the tables write: the task's only where some run of the
/// sweep had one (its `values` hold them).
pub fn columns<'a>(runs: impl IntoIterator<Item = &'a [Option<f64>]>) -> usize {
    let task = runs
        .into_iter()
        .any(|v| v.iter().skip(TASK_METRICS).any(Option::is_some));
    if task {
        METRICS.len()
    } else {
        TASK_METRICS
    }
}

/// The metric that says whether a run failed, not how it ran: never plotted.
pub const FAILED: &str = "failed";

/// One swept key and its values, each already a `--set`.
#[derive(Debug, Clone)]
pub struct Axis {
    /// The key as written (without the `+` of a paired key).
    pub key: String,
    /// The values as written, in order.
    pub values: Vec<String>,
    /// `KEY=VALUE` for each value.
    pub sets: Vec<Set>,
    /// Paired with the axis before it (written `+KEY=V1,V2,...`): its values go with
    /// that axis's one to one (its first with the first, ...), not in combination.
    pub paired: bool,
}

/// What is wrong with a sweep's `--set KEY=V1,V2,...`.
#[derive(Debug, thiserror::Error)]
pub enum AxisError {
    /// No `=` in it.
    #[error("--set {arg:?}: expected KEY=V1,V2,...")]
    NoValues {
        /// The argument as written.
        arg: String,
    },
    /// One of its values, as a `--set KEY=V`, is wrong.
    #[error(transparent)]
    Set(#[from] tactile_scenario::overrides::SetError),
}

/// Parses `KEY=V1,V2,...` (a value with commas inside brackets or quotes stays one),
/// or `+KEY=V1,V2,...` for a key paired with the one before it.
pub fn axis(arg: &str) -> Result<Axis, AxisError> {
    let (key, list) = arg.split_once('=').ok_or_else(|| AxisError::NoValues {
        arg: arg.to_string(),
    })?;
    let key = key.trim();
    let (key, paired) = match key.strip_prefix('+') {
        Some(k) => (k.trim(), true),
        None => (key, false),
    };
    let values = split_values(list);
    let sets = values
        .iter()
        .map(|v| Set::parse(&format!("{key}={v}")))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Axis {
        key: key.to_string(),
        values,
        sets,
        paired,
    })
}

/// Every combination of the axes' values, the first axis varying slowest; each
/// combination is the index of the value on every axis. A paired axis takes the
/// index of the axis before it.
pub fn combinations(axes: &[Axis]) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new()];
    for a in axes {
        if a.paired {
            for c in &mut out {
                let i = c.last().copied().unwrap_or(0);
                c.push(i);
            }
            continue;
        }
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
        .map(|(_, p)| {
            let v = summary.pointer(p)?;
            v.as_f64()
                .or_else(|| v.as_bool().map(|b| f64::from(u8::from(b))))
        })
        .collect()
}

/// A swept value as the tables write it, so a script reads it back whatever spacing
/// or quoting the `--set` had: a word as itself (`tdpa`), anything else as JSON (a
/// number `1000.0`, a boolean `true`, a list `[0,0,0]`, which `json.loads` reads).
pub fn value_cell(set: &Set) -> String {
    match serde_json::to_value(&set.value) {
        Ok(serde_json::Value::String(s)) => s,
        Ok(v) => v.to_string(),
        Err(_) => set.value.to_string(),
    }
}

/// The swept keys with a column of their own in `sweep.csv`: all but `seed`, which the
/// `seed` column every row has already says.
fn keyed(axes: &[Axis]) -> impl Iterator<Item = (usize, &Axis)> {
    axes.iter().enumerate().filter(|(_, a)| a.key != "seed")
}

/// The header of `sweep.csv`, one row per run with the same columns whatever
/// `--seeds`: the run's folder, its combination's index, each swept key, the seed the
/// run used, the first `n` metrics ([`columns`]).
pub fn runs_header(axes: &[Axis], n: usize) -> String {
    let mut cols: Vec<String> = vec!["run".into(), "combination".into()];
    cols.extend(keyed(axes).map(|(_, a)| csv_field(&a.key)));
    cols.push("seed".into());
    cols.extend(METRICS.iter().take(n).map(|(n, _)| n.to_string()));
    cols.join(",") + "\n"
}

/// One run's line of `sweep.csv`: its folder's name, combination `k`, the seed it ran
/// with and its metrics (as many as `values` holds: cut to the header's).
pub fn runs_row(
    run: &str,
    k: usize,
    axes: &[Axis],
    combo: &[usize],
    seed: u64,
    values: &[Option<f64>],
) -> String {
    let mut cols: Vec<String> = vec![csv_field(run), k.to_string()];
    cols.extend(keyed(axes).map(|(j, a)| csv_field(&value_cell(&a.sets[combo[j]]))));
    cols.push(seed.to_string());
    cols.extend(values.iter().map(|v| number(*v)));
    cols.join(",") + "\n"
}

/// The header of `sweep-summary.csv`, one row per combination with the same columns
/// whatever `--seeds`: per metric (the first `n`, [`columns`]) its mean and the half
/// width of its 95 % confidence interval, and how many runs were averaged.
pub fn summary_header(axes: &[Axis], n: usize) -> String {
    let mut cols: Vec<String> = vec!["combination".into()];
    cols.extend(axes.iter().map(|a| csv_field(&a.key)));
    cols.push("seeds".into());
    for (name, _) in METRICS.iter().take(n) {
        cols.push(format!("{name}_mean"));
        cols.push(format!("{name}_ci95"));
    }
    cols.join(",") + "\n"
}

/// A metric's cell: empty where there is no value.
fn number(v: Option<f64>) -> String {
    v.map_or_else(String::new, |x| format!("{x}"))
}

/// Each metric's mean and 95 % half width over one combination's runs (one `Vec` of
/// metric values per run): what `sweep.csv` and the plots show with `--seeds`.
pub fn stats(runs: &[Vec<Option<f64>>]) -> Vec<(Option<f64>, Option<f64>)> {
    (0..METRICS.len())
        .map(|m| {
            let v: Vec<f64> = runs
                .iter()
                .filter_map(|r| r.get(m).copied().flatten())
                .collect();
            mean_ci95(&v).map_or((None, None), |(a, b)| (Some(a), b))
        })
        .collect()
}

/// One combination's line of `sweep-summary.csv` over its `seeds` runs, from their
/// [`stats`]; an interval is empty for one run (one value bounds nothing).
pub fn summary_row(
    k: usize,
    axes: &[Axis],
    combo: &[usize],
    seeds: usize,
    stats: &[(Option<f64>, Option<f64>)],
) -> String {
    let mut cols: Vec<String> = vec![k.to_string()];
    cols.extend(
        axes.iter()
            .zip(combo)
            .map(|(a, &i)| csv_field(&value_cell(&a.sets[i]))),
    );
    cols.push(seeds.to_string());
    for (mean, ci) in stats {
        cols.push(number(*mean));
        cols.push(number(*ci));
    }
    cols.join(",") + "\n"
}

/// Two-sided 95 % quantiles of Student's t for 1 to 30 degrees of freedom.
const T95: [f64; 30] = [
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
    2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
    2.052, 2.048, 2.045, 2.042,
];

/// Student's t 95 % quantile for `df` degrees of freedom (beyond 30, the normal's 1.96
/// plus the first-order correction 2.4/df, within 0.2 % of the exact value).
pub fn t95(df: usize) -> f64 {
    match df {
        0 => f64::NAN,
        1..=30 => T95[df - 1],
        _ => 1.96 + 2.4 / df as f64,
    }
}

/// Mean of `v` and the half width of its 95 % confidence interval (Student's t with
/// the sample standard deviation); `None` without values, no interval for one value.
pub fn mean_ci95(v: &[f64]) -> Option<(f64, Option<f64>)> {
    let n = v.len();
    if n == 0 {
        return None;
    }
    if v.iter().all(|&x| x == v[0]) {
        // Seeds that changed nothing: the value itself, and an interval of exactly 0
        // (a mean summed in floating point would differ from the value by a rounding
        // error, and the interval would be that error posing as variation: 6.8e-16).
        return Some((v[0], (n > 1).then_some(0.0)));
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
    Some((mean, Some(t95(n - 1) * (var / n as f64).sqrt())))
}

/// The unit of a swept key, for a plot's labels: `ms` for the milliseconds keys
/// (`delay_ms`, `schedule_ms[1][0]`, `jitter.jitter_ms`, any `_ms`), `samples` for
/// their twins that count samples (`delay`, `schedule`, `jitter.jitter`, any
/// `_samples`); `s` for seconds (`operator.move_s`, any `_s`), `Hz` for a rate; `N/m` for a stiffness (`environment.objects[0].stiffness`), `N s/m`
/// for a wave impedance or a damping; `None` for the rest. A `delay` of 10 and a
/// `delay_ms` of 10 are ten times apart at 100 Hz, and a plot must say which it shows.
pub fn unit(key: &str) -> Option<&'static str> {
    let last = key.rsplit('.').next().unwrap_or(key);
    let name = last.split('[').next().unwrap_or(last);
    let samples = tactile_scenario::units::TWINS
        .iter()
        .any(|&(s, _)| s == name && (s != "jitter" || key.ends_with("jitter.jitter")));
    if name.ends_with("_ms") {
        Some("ms")
    } else if name.ends_with("_s") {
        Some("s")
    } else if name.ends_with("_hz") {
        Some("Hz")
    } else if samples || name.ends_with("_samples") {
        Some("samples")
    } else if name.ends_with("stiffness") {
        Some("N/m")
    } else if name == "wave_impedance" || name.ends_with("damping") {
        Some("N s/m")
    } else {
        None
    }
}

/// A swept key with its unit, as a plot labels it: `network.forward.delay_ms (ms)`.
pub fn labelled(key: &str) -> String {
    unit(key).map_or_else(|| key.to_string(), |u| format!("{key} ({u})"))
}

/// A swept value as a number for a plot's axis: the number itself, or the one number
/// a vector repeats (`[25,25,25]` is 25); `None` for words and for a vector of
/// different numbers (`[0,3,6]` is no more 3 than `[3,3,3]`: a plot shows it as a
/// category, written as it was swept).
pub fn numeric(value: &str) -> Option<f64> {
    let v = value.trim();
    if let Ok(x) = v.parse::<f64>() {
        return Some(x);
    }
    let inner = v.strip_prefix('[')?.strip_suffix(']')?;
    let xs: Vec<f64> = inner
        .split(',')
        .map(|e| e.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()?;
    let first = *xs.first()?;
    xs.iter().all(|x| *x == first).then_some(first)
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

    /// A time key's plot label says its unit; other keys none.
    #[test]
    fn swept_keys_are_labelled_with_their_unit() {
        for (key, want) in [
            ("network.forward.delay_ms", "network.forward.delay_ms (ms)"),
            ("network.forward.delay", "network.forward.delay (samples)"),
            (
                "network.backward.delay[0]",
                "network.backward.delay[0] (samples)",
            ),
            (
                "network.forward.schedule_ms[1][0]",
                "network.forward.schedule_ms[1][0] (ms)",
            ),
            (
                "network.forward.schedule",
                "network.forward.schedule (samples)",
            ),
            (
                "network.forward.jitter.jitter",
                "network.forward.jitter.jitter (samples)",
            ),
            (
                "network.forward.jitter.jitter_ms",
                "network.forward.jitter.jitter_ms (ms)",
            ),
            (
                "faults.peer_timeout_samples",
                "faults.peer_timeout_samples (samples)",
            ),
            ("network.forward.jitter", "network.forward.jitter"),
            (
                "environment.objects[0].stiffness",
                "environment.objects[0].stiffness (N/m)",
            ),
            ("control.wave_impedance", "control.wave_impedance (N s/m)"),
            ("operator.move_s", "operator.move_s (s)"),
            ("rate_hz", "rate_hz (Hz)"),
            ("samples", "samples"),
            ("control.kind", "control.kind"),
            ("network.forward.loss", "network.forward.loss"),
        ] {
            assert_eq!(labelled(key), want);
        }
    }

    /// The task's columns are written only for a sweep where a run had a task: every
    /// other sweep's tables keep their columns.
    #[test]
    fn the_tasks_columns_come_with_a_task_only() {
        let wall = values(&serde_json::json!({"samples_sent": 5}));
        let task = values(&serde_json::json!({"task": {"success": true, "completion_s": 4.5}}));
        assert_eq!(wall.len(), METRICS.len());
        assert_eq!(columns([wall.as_slice()]), TASK_METRICS);
        assert_eq!(columns([wall.as_slice(), task.as_slice()]), METRICS.len());
        assert_eq!(METRICS[TASK_METRICS].0, "task_success");
        assert_eq!(task[TASK_METRICS], Some(1.0));
        assert_eq!(task[TASK_METRICS + 1], Some(4.5));
        let header = runs_header(&[], TASK_METRICS);
        assert!(header.trim_end().ends_with("unfelt_energy_j"), "{header}");
    }

    #[test]
    fn a_failed_run_is_one_in_its_column_and_a_whole_run_zero() {
        let col = METRICS
            .iter()
            .position(|(n, _)| *n == FAILED)
            .expect("column");
        let failed = serde_json::json!({"failed": true, "samples_sent": 5});
        let whole = serde_json::json!({"failed": false, "samples_sent": 5});
        assert_eq!(values(&failed)[col], Some(1.0));
        assert_eq!(values(&whole)[col], Some(0.0));
        assert_eq!(values(&failed)[0], Some(5.0));
        // Over seeds, the share that failed.
        let runs = [
            values(&failed),
            values(&whole),
            values(&whole),
            values(&whole),
        ];
        assert_eq!(stats(&runs)[col].0, Some(0.25));
    }

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
    fn vectors_of_one_number_are_that_number_on_an_axis() {
        assert_eq!(numeric("25"), Some(25.0));
        assert_eq!(numeric("[25,25,25]"), Some(25.0));
        assert_eq!(numeric("[0, 3, 6]"), None);
        assert_eq!(numeric("[3, 3, 3.0]"), Some(3.0));
        assert_eq!(numeric("tdpa"), None);
        assert_eq!(numeric("[a,b]"), None);
    }

    /// A metric of known variance: normal values (Box-Muller over a seeded LCG),
    /// mean 10, sigma 2. The interval covers the true mean 95 % of the time, and its
    /// width shrinks as t(N-1) sigma / sqrt(N).
    #[test]
    fn the_interval_covers_the_mean_as_often_as_it_says() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((seed >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let mut normal = move || {
            let (u, v) = (uniform(), uniform());
            10.0 + 2.0 * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        for n in [5usize, 20] {
            let (mut covered, mut width) = (0, 0.0);
            let trials = 4000;
            for _ in 0..trials {
                let v: Vec<f64> = (0..n).map(|_| normal()).collect();
                let (mean, ci) = mean_ci95(&v).expect("values");
                let ci = ci.expect("n > 1");
                covered += usize::from((mean - 10.0).abs() <= ci);
                width += ci / trials as f64;
            }
            let coverage = covered as f64 / trials as f64;
            assert!(
                (0.935..=0.965).contains(&coverage),
                "n {n}: coverage {coverage}"
            );
            // E[s] = c4 sigma; c4 is 0.940 for n = 5, 0.987 for n = 20.
            let c4 = if n == 5 { 0.9400 } else { 0.9869 };
            let expected = t95(n - 1) * 2.0 * c4 / (n as f64).sqrt();
            assert!(
                (width / expected - 1.0).abs() < 0.03,
                "n {n}: {width} vs {expected}"
            );
        }
        assert_eq!(mean_ci95(&[3.0]), Some((3.0, None)));
        assert_eq!(mean_ci95(&[]), None);
    }

    /// Seeds that change nothing give the value and no variation, not a rounding
    /// error: three 0.1s sum to 0.30000000000000004, whose third is not 0.1.
    #[test]
    fn equal_values_have_an_interval_of_zero() {
        assert_eq!(mean_ci95(&[0.1; 3]), Some((0.1, Some(0.0))));
        assert_eq!(mean_ci95(&[0.0012345; 20]), Some((0.0012345, Some(0.0))));
        let (_, ci) = mean_ci95(&[0.1, 0.1, 0.1000001]).expect("values");
        assert!(ci.expect("three") > 0.0);
    }

    #[test]
    fn a_paired_axis_moves_with_the_one_before() {
        let axes = [
            axis("network.forward.delay_ms=0,5,25").expect("a"),
            axis("+network.backward.delay_ms=0,5,25").expect("b"),
            axis("control.kind=none,tdpa").expect("c"),
        ];
        assert!(!axes[0].paired && axes[1].paired && !axes[2].paired);
        assert_eq!(axes[1].key, "network.backward.delay_ms");
        let c = combinations(&axes);
        assert_eq!(c.len(), 6);
        assert_eq!(c[0], [0, 0, 0]);
        assert_eq!(c[1], [0, 0, 1]);
        assert_eq!(c[5], [2, 2, 1]);
        assert_eq!(
            describe(&axes, &c[3]),
            "network.forward.delay_ms=5 network.backward.delay_ms=5 control.kind=tdpa"
        );
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(csv_field("[1,2]"), "\"[1,2]\"");
        assert_eq!(csv_field("tdpa"), "tdpa");
    }

    /// A list reads back as JSON whatever its spacing; a word as itself.
    #[test]
    fn swept_values_are_written_to_be_parsed_back() {
        let a = axis("network.forward.delay=[0, 0, 0],[5,5, 5]").expect("a");
        assert_eq!(value_cell(&a.sets[0]), "[0,0,0]");
        assert_eq!(value_cell(&a.sets[1]), "[5,5,5]");
        let b = axis("control.kind=tdpa,\"wave\"").expect("b");
        assert_eq!(value_cell(&b.sets[0]), "tdpa");
        assert_eq!(value_cell(&b.sets[1]), "wave");
        let c = axis("rate_hz=1000.0,500").expect("c");
        assert_eq!(value_cell(&c.sets[0]), "1000.0");
        assert_eq!(value_cell(&c.sets[1]), "500");
        let d = axis("scale=[0.5,1e-3]").expect("d");
        let back: Vec<f64> = serde_json::from_str(&value_cell(&d.sets[0])).expect("json");
        assert_eq!(back, [0.5, 1e-3]);
    }
}
