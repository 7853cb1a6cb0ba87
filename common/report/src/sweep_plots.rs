//! `sweep-METRIC.svg`: each metric of a sweep against the first swept key, one line
//! per value of the second, a marker at every run, and with `--seeds` the 95 %
//! confidence interval as an error bar. Vector values (`[25,25,25]`) sit at their
//! elements' mean on a numeric axis; words at their positions 0, 1, 2, ... Where two
//! lines coincide (controls that agree at a point), both show: each line has its own
//! colour, dash and marker, the first drawn widest (`plots::looks`).

use crate::plots::{draw_legend, draw_line, draw_markers, look, tick};
use crate::sweep::{labelled, numeric, unit, Axis, FAILED, METRICS};
use plotters::prelude::*;
use std::path::Path;

/// One combination's values: its value index on each axis, and per metric the mean
/// and (with seeds) the interval's half width.
pub type Point = (Vec<usize>, Vec<(Option<f64>, Option<f64>)>);

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// Writes `sweep-METRIC.svg` for every metric into `out`.
pub fn sweep_plots(out: &Path, axes: &[Axis], points: &[Point]) -> Result<(), String> {
    let Some(first) = axes.first() else {
        return Ok(());
    };
    let nums: Option<Vec<f64>> = first.values.iter().map(|v| numeric(v)).collect();
    let x_of = |i: usize| nums.as_ref().map_or(i as f64, |n| n[i]);
    // The axis says the unit of a time key (samples or ms, ten times apart at 100 Hz).
    let x_desc = if nums.is_some() {
        labelled(&first.key)
    } else {
        format!("{} (0: {})", labelled(&first.key), first.values.join(", "))
    };
    let lines = axes.get(1).map_or(1, |a| a.values.len());
    for (m, (name, _)) in METRICS.iter().enumerate() {
        if *name == FAILED {
            continue;
        }
        let mut series = Vec::new();
        for line in 0..lines {
            let mut pts: Vec<(f64, f64, f64)> = points
                .iter()
                .filter(|(c, _)| c.get(1).is_none_or(|&l| l == line))
                .filter_map(|(c, v)| {
                    let (mean, ci) = v[m];
                    mean.map(|y| (x_of(c[0]), y, ci.unwrap_or(0.0)))
                })
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let label = axes.get(1).map_or_else(
                || name.to_string(),
                |a| {
                    let unit = unit(&a.key).map_or_else(String::new, |u| format!(" {u}"));
                    format!("{}={}{unit}", a.key, a.values[line])
                },
            );
            series.push((label, pts));
        }
        crate::plots::whole_svg(&out.join(format!("sweep-{name}.svg")), |p| {
            plot(p, name, &first.key, &x_desc, &series)
        })?;
    }
    Ok(())
}

/// A line's label and its points: x, the mean, the interval's half width.
type Series = (String, Vec<(f64, f64, f64)>);

/// The ranges the points and their error bars span, padded.
fn ranges(series: &[Series]) -> Option<((f64, f64), (f64, f64))> {
    let all = series.iter().flat_map(|s| s.1.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y, e) in all {
        (x0, x1) = (x0.min(x), x1.max(x));
        (y0, y1) = (y0.min(y - e), y1.max(y + e));
    }
    if !x0.is_finite() || !y0.is_finite() {
        return None;
    }
    let px = ((x1 - x0) * 0.05).max(0.5);
    let py = ((y1 - y0) * 0.08).max(y1.abs().max(1e-9) * 0.05);
    // Headroom above the data for the legend (upper right), so it covers no point.
    let legend = (y1 - y0 + 2.0 * py) * 0.03 * (series.len() as f64 + 1.0);
    Some(((x0 - px, x1 + px), (y0 - py, y1 + py + legend)))
}

fn plot(path: &Path, name: &str, key: &str, x_desc: &str, series: &[Series]) -> Result<(), String> {
    let root = SVGBackend::new(path, (crate::plots::WIDTH, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let Some(((x0, x1), (y0, y1))) = ranges(series) else {
        return root.present().map_err(err);
    };
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{name} against {key}"), ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(name)
        .y_label_formatter(&tick)
        .x_label_formatter(&tick)
        .draw()
        .map_err(err)?;
    for (k, (label, pts)) in series.iter().enumerate() {
        let look = look(k, series.len());
        let line: Vec<(f64, f64)> = pts.iter().map(|p| (p.0, p.1)).collect();
        draw_line(&mut chart, line.clone(), &look, label)?;
        draw_markers(&mut chart, &line, &look)?;
        let style = look.style();
        chart
            .draw_series(
                pts.iter()
                    .filter(|p| p.2 > 0.0)
                    .map(|p| ErrorBar::new_vertical(p.0, p.1 - p.2, p.1, p.1 + p.2, style, 8)),
            )
            .map_err(err)?;
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 0.85)?;
    root.present().map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plots::looks::svg;
    use crate::sweep::axis;

    /// The plot of `samples_sent` over the axes `a` and `b` (`KEY=V1,V2,...`), every
    /// metric 1 + the first axis's index (the same for every value of the second: its
    /// lines coincide).
    fn samples_sent(a: &str, b: &str) -> String {
        let axes = &[axis(a).expect("a"), axis(b).expect("b")];
        let points: Vec<Point> = crate::sweep::combinations(axes)
            .into_iter()
            .map(|c| {
                let y = 1.0 + c[0] as f64;
                (c, vec![(Some(y), None); METRICS.len()])
            })
            .collect();
        let dir = tempfile::tempdir().expect("tmp");
        sweep_plots(dir.path(), axes, &points).expect("plots");
        std::fs::read_to_string(dir.path().join("sweep-samples_sent.svg")).expect("svg")
    }

    /// A swept time key's axis and a second key's legend say their units.
    #[test]
    fn a_swept_time_is_labelled_in_its_unit() {
        let text = samples_sent(
            "network.forward.delay_ms=0,50,100",
            "network.backward.delay=[0,0,0],[5,5,5]",
        );
        // plotters writes each text on a line of its own.
        for want in [
            "network.forward.delay_ms (ms)",
            "network.backward.delay=[5,5,5] samples",
        ] {
            assert!(
                text.lines().any(|l| l.trim() == want),
                "{want} not in the plot"
            );
        }
    }

    /// Three controls with the same value at every delay: each line is drawn in its
    /// own colour, the first widest and solid, the later narrower and dashed, each
    /// with its own marker, so none hides another.
    #[test]
    fn lines_that_coincide_all_show() {
        let text = samples_sent(
            "network.forward.delay=[0,0,0],[10,10,10],[50,50,50]",
            "control.kind=none,tdpa,wave",
        );
        let lines = svg::polylines(&text);
        let hex = |k: usize| {
            let c = look(k, 3).colour;
            format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
        };
        let widths: Vec<u32> = (0..3)
            .map(|k| {
                let (_, w) = &lines[&hex(k)];
                assert_eq!(w.len(), 1, "series {k}: {w:?}");
                w[0].parse().expect("width")
            })
            .collect();
        assert!(widths[0] > widths[1] && widths[1] > widths[2], "{widths:?}");
        // Dashed: a dash per polyline, many more than the solid line's one (and its
        // legend's).
        assert!(lines[&hex(0)].0 <= 2, "{:?}", lines[&hex(0)]);
        assert!(lines[&hex(1)].0 > 4 && lines[&hex(2)].0 > 4, "{lines:?}");
        let shapes: Vec<Vec<&str>> = (0..3).map(|k| svg::shapes(&text, &hex(k))).collect();
        assert_eq!(shapes, [vec!["circle"], vec!["polygon"], vec!["rect"]]);
    }
}
