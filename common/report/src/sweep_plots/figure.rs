//! Draws a sweep's [`Figure`]: the title and the settings over a grid of panels that
//! share their y range (so panels compare at a glance), the legend in a strip below.
//! Fonts are sized for a figure printed a column wide: ticks 15 px, axis titles 16 px,
//! the title 22 px on a 1000 px wide figure.

use super::keys::{decimals, fixed, number, Scale};
use super::{Figure, Panel};
use crate::plots::looks::{marker, text_w, Look};
use crate::plots::ticked::Ticked;
use crate::plots::{draw_line, look, WIDTH};
use plotters::coord::ranged1d::{BoldPoints, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

use crate::plots::{err, PlotResult};

/// Tick labels, axis titles, panel titles, the figure's title, px.
const TICK: u32 = 15;
const DESC: u32 = 16;
const PANEL: u32 = 17;
const TITLE: u32 = 22;
/// A legend row's height, px.
const ROW: i32 = 26;
/// Columns and height of the panels' grid.
fn grid(n: usize) -> (usize, u32) {
    match n {
        0 | 1 => (1, 500),
        2..=4 => (2, 380),
        _ => (3, 320),
    }
}

/// The legend's entries per row.
fn per_row(labels: &[String]) -> usize {
    let widest = labels.iter().map(|l| text_w(l, TICK)).max().unwrap_or(0) + 70;
    ((WIDTH as i32 - 40) / widest).max(1) as usize
}

/// Draws `fig` into `path`.
pub(super) fn draw(path: &Path, fig: &Figure) -> PlotResult {
    let (cols, panel_h) = grid(fig.panels.len());
    let rows = fig.panels.len().div_ceil(cols);
    let header = if fig.subtitle.is_empty() { 40 } else { 64 };
    let legend_rows = fig.legend.len().div_ceil(per_row(&fig.legend));
    let legend_h = if legend_rows == 0 {
        0
    } else {
        legend_rows as u32 * ROW as u32 + 16
    };
    let height = header + rows as u32 * panel_h + legend_h;
    let root = SVGBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let centre = Pos::new(HPos::Center, VPos::Center);
    let font = |size: u32| ("sans-serif", size).into_font().color(&BLACK).pos(centre);
    let mid = WIDTH as i32 / 2;
    root.draw(&Text::new(fig.title.clone(), (mid, 20), font(TITLE)))
        .map_err(err)?;
    if !fig.subtitle.is_empty() {
        root.draw(&Text::new(fig.subtitle.clone(), (mid, 46), font(TICK)))
            .map_err(err)?;
    }
    let (_, body) = root.split_vertically(header);
    let (panels, strip) = body.split_vertically(rows as u32 * panel_h);
    let y = y_range(&fig.panels);
    for (area, p) in panels.split_evenly((rows, cols)).iter().zip(&fig.panels) {
        panel(area, fig, p, y)?;
    }
    legend(&strip, fig)?;
    root.present().map_err(err)
}

/// The y range every panel shares: the points and their intervals, padded; a flat
/// metric gets a range around its value.
fn y_range(panels: &[Panel]) -> (f64, f64) {
    let pts = panels.iter().flat_map(|p| p.lines.iter().flatten());
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(_, y, e) in pts {
        (lo, hi) = (lo.min(y - e), hi.max(y + e));
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let pad = if hi > lo {
        (hi - lo) * 0.08
    } else if hi != 0.0 {
        hi.abs() * 0.1
    } else {
        1.0
    };
    (lo - pad, hi + pad)
}

/// The x range and its ticks with their labels.
fn x_axis(scale: &Scale, plot_w: i32) -> ((f64, f64), Vec<(f64, String)>) {
    match scale {
        Scale::Categories(words) => {
            let n = words.len() as f64;
            let ticks = words.iter().enumerate();
            (
                (-0.5, n - 0.5),
                ticks.map(|(i, w)| (i as f64, w.clone())).collect(),
            )
        }
        Scale::Numbers(v) => {
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                    (a.min(*x), b.max(*x))
                });
            let pad = if hi > lo { (hi - lo) * 0.05 } else { 0.5 };
            let range = (lo - pad, hi + pad);
            let mut at: Vec<f64> = v.clone();
            at.sort_by(f64::total_cmp);
            let swept: Vec<(f64, String)> = at.iter().map(|&x| (x, number(x))).collect();
            // The swept values are the ticks where their labels fit apart.
            let px = |d: f64| d / (range.1 - range.0) * plot_w as f64;
            let fit = swept.windows(2).all(|w| {
                let need = (text_w(&w[0].1, TICK) + text_w(&w[1].1, TICK)) / 2 + 10;
                px(w[1].0 - w[0].0) >= need as f64
            });
            if fit {
                (range, swept)
            } else {
                (range, nice(range))
            }
        }
    }
}

/// About eight round ticks over `range`, each labelled with the decimals they need.
fn nice(range: (f64, f64)) -> Vec<(f64, String)> {
    let at = RangedCoordf64::from(range.0..range.1).key_points(BoldPoints(8));
    let d = decimals(&at);
    at.iter().map(|&x| (x, fixed(x, d))).collect()
}

/// Draws one panel: its title, axes, and every line's markers (and, on a numeric
/// axis, the line through them) with their error bars.
fn panel(area: &Area, fig: &Figure, p: &Panel, (y0, y1): (f64, f64)) -> PlotResult {
    let yt = nice((y0, y1));
    let y_area = yt.iter().map(|t| text_w(&t.1, TICK)).max().unwrap_or(0) + 46;
    let (w, _) = area.dim_in_pixel();
    let ((x0, x1), xt) = x_axis(&fig.x, w as i32 - y_area - 30);
    let (xs, ys): (Vec<f64>, Vec<f64>) = (
        xt.iter().map(|t| t.0).collect(),
        yt.iter().map(|t| t.0).collect(),
    );
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(10)
        .margin_right(20)
        .x_label_area_size(52)
        .y_label_area_size(y_area);
    if !p.title.is_empty() {
        builder.caption(&p.title, ("sans-serif", PANEL));
    }
    let mut chart = builder
        .build_cartesian_2d(Ticked::new((x0, x1), xs), Ticked::new((y0, y1), ys))
        .map_err(err)?;
    let label = |ticks: &[(f64, String)], v: f64| {
        ticks
            .iter()
            .find(|t| (t.0 - v).abs() <= 1e-9 * (1.0 + v.abs()))
            .map_or_else(String::new, |t| t.1.clone())
    };
    chart
        .configure_mesh()
        .x_desc(fig.x_desc.as_str())
        .y_desc(fig.y_desc.as_str())
        .label_style(("sans-serif", TICK))
        .axis_desc_style(("sans-serif", DESC))
        .bold_line_style(BLACK.mix(0.12))
        .x_label_formatter(&|v| label(&xt, *v))
        .y_label_formatter(&|v| label(&yt, *v))
        .draw()
        .map_err(err)?;
    let n = p.lines.len();
    let joined = matches!(fig.x, Scale::Numbers(_));
    for (k, pts) in p.lines.iter().enumerate() {
        let look = look(k, n);
        let at: Vec<(f64, f64)> = pts.iter().map(|p| (p.0, p.1)).collect();
        if joined {
            draw_line(&mut chart, at.clone(), &look, "")?;
        }
        // The interval as a bar with a cap at each end (plotters' ErrorBar also rings
        // the mean, which hid the line's own marker).
        let style = ShapeStyle::from(look.colour).stroke_width(2);
        for &(x, y, e) in pts.iter().filter(|p| p.2 > 0.0) {
            let bar = PathElement::new(vec![(x, y - e), (x, y + e)], style);
            let cap = |y| EmptyElement::at((x, y)) + PathElement::new(vec![(-5, 0), (5, 0)], style);
            chart.draw_series([bar]).map_err(err)?;
            chart.draw_series([cap(y - e), cap(y + e)]).map_err(err)?;
        }
        chart
            .draw_series(at.iter().map(|&a| marker(a, &look)))
            .map_err(err)?;
    }
    if p.lines.iter().all(Vec::is_empty) {
        let style = ("sans-serif", DESC)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let at = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        chart
            .draw_series([Text::new("no values", at, style)])
            .map_err(err)?;
    }
    Ok(())
}

/// The legend under the panels: per line its marker (on a numeric axis, on a stretch
/// of its line) and its words, row by row.
fn legend(area: &Area, fig: &Figure) -> PlotResult {
    if fig.legend.is_empty() {
        return Ok(());
    }
    let per = per_row(&fig.legend);
    let width = (WIDTH as i32 - 40) / per as i32;
    let font = ("sans-serif", TICK)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let joined = matches!(fig.x, Scale::Numbers(_));
    let n = fig.legend.len();
    for (k, text) in fig.legend.iter().enumerate() {
        let (row, col) = ((k / per) as i32, (k % per) as i32);
        let (x, y) = (20 + col * width, 8 + row * ROW + ROW / 2);
        let look: Look = look(k, n);
        if joined {
            let (on, off) = look.dash.unwrap_or((40, 1));
            let line = DashedPathElement::new(vec![(x, y), (x + 40, y)], on, off, look.style());
            area.draw(&line).map_err(err)?;
        }
        area.draw(&marker((x + 20, y), &look)).map_err(err)?;
        area.draw(&Text::new(text.clone(), (x + 52, y), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}
