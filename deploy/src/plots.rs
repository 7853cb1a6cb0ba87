//! SVG plots of a run: the overhead histogram, master and slave positions over time,
//! and forces over time. Written with plotters' SVG backend, which needs no system
//! library or font file.

use plotters::prelude::*;
use std::path::Path;
use tactile_common::trace::TraceRow;

type PlotResult = Result<(), String>;

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

const AXES: [&str; 3] = ["x", "y", "z"];
const COLOURS: [RGBColor; 3] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];

/// Histogram of the system overhead per round trip, in microseconds.
pub fn overhead_histogram(rows: &[TraceRow], path: &Path) -> PlotResult {
    let us: Vec<f64> = rows
        .iter()
        .filter(|r| r.backward.is_some())
        .map(|r| r.overhead_ns.max(0) as f64 / 1000.0)
        .collect();
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    if us.is_empty() {
        return root.present().map_err(err);
    }
    let mut sorted = us.clone();
    sorted.sort_by(f64::total_cmp);
    // Cut the axis at 1.5 x p99 so the body of the distribution stays visible; the
    // tail goes into the last bin (and is in the percentiles and the .hgrm file).
    let hi = sorted[((sorted.len() - 1) as f64 * 0.99) as usize].max(1.0) * 1.5;
    let bins = 100usize;
    let width = hi / bins as f64;
    let mut counts = vec![0u64; bins];
    for v in &us {
        let k = ((v / width) as usize).min(bins - 1);
        counts[k] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(1) as f64 * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "System overhead per round trip (round trip - injected delay)",
            ("sans-serif", 20),
        )
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..hi, 0.0..top)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("overhead (us); the last bin holds everything above 1.5 x p99")
        .y_desc("samples")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(counts.iter().enumerate().map(|(k, c)| {
            let x0 = k as f64 * width;
            Rectangle::new([(x0, 0.0), (x0 + width, *c as f64)], COLOURS[0].filled())
        }))
        .map_err(err)?;
    root.present().map_err(err)
}

fn time_series(
    path: &Path,
    title: &str,
    y_desc: &str,
    t: &[f64],
    series: &[(String, RGBColor, bool, Vec<f64>)],
) -> PlotResult {
    let root = SVGBackend::new(path, (1000, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, _, _, v) in series {
        for x in v.iter().filter(|x| x.is_finite()) {
            lo = lo.min(*x);
            hi = hi.max(*x);
        }
    }
    if !lo.is_finite() || t.is_empty() {
        return root.present().map_err(err);
    }
    let pad = ((hi - lo) * 0.05).max(1e-6);
    let t_end = t.last().copied().unwrap_or(1.0).max(1e-3);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(y_desc)
        .draw()
        .map_err(err)?;
    for (label, colour, dashed, v) in series {
        // Dashed series (the reference: target, felt force) are drawn lighter and
        // thinner, so they read apart from the solid ones in the legend too.
        let style = if *dashed {
            ShapeStyle::from(colour.mix(0.55)).stroke_width(1)
        } else {
            ShapeStyle::from(colour).stroke_width(2)
        };
        let points = t.iter().copied().zip(v.iter().copied());
        let legend = move |(x, y): (i32, i32)| PathElement::new(vec![(x, y), (x + 20, y)], style);
        let drawn = if *dashed {
            chart.draw_series(DashedLineSeries::new(points, 6, 4, style))
        } else {
            chart.draw_series(LineSeries::new(points, style))
        };
        drawn.map_err(err)?.label(label.as_str()).legend(legend);
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)
}

/// Operator target (dashed) and slave tool (solid) per axis over time.
pub fn positions(rows: &[TraceRow], t_s: f64, path: &Path) -> PlotResult {
    let t: Vec<f64> = rows.iter().map(|r| r.n as f64 * t_s).collect();
    let mut series = Vec::new();
    for i in 0..3 {
        series.push((
            format!("{} operator target", AXES[i]),
            COLOURS[i],
            true,
            rows.iter().map(|r| r.target[i]).collect(),
        ));
        series.push((
            format!("{} slave tool", AXES[i]),
            COLOURS[i],
            false,
            rows.iter()
                .map(|r| r.backward.map_or(f64::NAN, |b| b.slave.tool[i]))
                .collect(),
        ));
    }
    time_series(
        path,
        "Master target and slave tool position",
        "position (m)",
        &t,
        &series,
    )
}

/// Contact force at the slave (solid) and force felt at the master (dashed).
pub fn forces(rows: &[TraceRow], t_s: f64, path: &Path) -> PlotResult {
    let t: Vec<f64> = rows.iter().map(|r| r.n as f64 * t_s).collect();
    let mut series = Vec::new();
    for i in 0..3 {
        series.push((
            format!("F{} slave h(n)", AXES[i]),
            COLOURS[i],
            false,
            rows.iter()
                .map(|r| r.backward.map_or(f64::NAN, |b| b.slave.force[i]))
                .collect(),
        ));
        series.push((
            format!("F{} felt q(n)", AXES[i]),
            COLOURS[i],
            true,
            rows.iter().map(|r| r.felt[i]).collect(),
        ));
    }
    time_series(
        path,
        "Contact force (slave) and feedback force (master)",
        "force (N)",
        &t,
        &series,
    )
}
