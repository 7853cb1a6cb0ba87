//! Draws a [`Map`]: the title and the settings, the cells with their numbers and
//! marks, the colour bar to the right, and under the map a legend of the marks.

use super::{colour, ink, Cell, ACTIVE_ENERGY_J, RATIO_TOP, SETTLED_SWING_N};
use crate::plots::looks::text_w;
use crate::plots::ticked::Ticked;
use crate::plots::WIDTH;
use crate::sweep_plots::keys::number;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontTransform;
use std::path::Path;

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

use crate::plots::{err, PlotResult};

/// Everything one map shows.
#[derive(Debug, Clone)]
pub(super) struct Map {
    pub title: String,
    /// The settings (keys of one value).
    pub subtitle: String,
    pub x_desc: String,
    pub y_desc: String,
    /// The first key's values (columns) and the second's (rows).
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    /// Per column, per row, the cell (None: no run).
    pub grid: Vec<Vec<Option<Cell>>>,
}

/// Tick labels and legend, cell numbers, axis titles, title, px.
const TICK: u32 = 15;
const NUMBER: u32 = 16;
const DESC: u32 = 16;
const TITLE: u32 = 22;
/// The map's height, the colour bar's column's width, px.
const MAP_H: u32 = 580;
const BAR_W: u32 = 150;
/// A row of the marks' legend, px.
const LEGEND_ROW: i32 = 26;
/// The colour bar's steps (of [`RATIO_TOP`] / `STEPS` each).
const STEPS: usize = 60;

fn font(size: u32, colour: RGBColor, pos: Pos) -> TextStyle<'static> {
    ("sans-serif", size).into_font().color(&colour).pos(pos)
}

fn centred() -> Pos {
    Pos::new(HPos::Center, VPos::Center)
}

/// Draws `map` into `path`.
pub(super) fn draw(path: &Path, map: &Map) -> PlotResult {
    let header = if map.subtitle.is_empty() { 40 } else { 64 };
    let root = SVGBackend::new(path, (WIDTH, header + MAP_H + legend_h())).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mid = WIDTH as i32 / 2;
    let title = Text::new(map.title.clone(), (mid, 20), font(TITLE, BLACK, centred()));
    root.draw(&title).map_err(err)?;
    if !map.subtitle.is_empty() {
        let sub = Text::new(
            map.subtitle.clone(),
            (mid, 46),
            font(TICK, BLACK, centred()),
        );
        root.draw(&sub).map_err(err)?;
    }
    let (_, body) = root.split_vertically(header);
    let (upper, legend_area) = body.split_vertically(MAP_H);
    let (cells, bar) = upper.split_horizontally(WIDTH - BAR_W);
    let (top, bottom) = grid(&cells, map)?;
    colour_bar(&bar, (top, bottom))?;
    legend(&legend_area)?;
    root.present().map_err(err)
}

/// The cells, their axes, numbers and marks; returns the plotting area's top and
/// bottom, px, in `area`, for the colour bar to match.
fn grid(area: &Area, map: &Map) -> PlotResult<(i32, i32)> {
    let (nx, ny) = (map.x.len(), map.y.len());
    let labels = |v: &[f64]| v.iter().map(|x| number(*x)).collect::<Vec<_>>();
    let (xl, yl) = (labels(&map.x), labels(&map.y));
    let y_area = yl.iter().map(|t| text_w(t, TICK)).max().unwrap_or(0) + 46;
    let centres = |n: usize| (0..n).map(|i| i as f64 + 0.5).collect::<Vec<_>>();
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(52)
        .y_label_area_size(y_area)
        .build_cartesian_2d(
            Ticked::new((0.0, nx as f64), centres(nx)),
            Ticked::new((0.0, ny as f64), centres(ny)),
        )
        .map_err(err)?;
    let name = |l: &[String], t: f64| l.get(t.floor() as usize).cloned().unwrap_or_default();
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(map.x_desc.as_str())
        .y_desc(map.y_desc.as_str())
        .label_style(("sans-serif", TICK))
        .axis_desc_style(("sans-serif", DESC))
        .x_label_formatter(&|t| name(&xl, *t))
        .y_label_formatter(&|t| name(&yl, *t))
        .draw()
        .map_err(err)?;
    let (w, h) = chart.plotting_area().dim_in_pixel();
    let cell_px = (w as f64 / nx as f64, h as f64 / ny as f64);
    for (i, column) in map.grid.iter().enumerate() {
        for (j, c) in column.iter().enumerate() {
            one_cell(&mut chart, (i as f64, j as f64), *c, cell_px)?;
        }
    }
    let range = chart.plotting_area().get_pixel_range();
    let top = range.1.start - area.get_base_pixel().1;
    Ok((top, top + h as i32))
}

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<Ticked, Ticked>>;

/// One cell at `(x0, y0)` (its lower left corner): its colour, its number, and its
/// marks in the colour that contrasts with it; `px` is a cell's size in pixels.
fn one_cell(
    chart: &mut Chart,
    (x0, y0): (f64, f64),
    c: Option<Cell>,
    px: (f64, f64),
) -> PlotResult {
    let fill = colour(c.and_then(|c| c.ratio));
    let ink = ink(fill);
    let rect = Rectangle::new([(x0, y0), (x0 + 1.0, y0 + 1.0)], fill.filled());
    chart.draw_series([rect]).map_err(err)?;
    let text = match c {
        None => "no run".to_string(),
        Some(c) => c.ratio.map_or("n/a".to_string(), |r| format!("{r:.2}")),
    };
    let centre = (x0 + 0.5, y0 + 0.5);
    let style = font(NUMBER, ink, centred());
    chart
        .draw_series([Text::new(text.clone(), centre, style)])
        .map_err(err)?;
    let stroke = ShapeStyle::from(ink).stroke_width(2);
    if c.is_some_and(|c| c.settled == Some(false)) {
        // The diagonals from the corners to the edge of the number's box, about.
        let half = (
            (text_w(&text, NUMBER) / 2 + 6) as f64,
            (NUMBER / 2 + 5) as f64,
        );
        let gap = (half.0 / px.0).min(half.1 / px.1).min(0.3);
        let segments = [(-1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (1.0, -1.0)].map(|(sx, sy)| {
            let at = |d: f64| (centre.0 + sx * d, centre.1 + sy * d);
            PathElement::new(vec![at(gap), at(0.4)], stroke)
        });
        chart.draw_series(segments).map_err(err)?;
    }
    if c.is_some_and(|c| c.passive == Some(false)) {
        let corners = [(x0 + 0.05, y0 + 0.88), (x0 + 0.95, y0 + 0.95)];
        chart
            .draw_series([Rectangle::new(corners, ink.filled())])
            .map_err(err)?;
    }
    Ok(())
}

/// The colour bar, from 0 at `bottom` to [`RATIO_TOP`] and above at `top` (px in
/// `area`), its ticks every 0.25, and its title along it.
fn colour_bar(area: &Area, (top, bottom): (i32, i32)) -> PlotResult {
    let (x0, x1) = (14, 38);
    let at = |r: f64| bottom - ((r / RATIO_TOP) * (bottom - top) as f64).round() as i32;
    for k in 0..STEPS {
        let (a, b) = (k as f64, k as f64 + 1.0);
        let r = (a + 0.5) * RATIO_TOP / STEPS as f64;
        let step = RATIO_TOP / STEPS as f64;
        let rect = Rectangle::new(
            [(x0, at(b * step)), (x1, at(a * step))],
            colour(Some(r)).filled(),
        );
        area.draw(&rect).map_err(err)?;
    }
    area.draw(&Rectangle::new([(x0, top), (x1, bottom)], BLACK))
        .map_err(err)?;
    let left = Pos::new(HPos::Left, VPos::Center);
    for k in 0..=6 {
        let r = k as f64 * 0.25;
        let y = at(r);
        area.draw(&PathElement::new(vec![(x1, y), (x1 + 5, y)], BLACK))
            .map_err(err)?;
        let label = if k == 6 {
            format!("≥{}", number(r))
        } else {
            number(r)
        };
        area.draw(&Text::new(label, (x1 + 8, y), font(TICK, BLACK, left)))
            .map_err(err)?;
    }
    let along = ("sans-serif", DESC)
        .into_font()
        .transform(FontTransform::Rotate270)
        .color(&BLACK)
        .pos(centred());
    let title = Text::new(
        "felt / environment stiffness",
        (112, (top + bottom) / 2),
        along,
    );
    area.draw(&title).map_err(err)
}

/// The marks' legend's entries: a crossed cell, a cell with the bar, a grey cell.
fn entries() -> [String; 3] {
    [
        format!("unsettled: force swing of {SETTLED_SWING_N} N or more in the last second"),
        format!("channel made more than {:.0} mJ", -ACTIVE_ENERGY_J * 1e3),
        "n/a: no stiffness identified".to_string(),
    ]
}

/// Half a legend square's side, px.
const SQUARE: i32 = 9;

/// Where each entry of the legend goes (its square's centre), row after row: an entry
/// that would pass the figure's edge starts a row of its own; and the rows.
fn layout(entries: &[String]) -> (Vec<(i32, i32)>, i32) {
    let (mut x, mut row) = (20, 0);
    let mut at = Vec::new();
    for text in entries {
        let width = 2 * SQUARE + 8 + text_w(text, TICK) + 28;
        if x > 20 && x + width > WIDTH as i32 - 10 {
            (x, row) = (20, row + 1);
        }
        at.push((x, LEGEND_ROW / 2 + 4 + row * LEGEND_ROW));
        x += width;
    }
    (at, row + 1)
}

/// The legend's height, px.
fn legend_h() -> u32 {
    (layout(&entries()).1 * LEGEND_ROW + 12) as u32
}

/// The marks' legend.
fn legend(area: &Area) -> PlotResult {
    let left = Pos::new(HPos::Left, VPos::Center);
    let entries = entries();
    let s = SQUARE;
    for (k, (text, (x, y))) in entries.iter().zip(layout(&entries).0).enumerate() {
        let fill = if k == 2 { colour(None) } else { WHITE };
        let square = [(x - s, y - s), (x + s, y + s)];
        area.draw(&Rectangle::new(square, fill.filled()))
            .map_err(err)?;
        area.draw(&Rectangle::new(square, BLACK)).map_err(err)?;
        let stroke = ShapeStyle::from(BLACK).stroke_width(2);
        match k {
            0 => {
                for (a, b) in [((-s, -s), (s, s)), ((-s, s), (s, -s))] {
                    let ends = vec![(x + a.0, y + a.1), (x + b.0, y + b.1)];
                    area.draw(&PathElement::new(ends, stroke)).map_err(err)?;
                }
            }
            1 => {
                let corners = [(x - s + 1, y - s + 1), (x + s - 1, y - s + 4)];
                area.draw(&Rectangle::new(corners, BLACK.filled()))
                    .map_err(err)?;
            }
            _ => {}
        }
        area.draw(&Text::new(
            text.clone(),
            (x + s + 8, y),
            font(TICK, BLACK, left),
        ))
        .map_err(err)?;
    }
    Ok(())
}
