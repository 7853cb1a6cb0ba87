//! The time-series plots of a run (positions, forces, passivity): lines over time with
//! their legend in a strip below the plot area, where it can cover no data (a legend
//! inside the area sat on the lines in some runs, and no corner is free in all of
//! them).

use super::{err, Line, PlotResult, WIDTH};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Height of the plot above the legend, pixels.
const PLOT_HEIGHT: u32 = 560;
/// Height of one row of the legend, pixels.
const ROW: i32 = 22;
/// Left edge of the plot area: the chart's margin and its y label area.
const LEFT: i32 = 10 + 70;

/// A tick label as plotters writes it, except that a tick at zero never reads "-0.0":
/// the ticks are sums of steps, and the one at zero can come out a hair below it.
pub(crate) fn tick(v: &f64) -> String {
    let s = RangedCoordf64::format(v);
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// How a line is drawn. Where a plot pairs references (the master handle, the felt
/// force) with measured lines (the slave tool, h(n)), a reference is a thin line in the
/// full colour drawn over its measured line, a wider band in a lighter tint of the same
/// colour: where the two coincide, as they do most of a run, the reference still shows
/// as the band's dark core (a light, thin reference under the measured line could not
/// be read). Lines of a plot without pairs are plain. Not dashed: a thinned series
/// zig-zags between each bucket's extremes, and dashing that path would write
/// thousands of dashes.
fn style(colour: RGBColor, reference: bool, paired: bool) -> ShapeStyle {
    match (reference, paired) {
        (true, _) => ShapeStyle::from(colour).stroke_width(2),
        (false, true) => ShapeStyle::from(colour.mix(0.4)).stroke_width(6),
        (false, false) => ShapeStyle::from(colour).stroke_width(2),
    }
}

/// The shade of the stretches a plot marks (the operator's clutch released).
const SHADE: RGBColor = RGBColor(150, 150, 150);

/// Lines of (t, y) points on linear axes from 0 to the last time, with a legend below;
/// the stretches `shade` (from, to, s) marked with a grey band and a legend entry
/// `shade_label`.
pub(crate) fn time_series(
    path: &Path,
    (title, y_desc): (&str, &str),
    series: &[Line],
    (shade, shade_label): (&[(f64, f64)], &str),
) -> PlotResult {
    let mut series = series.to_vec();
    if !shade.is_empty() {
        series.push((shade_label.to_string(), SHADE, false, Vec::new()));
    }
    let series = &series[..];
    let rows = if series.len() <= 3 { 1 } else { 2 };
    let strip = (rows * ROW + 16) as u32;
    let root = SVGBackend::new(path, (WIDTH, PLOT_HEIGHT + strip)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (mut lo, mut hi, mut t_end) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for (_, _, _, v) in series {
        for (t, x) in v {
            lo = lo.min(*x);
            hi = hi.max(*x);
            t_end = t_end.max(*t);
        }
    }
    if !lo.is_finite() {
        return root.present().map_err(err);
    }
    let pad = ((hi - lo) * 0.05).max(1e-6);
    let t_end = t_end.max(1e-3);
    let (top, bottom) = root.split_vertically(PLOT_HEIGHT);
    let mut chart = ChartBuilder::on(&top)
        .caption(title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(LEFT - 10)
        .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(y_desc)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()
        .map_err(err)?;
    chart
        .draw_series(shade.iter().map(|(a, b)| {
            Rectangle::new([(*a, lo - pad), (*b, hi + pad)], SHADE.mix(0.25).filled())
        }))
        .map_err(err)?;
    let paired = series.iter().any(|s| s.2);
    // Measured lines first, references over them.
    for pass in [false, true] {
        for (_, colour, reference, v) in series.iter().filter(|s| s.2 == pass) {
            chart
                .draw_series(LineSeries::new(
                    v.iter().copied(),
                    style(*colour, *reference, paired),
                ))
                .map_err(err)?;
        }
    }
    legend(&bottom, series, rows, paired)?;
    root.present().map_err(err)
}

/// The legend in `area`, under the plot area: column-major in `rows` rows, so the
/// lines of one axis (a reference above its measured line) share a column.
fn legend(
    area: &DrawingArea<SVGBackend, Shift>,
    series: &[Line],
    rows: i32,
    paired: bool,
) -> PlotResult {
    let cols = (series.len() as i32 + rows - 1) / rows;
    let width = (WIDTH as i32 - LEFT - 10) / cols.max(1);
    let font = ("sans-serif", 14)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (k, (label, colour, reference, _)) in series.iter().enumerate() {
        let k = k as i32;
        let (x, y) = (LEFT + (k / rows) * width, 8 + (k % rows) * ROW + ROW / 2);
        area.draw(&PathElement::new(
            vec![(x, y), (x + 30, y)],
            style(*colour, *reference, paired),
        ))
        .map_err(err)?;
        area.draw(&Text::new(label.clone(), (x + 38, y), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tick_at_zero_never_reads_negative() {
        for zero in [-0.0, -1e-17, 0.0] {
            assert_eq!(tick(&zero), "0.0", "{zero:e}");
        }
        assert_eq!(tick(&-0.02), "-0.02");
        assert_eq!(tick(&-500.0), "-500.0");
        assert_eq!(tick(&2.5), "2.5");
    }

    /// The (x, y) of the `<text>` element whose content is `label`.
    fn text_at(svg: &str, label: &str) -> (i32, i32) {
        let at = svg.find(&format!(">\n{label}\n</text>")).expect(label);
        let open = svg[..at].rfind("<text").expect("<text");
        let attr = |name: &str| {
            svg[open..at]
                .split(&format!(" {name}=\""))
                .nth(1)
                .and_then(|s| s.split('"').next())
                .and_then(|s| s.parse().ok())
                .expect(name)
        };
        (attr("x"), attr("y"))
    }

    #[test]
    fn the_legend_lies_below_the_plot_area_an_axis_to_a_column() {
        let dir = tempfile::tempdir().expect("tmp");
        let path = dir.path().join("t.svg");
        let line = |name: &str, reference: bool| {
            let pts = (0..100)
                .map(|k| (k as f64, (k as f64 * 0.1).sin()))
                .collect();
            (name.to_string(), RGBColor(0, 0, 0), reference, pts)
        };
        let lines = [
            line("x ref", true),
            line("x measured", false),
            line("y ref", true),
            line("y measured", false),
        ];
        time_series(&path, ("title", "y"), &lines, (&[], "")).expect("plot");
        let svg = std::fs::read_to_string(&path).expect("svg");
        for (label, ..) in &lines {
            let (_, y) = text_at(&svg, label);
            assert!(y > PLOT_HEIGHT as i32, "{label} at y = {y}");
        }
        let (a, b) = (text_at(&svg, "x ref"), text_at(&svg, "x measured"));
        assert!(a.0 == b.0 && a.1 < b.1, "{a:?} {b:?}");
        assert!(text_at(&svg, "y ref").0 > a.0);
        assert!(!svg.contains("\n-0.0\n"), "a tick reads -0.0");
    }
}
