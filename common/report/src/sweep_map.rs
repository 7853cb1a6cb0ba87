//! `map-VALUE.svg`: the stability and transparency map researchers publish, drawn when
//! a sweep's first two swept keys are numbers (a wall's stiffness and a delay, say):
//! one cell per pair, its colour the stiffness the operator felt over the
//! environment's (`transparency.stiffness_ratio`), and one map per value of a third
//! key (`control.kind=none,tdpa,wave,mmt`). Two marks, decided as docs/05 does from
//! the run's summary:
//! - a cross where the contact did not settle (unstable): its force swung by
//!   [`SETTLED_SWING_N`] or more over the last second (a contact that keeps
//!   oscillating leaves the wall every cycle and swings by its whole force);
//! - a bar along the cell's top where the channel made energy: its passivity observer
//!   fell below [`ACTIVE_ENERGY_J`] (fifteen times the 3.3 mJ the wall-delay contact
//!   stores at rest). A settled contact can have done so once (MMT's slave presses the
//!   wall before the master renders it), so it is marked apart from instability.

use crate::plots::tick;
use crate::sweep::{labelled, numeric, Axis, METRICS};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// A settled contact's largest force swing over the last second, N.
pub const SETTLED_SWING_N: f64 = 0.5;
/// A channel whose observer fell below this made energy, J.
pub const ACTIVE_ENERGY_J: f64 = -0.05;

/// What one cell shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Felt over environment's stiffness (None: not identified).
    pub ratio: Option<f64>,
    /// The contact settled (None: the figure missing).
    pub settled: Option<bool>,
    /// The channel made no energy to speak of (None: the figure missing).
    pub passive: Option<bool>,
}

fn metric(name: &str) -> Option<usize> {
    METRICS.iter().position(|(n, _)| *n == name)
}

/// A combination's cell from its metrics' means (as [`crate::sweep_plots::Point`]
/// holds them).
pub fn cell(means: &[(Option<f64>, Option<f64>)]) -> Cell {
    let get = |name| metric(name).and_then(|i| means.get(i)).and_then(|m| m.0);
    Cell {
        ratio: get("stiffness_ratio"),
        settled: get("force_swing_n").map(|s| s < SETTLED_SWING_N),
        passive: get("observer_min_j").map(|w| w > ACTIVE_ENERGY_J),
    }
}

/// Writes a map per value of the third axis (one map without one) into `out`, if the
/// first two axes are numeric; returns the files written.
pub fn sweep_maps(
    out: &Path,
    axes: &[Axis],
    points: &[crate::sweep_plots::Point],
) -> Result<Vec<String>, String> {
    let (Some(x), Some(y)) = (axes.first(), axes.get(1)) else {
        return Ok(Vec::new());
    };
    let nums = |a: &Axis| {
        a.values
            .iter()
            .map(|v| numeric(v))
            .collect::<Option<Vec<f64>>>()
    };
    let (Some(xs), Some(ys)) = (nums(x), nums(y)) else {
        return Ok(Vec::new());
    };
    let pages = axes.get(2).map_or(1, |a| a.values.len());
    let mut written = Vec::new();
    for page in 0..pages {
        let mut grid = vec![vec![None; ys.len()]; xs.len()];
        for (combo, means) in points {
            if combo.get(2).is_none_or(|&p| p == page) {
                grid[combo[0]][combo[1]] = Some(cell(means));
            }
        }
        let (name, title) = match axes.get(2) {
            Some(a) => {
                let v = &a.values[page];
                (
                    format!("map-{}.svg", file_safe(v)),
                    format!("{}={v}", a.key),
                )
            }
            None => ("map.svg".to_string(), String::new()),
        };
        let axes_text = (labelled(&x.key), labelled(&y.key));
        crate::plots::whole_svg(&out.join(&name), |p| {
            draw(p, &title, &axes_text, (&x.values, &y.values), &grid)
        })?;
        written.push(name);
    }
    Ok(written)
}

/// A value as a file name's part: letters, digits, `-`, `.` and `_` kept, others `_`.
fn file_safe(v: &str) -> String {
    v.chars()
        .map(|c| match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' | '-' | '.' | '_' => c,
            _ => '_',
        })
        .collect()
}

/// The colour of a ratio: blue (nothing felt) through white (0.5) to red (1, the
/// environment's own), darker red above one; grey where none was identified.
pub fn colour(ratio: Option<f64>) -> RGBColor {
    let Some(r) = ratio.filter(|r| r.is_finite()) else {
        return RGBColor(200, 200, 200);
    };
    let lerp = |a: u8, b: u8, t: f64| (a as f64 + (b as f64 - a as f64) * t.clamp(0.0, 1.0)) as u8;
    let (blue, white, red, dark) = ((49, 54, 149), (247, 247, 247), (215, 48, 39), (103, 0, 13));
    let mix = |p: (u8, u8, u8), q: (u8, u8, u8), t| {
        RGBColor(lerp(p.0, q.0, t), lerp(p.1, q.1, t), lerp(p.2, q.2, t))
    };
    match r {
        r if r < 0.5 => mix(blue, white, r / 0.5),
        r if r <= 1.0 => mix(white, red, (r - 0.5) / 0.5),
        r => mix(red, dark, (r - 1.0) / 0.5),
    }
}

type Grid = Vec<Vec<Option<Cell>>>;

fn draw(
    path: &Path,
    title: &str,
    (x_desc, y_desc): &(String, String),
    (xv, yv): (&Vec<String>, &Vec<String>),
    grid: &Grid,
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let root = SVGBackend::new(path, (crate::plots::WIDTH, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (nx, ny) = (xv.len() as f64, yv.len() as f64);
    let caption =
        format!("felt / environment stiffness; x: unsettled, bar: channel made > 50 mJ; {title}");
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d(0.0..nx, 0.0..ny)
        .map_err(|e| err(&e))?;
    let at = |v: &Vec<String>, t: f64| {
        let i = t.floor();
        (t - i - 0.5).abs() < 1e-6 && i >= 0.0 && (i as usize) < v.len()
    };
    let name = |v: &Vec<String>, t: f64| match at(v, t) {
        true => numeric(&v[t.floor() as usize])
            .map_or_else(|| v[t.floor() as usize].clone(), |n| tick(&n)),
        false => String::new(),
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(x_desc.as_str())
        .y_desc(y_desc.as_str())
        .x_labels(4 * xv.len() + 1)
        .y_labels(4 * yv.len() + 1)
        .x_label_formatter(&|t| name(xv, *t))
        .y_label_formatter(&|t| name(yv, *t))
        .draw()
        .map_err(|e| err(&e))?;
    let centre = Pos::new(HPos::Center, VPos::Center);
    for (i, column) in grid.iter().enumerate() {
        for (j, c) in column.iter().enumerate() {
            let (x0, y0) = (i as f64, j as f64);
            let fill = colour(c.and_then(|c| c.ratio));
            chart
                .draw_series([Rectangle::new(
                    [(x0, y0), (x0 + 1.0, y0 + 1.0)],
                    fill.filled(),
                )])
                .map_err(|e| err(&e))?;
            let text = match c {
                None => "no run".to_string(),
                Some(c) => c.ratio.map_or("n/a".to_string(), |r| format!("{r:.2}")),
            };
            let style = ("sans-serif", 16).into_font().color(&BLACK).pos(centre);
            chart
                .draw_series([Text::new(text, (x0 + 0.5, y0 + 0.5), style)])
                .map_err(|e| err(&e))?;
            let line =
                |a: (f64, f64), b: (f64, f64)| PathElement::new(vec![a, b], BLACK.stroke_width(2));
            if c.is_some_and(|c| c.settled == Some(false)) {
                let (a, b) = ((x0 + 0.1, y0 + 0.1), (x0 + 0.9, y0 + 0.9));
                chart
                    .draw_series([line(a, b), line((a.0, b.1), (b.0, a.1))])
                    .map_err(|e| err(&e))?;
            }
            if c.is_some_and(|c| c.passive == Some(false)) {
                let corners = [(x0 + 0.05, y0 + 0.88), (x0 + 0.95, y0 + 0.95)];
                chart
                    .draw_series([Rectangle::new(corners, BLACK.filled())])
                    .map_err(|e| err(&e))?;
            }
        }
    }
    root.present().map_err(|e| err(&e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::axis;

    fn means(swing: f64, w: f64, ratio: f64) -> Vec<(Option<f64>, Option<f64>)> {
        let mut m = vec![(None, None); METRICS.len()];
        let mut put = |name, v| m[metric(name).expect("a metric")] = (Some(v), None);
        put("force_swing_n", swing);
        put("observer_min_j", w);
        put("stiffness_ratio", ratio);
        m
    }

    #[test]
    fn a_cell_says_whether_the_contact_settled_and_the_channel_made_energy() {
        let c = cell(&means(0.1, -0.01, 0.9));
        assert_eq!(
            (c.settled, c.passive, c.ratio),
            (Some(true), Some(true), Some(0.9))
        );
        assert_eq!(cell(&means(2.0, -0.01, 0.9)).settled, Some(false));
        assert_eq!(cell(&means(0.1, -0.2, 0.9)).passive, Some(false));
        let none = vec![(None, None); METRICS.len()];
        let empty = Cell {
            ratio: None,
            settled: None,
            passive: None,
        };
        assert_eq!(cell(&none), empty);
    }

    #[test]
    fn the_colour_runs_from_blue_through_white_to_red() {
        assert_eq!(colour(Some(0.0)), RGBColor(49, 54, 149));
        assert_eq!(colour(Some(0.5)), RGBColor(247, 247, 247));
        assert_eq!(colour(Some(1.0)), RGBColor(215, 48, 39));
        assert_eq!(colour(None), RGBColor(200, 200, 200));
        assert_eq!(colour(Some(9.0)), RGBColor(103, 0, 13));
    }

    /// Two numeric axes and a third: one map per value of the third, each cell its
    /// ratio, a cross on each unstable one; words on the first axis: no map.
    #[test]
    fn a_map_per_value_of_the_third_axis() {
        let tmp = tempfile::tempdir().expect("tmp");
        let dir = tmp.path();
        let svg = |p: &Path| std::fs::read_to_string(p).expect("svg");
        let axes = [
            axis("environment.objects[0].stiffness=[300,300,300],[600,600,600]").expect("x"),
            axis("network.forward.delay_ms=0,200").expect("y"),
            axis("control.kind=none,mmt").expect("z"),
        ];
        let mut points = Vec::new();
        for (i, j, k) in
            (0..2).flat_map(|i| (0..2).flat_map(move |j| (0..2).map(move |k| (i, j, k))))
        {
            let unstable = k == 0 && j == 1;
            let swing = if unstable { 5.0 } else { 0.0 };
            let w = if k == 1 && i == 1 && j == 1 {
                -0.1
            } else {
                -0.001
            };
            points.push((
                vec![i, j, k],
                means(swing, w, 0.25 + 0.25 * (i + j + k) as f64),
            ));
        }
        let files = sweep_maps(dir, &axes, &points).expect("maps");
        assert_eq!(files, ["map-none.svg", "map-mmt.svg"]);
        let none = svg(&dir.join("map-none.svg"));
        let mmt = svg(&dir.join("map-mmt.svg"));
        for s in [&none, &mmt] {
            assert!(s.contains("network.forward.delay_ms (ms)"), "{s}");
            assert!(s.contains("environment.objects[0].stiffness"));
        }
        // Two crossed cells on none's map (two wide strokes each), none on mmt's; one
        // bar (a black rectangle) on mmt's, none on none's.
        let strokes = |s: &str| s.matches(r#"stroke-width="2""#).count();
        assert_eq!((strokes(&none), strokes(&mmt)), (4, 0), "{none}");
        let bars = |s: &str| s.matches(r##"fill="#000000" stroke="none"/>"##).count();
        assert_eq!((bars(&none), bars(&mmt)), (0, 1), "{mmt}");
        assert!(
            mmt.contains("\n1.00\n") && none.contains("\n0.25\n"),
            "{mmt}"
        );
        let words = [
            axis("control.kind=none,mmt").expect("a"),
            axis("seed=1,2").expect("b"),
        ];
        assert!(sweep_maps(dir, &words, &points).expect("none").is_empty());
    }
}
