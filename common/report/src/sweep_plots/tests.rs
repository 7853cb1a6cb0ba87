use super::*;
use crate::plots::look;
use crate::plots::looks::svg;
use crate::sweep::{axis, combinations};

/// Every metric's points over `axes` (`KEY=V1,V2,...` each), each metric's value at a
/// combination `value(combination)`; the plots written into a fresh folder, which is
/// returned with the files written.
fn plots(
    keys: &[&str],
    value: impl Fn(&[usize]) -> Option<f64>,
) -> (tempfile::TempDir, Vec<String>) {
    let axes: Vec<Axis> = keys.iter().map(|k| axis(k).expect("axis")).collect();
    let points: Vec<Point> = combinations(&axes)
        .into_iter()
        .map(|c| {
            let v = value(&c);
            (c, vec![(v, None); METRICS.len()])
        })
        .collect();
    let dir = tempfile::tempdir().expect("tmp");
    let files = sweep_plots(dir.path(), &axes, &points).expect("plots");
    (dir, files)
}

fn read(dir: &tempfile::TempDir, metric: &str) -> String {
    std::fs::read_to_string(dir.path().join(format!("sweep-{metric}.svg"))).expect("svg")
}

/// The colour of series `k` of `n`, as the SVG writes it.
fn hex(k: usize, n: usize) -> String {
    let c = look(k, n).colour;
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// The x coordinates of each `<polyline>` drawn in `colour`.
fn polyline_xs(text: &str, colour: &str) -> Vec<Vec<i32>> {
    text.split("<polyline")
        .skip(1)
        .filter(|el| el.contains(&format!("stroke=\"{colour}\"")))
        .filter_map(|el| {
            let pts = el.split("points=\"").nth(1)?.split('"').next()?;
            let xs = pts
                .split_whitespace()
                .filter_map(|p| p.split(',').next()?.parse().ok())
                .collect();
            Some(xs)
        })
        .collect()
}

/// A swept time key's axis and a second key's legend say their units.
#[test]
fn a_swept_time_is_labelled_in_its_unit() {
    let keys = [
        "network.forward.delay_ms=0,50,100",
        "network.backward.delay=[0,0,0],[5,5,5]",
    ];
    let (dir, _) = plots(&keys, |c| Some(1.0 + c[0] as f64));
    let texts = svg::texts(&read(&dir, "samples_sent"));
    for want in [
        "network.forward.delay_ms (ms)",
        "network.backward.delay=[5,5,5] samples",
    ] {
        assert!(texts.iter().any(|t| t == want), "{want} not in {texts:?}");
    }
}

/// The y axis says the metric in words and its unit, the values scaled to it: a
/// position RMS of 0.002 m reads 2 mm.
#[test]
fn the_metric_is_said_in_words_and_its_unit() {
    let (dir, _) = plots(&["network.forward.delay_ms=0,50"], |c| {
        Some(0.002 * (1 + c[0]) as f64)
    });
    let texts = svg::texts(&read(&dir, "position_rms_m"));
    assert!(
        texts.iter().any(|t| t == "RMS position error (mm)"),
        "{texts:?}"
    );
    assert!(texts.iter().any(|t| t == "2.0" || t == "2"), "{texts:?}");
    assert!(!texts.iter().any(|t| t == "0.002"), "{texts:?}");
}

/// Three controls with the same value at every delay: each line is drawn in its
/// own colour, the first widest and solid, the later narrower and dashed, each
/// with its own marker, so none hides another.
#[test]
fn lines_that_coincide_all_show() {
    let keys = [
        "network.forward.delay=[0,0,0],[10,10,10],[50,50,50]",
        "control.kind=none,tdpa,wave",
    ];
    let (dir, _) = plots(&keys, |c| Some(1.0 + c[0] as f64));
    let text = read(&dir, "samples_sent");
    let lines = svg::polylines(&text);
    let widths: Vec<u32> = (0..3)
        .map(|k| {
            let (_, w) = &lines[&hex(k, 3)];
            assert_eq!(w.len(), 1, "series {k}: {w:?}");
            w[0].parse().expect("width")
        })
        .collect();
    assert!(widths[0] > widths[1] && widths[1] > widths[2], "{widths:?}");
    // Dashed: a dash per polyline, many more than the solid line's one (and its
    // legend's).
    assert!(lines[&hex(0, 3)].0 <= 2, "{:?}", lines[&hex(0, 3)]);
    assert!(
        lines[&hex(1, 3)].0 > 4 && lines[&hex(2, 3)].0 > 4,
        "{lines:?}"
    );
    let shapes: Vec<Vec<&str>> = (0..3).map(|k| svg::shapes(&text, &hex(k, 3))).collect();
    assert_eq!(shapes, [vec!["circle"], vec!["polygon"], vec!["rect"]]);
}

/// A metric no run has a value of gets no figure (and an older one is removed); a
/// line without values is named so in the legend.
#[test]
fn no_plot_for_a_metric_without_values() {
    let keys = ["network.forward.delay_ms=0,50", "control.kind=none,mmt"];
    let axes: Vec<Axis> = keys.iter().map(|k| axis(k).expect("axis")).collect();
    let ratio = METRICS
        .iter()
        .position(|(n, _)| *n == "stiffness_ratio")
        .expect("metric");
    let points: Vec<Point> = combinations(&axes)
        .into_iter()
        .map(|c| {
            let mut v = vec![(None, None); METRICS.len()];
            v[0] = (Some(1.0), None);
            // Only mmt's runs have a ratio.
            if c[1] == 1 {
                v[ratio] = (Some(0.9), None);
            }
            (c, v)
        })
        .collect();
    let dir = tempfile::tempdir().expect("tmp");
    let stale = dir.path().join("sweep-force_rms_n.svg");
    std::fs::write(&stale, "<svg/>").expect("old plot");
    let files = sweep_plots(dir.path(), &axes, &points).expect("plots");
    assert_eq!(
        files,
        ["sweep-samples_sent.svg", "sweep-stiffness_ratio.svg"]
    );
    let on_disk = std::fs::read_dir(dir.path()).expect("dir").count();
    assert_eq!(on_disk, 2, "the stale plot is removed");
    let texts = svg::texts(&read(&dir, "stiffness_ratio"));
    assert!(
        texts.iter().any(|t| t == "control.kind=none (no values)"),
        "{texts:?}"
    );
    assert!(texts.iter().any(|t| t == "control.kind=mmt"), "{texts:?}");
}

/// A word swept on the x axis: its ticks are the words, at their categories and
/// nowhere between, and no line joins them; two lines' markers stand side by side.
#[test]
fn words_on_the_x_axis_are_categories() {
    let keys = ["control.kind=none,tdpa,wave,mmt", "seed=1,2"];
    let (dir, _) = plots(&keys, |c| Some([1.5, 3.3, 2.4, 0.1][c[0]]));
    let text = read(&dir, "felt_step_max_n");
    let texts = svg::texts(&text);
    let ticks: Vec<&String> = texts
        .iter()
        .filter(|t| ["none", "tdpa", "wave", "mmt"].contains(&t.as_str()))
        .collect();
    assert_eq!(ticks, ["none", "tdpa", "wave", "mmt"]);
    // Nothing else on the x axis's row of ticks (the old plot labelled 0, 0.5, 1,
    // ..., 3.5 there, and the words only in the axis's title).
    let row = svg::placed(&text)
        .into_iter()
        .find(|t| t.0 == "none")
        .expect("tick")
        .2;
    let on_row: Vec<String> = svg::placed(&text)
        .into_iter()
        .filter(|t| t.2 == row)
        .map(|t| t.0)
        .collect();
    assert_eq!(on_row, ["none", "tdpa", "wave", "mmt"]);
    for k in 0..2 {
        let lines = polyline_xs(&text, &hex(k, 2));
        assert!(
            lines.is_empty(),
            "no line through the categories: {lines:?}"
        );
    }
    assert_eq!(svg::shapes(&text, &hex(0, 2)), ["circle"]);
    assert_eq!(svg::shapes(&text, &hex(1, 2)), ["polygon"]);
}

/// Three keys: a panel per value of the third, in each one line per value of the
/// second, each line's points in the order of the x axis, whatever the order swept;
/// a key of one value is a setting under the title, not a line.
#[test]
fn a_third_key_is_a_panel_of_its_own() {
    let keys = [
        "operator.move_s=16,1,4",
        "network.forward.delay_ms=0,100",
        "control.kind=tdpa,wave,mmt",
        "samples=24000",
    ];
    let (dir, _) = plots(&keys, |c| Some((c[0] * 100 + c[1] * 10 + c[2]) as f64));
    let text = read(&dir, "position_rms_m");
    let texts = svg::texts(&text);
    for want in [
        "control.kind=tdpa",
        "control.kind=wave",
        "control.kind=mmt",
        "network.forward.delay_ms=0 ms",
        "network.forward.delay_ms=100 ms",
        "samples=24000",
        "RMS position error against operator.move_s",
    ] {
        assert_eq!(
            texts.iter().filter(|t| *t == want).count(),
            1,
            "{want} once in {texts:?}"
        );
    }
    // The solid line: one polyline per panel and one in the legend, each panel's
    // running from left to right through its three runs.
    let lines = polyline_xs(&text, &hex(0, 2));
    assert_eq!(lines.len(), 3 + 1, "{lines:?}");
    for xs in &lines[..3] {
        assert_eq!(xs.len(), 3);
        assert!(xs.windows(2).all(|w| w[0] < w[1]), "{xs:?}");
    }
}

/// With seeds, each mean has its 95 % interval as a bar that leaves the line's own
/// marker alone (no ring around it), and the title's line says what the bars are.
#[test]
fn error_bars_leave_the_markers_as_they_are() {
    let keys = ["network.forward.delay_ms=0,50", "control.kind=tdpa,wave"];
    let axes: Vec<Axis> = keys.iter().map(|k| axis(k).expect("axis")).collect();
    let points: Vec<Point> = combinations(&axes)
        .into_iter()
        .map(|c| (c, vec![(Some(1.0), Some(0.25)); METRICS.len()]))
        .collect();
    let dir = tempfile::tempdir().expect("tmp");
    sweep_plots(dir.path(), &axes, &points).expect("plots");
    let text = read(&dir, "samples_sent");
    assert_eq!(svg::shapes(&text, &hex(0, 2)), ["circle"]);
    assert_eq!(svg::shapes(&text, &hex(1, 2)), ["polygon"]);
    let texts = svg::texts(&text);
    let note = "error bars: 95 % confidence interval of the mean over the seeds";
    assert!(texts.iter().any(|t| t == note), "{texts:?}");
}
