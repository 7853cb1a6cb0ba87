//! `percentiles.svg`: latency against percentile, one line per distribution. The
//! ticks are chosen here, not by plotters: its log axes put the next decade's tick
//! twice (as the last of a decade's 2..9 and as the next decade), which printed
//! `100.0` twice on the latency axis; and a percentile is printed with as many
//! decimals as its decade needs, so 99.9999 % never rounds to a second `100%`.

use super::{draw_legend, draw_line, err, look, tick, PlotResult};
use plotters::prelude::*;
use std::path::Path;

/// The percentile plot's axes: the largest 1/(1-p), rounded up to a decade (the last
/// point, p = 1, has no finite one: it is drawn there), and the latency range with
/// headroom; None without a point.
fn percentile_extent(series: &[(String, Vec<(f64, f64)>)]) -> Option<(f64, f64, f64)> {
    let mut x_max = 10.0f64;
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for (_, pts) in series {
        for &(q, v) in pts {
            if q < 1.0 {
                x_max = x_max.max(1.0 / (1.0 - q));
            }
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if !lo.is_finite() {
        return None;
    }
    let x_max = 10f64.powf(x_max.log10().ceil());
    Some((
        x_max,
        (lo * 0.8).max(0.01),
        (hi * 1.25).max(lo * 10.0).max(0.1),
    ))
}

/// The percentile axis's ticks: every decade of 1/(1-p) up to `x_max` (0 %, 90 %,
/// 99 %, ...).
fn percentile_ticks(x_max: f64) -> Vec<f64> {
    let decades = x_max.log10().round().clamp(0.0, 15.0) as i32;
    (0..=decades).map(|d| 10f64.powi(d)).collect()
}

/// A percentile tick's label: `1/(1-p)` = 10^d is 100 - 10^(2-d) %, printed with the
/// d - 2 decimals it has.
fn percentile_label(x: f64) -> String {
    let d = x.log10().round().max(0.0) as usize;
    format!("{:.*}%", d.saturating_sub(2), 100.0 - 100.0 / x)
}

/// The latency axis's ticks: 1, 2 and 5 of every decade within `lo..=hi`, or the
/// decades alone when they are more than 5.
fn latency_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let steps: &[f64] = if last - first > 5 {
        &[1.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    (first..=last)
        .flat_map(|d| steps.iter().map(move |m| m * 10f64.powi(d)))
        .filter(|v| (lo..=hi).contains(v))
        .collect()
}

/// Latency against percentile as the field draws it (HdrHistogram's plotter): the
/// percentile on a log axis of 1/(1 - p), so 90 %, 99 %, 99.9 % and 99.99 % are evenly
/// spaced and the tail is as visible as the body; one line per distribution, each
/// from its `.hgrm` text; latency on a log axis too, since body and tail lie decades
/// apart. Lines that coincide (in-process, the round trip is all overhead) all show:
/// see `looks`.
pub fn percentile_plot(
    path: &Path,
    title: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> PlotResult {
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let Some((x_max, lo, hi)) = percentile_extent(series) else {
        return root.present().map_err(err);
    };
    // The right margin holds the half of the last tick label ("99.99%") that lies
    // past the axis's end.
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(10)
        .margin_right(40)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (1.0..x_max)
                .log_scale()
                .with_key_points(percentile_ticks(x_max)),
            (lo..hi).log_scale().with_key_points(latency_ticks(lo, hi)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("percentile")
        .y_desc("latency (us)")
        .x_label_formatter(&|x| percentile_label(*x))
        .y_label_formatter(&tick)
        .draw()
        .map_err(err)?;
    for (k, (label, pts)) in series.iter().enumerate() {
        let line: Vec<(f64, f64)> = pts
            .iter()
            .map(|&(q, v)| (if q < 1.0 { 1.0 / (1.0 - q) } else { x_max }.min(x_max), v))
            .collect();
        draw_line(&mut chart, line, &look(k, series.len()), label)?;
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, 0.8)?;
    root.present().map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_unique_and_percentiles_exact() {
        let xs = percentile_ticks(1e7);
        let labels: Vec<String> = xs.iter().map(|&x| percentile_label(x)).collect();
        assert_eq!(
            labels,
            [
                "0%",
                "90%",
                "99%",
                "99.9%",
                "99.99%",
                "99.999%",
                "99.9999%",
                "99.99999%"
            ]
        );
        assert_eq!(
            latency_ticks(0.8, 125.0),
            [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        );
        assert_eq!(latency_ticks(0.01, 1e6).len(), 9);
    }

    /// Two distributions that coincide (a round trip that is all overhead), one going
    /// out to 99.99999 %: every tick label once, and both lines drawn apart, the first
    /// wider and solid, the second narrower and dashed over it.
    #[test]
    fn coinciding_lines_both_show_and_no_tick_repeats() {
        let pts: Vec<(f64, f64)> = (0..=70)
            .map(|k| (1.0 - 10f64.powf(-f64::from(k) / 10.0), 1.0 + f64::from(k)))
            .chain([(1.0, 80.0)])
            .collect();
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join("p.svg");
        let series = [("round trip".into(), pts.clone()), ("overhead".into(), pts)];
        percentile_plot(&path, "t", &series).expect("plot");
        let text = std::fs::read_to_string(&path).expect("svg");
        let ticks: Vec<String> = crate::plots::looks::svg::texts(&text)
            .into_iter()
            .filter(|t| t.trim_end_matches('%').parse::<f64>().is_ok())
            .collect();
        assert!(ticks.iter().any(|t| t == "99.99999%"), "{ticks:?}");
        let mut unique = ticks.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), ticks.len(), "a tick label twice: {ticks:?}");
        let lines = crate::plots::looks::svg::polylines(&text);
        let (a, b) = (look(0, 2), look(1, 2));
        let hex = |c: RGBColor| format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
        let (first, second) = (&lines[&hex(a.colour)], &lines[&hex(b.colour)]);
        assert_eq!(first.1, ["3"], "the first drawn is the wider");
        assert_eq!(second.1, ["2"]);
        assert!(
            second.0 > 10 * first.0,
            "the second is dashed: {second:?} {first:?}"
        );
    }
}
