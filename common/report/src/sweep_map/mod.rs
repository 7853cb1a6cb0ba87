//! `map-VALUE.svg`: the stability and transparency map researchers publish, drawn when
//! a sweep's first two keys that vary are numbers (a wall's stiffness and a delay,
//! say): one cell per pair, its colour the stiffness the operator felt over the
//! environment's (`transparency.stiffness_ratio`, read off the colour bar beside the
//! map, its value written in the cell), and one map per value of a third key that
//! varies (`control.kind=none,tdpa,wave,mmt`; per combination of the third and later
//! ones). A key swept over one value is a setting, said under the title. Two marks,
//! decided as docs/05 does from the run's summary, explained in a legend under the map:
//! - a cross where the contact did not settle (unstable): its force swung by
//!   [`SETTLED_SWING_N`] or more over the last second (a contact that keeps
//!   oscillating leaves the wall every cycle and swings by its whole force); the cross
//!   stops short of the cell's number, which stays readable;
//! - a bar along the cell's top where the channel made energy: its passivity observer
//!   fell below [`ACTIVE_ENERGY_J`] (fifteen times the 3.3 mJ the wall-delay contact
//!   stores at rest). A settled contact can have done so once (MMT's slave presses the
//!   wall before the master renders it), so it is marked apart from instability.
//!
//! The number and the marks are drawn in black on a light cell and in white on a dark
//! one.

mod draw;
#[cfg(test)]
mod tests;

use crate::sweep::{labelled, numeric, Axis, METRICS};
use crate::sweep_plots::keys::{settings, sub_combinations, Roles};
use plotters::prelude::RGBColor;
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

/// Writes a map per combination of the values of the third and later keys that vary
/// (one map without one) into `out`, if the first two that vary are numbers; returns
/// the files written.
pub fn sweep_maps(
    out: &Path,
    axes: &[Axis],
    points: &[crate::sweep_plots::Point],
) -> crate::plots::PlotResult<Vec<String>> {
    let roles = Roles::of(axes);
    let (Some(&x), Some(&y)) = (roles.varying.first(), roles.varying.get(1)) else {
        return Ok(Vec::new());
    };
    let nums = |a: &Axis| {
        a.values
            .iter()
            .map(|v| numeric(v))
            .collect::<Option<Vec<f64>>>()
    };
    let (Some(xs), Some(ys)) = (nums(&axes[x]), nums(&axes[y])) else {
        return Ok(Vec::new());
    };
    let pages = &roles.varying[2..];
    let mut written = Vec::new();
    for page in sub_combinations(axes, pages) {
        let mut grid = vec![vec![None; ys.len()]; xs.len()];
        for (combo, means) in points {
            if pages.iter().all(|&a| combo[a] == page[a]) {
                grid[combo[x]][combo[y]] = Some(cell(means));
            }
        }
        let name = match pages {
            [] => "map.svg".to_string(),
            _ => {
                let parts: Vec<String> = pages
                    .iter()
                    .map(|&a| file_safe(&axes[a].values[page[a]]))
                    .collect();
                format!("map-{}.svg", parts.join("-"))
            }
        };
        let mut title = "felt / environment stiffness".to_string();
        if !pages.is_empty() {
            title += &format!(", {}", settings(axes, pages, Some(&page)));
        }
        let map = draw::Map {
            title,
            subtitle: settings(axes, &roles.fixed, None),
            x_desc: labelled(&axes[x].key),
            y_desc: labelled(&axes[y].key),
            x: xs.clone(),
            y: ys.clone(),
            grid,
        };
        crate::plots::whole_svg(&out.join(&name), |p| draw::draw(p, &map))?;
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

/// The ratio at the colour bar's top: every ratio from it up has the darkest red.
pub const RATIO_TOP: f64 = 1.5;

/// The colour to write on a cell of `fill`: black on a light one, white on a dark one
/// (by the cell's relative luminance, as WCAG computes it).
pub fn ink(fill: RGBColor) -> RGBColor {
    let linear = |c: u8| {
        let c = c as f64 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let l = 0.2126 * linear(fill.0) + 0.7152 * linear(fill.1) + 0.0722 * linear(fill.2);
    // Black where it contrasts 4:1 or better ((l + 0.05) / 0.05: the reds around 1,
    // 4.3:1), so the map's numbers change colour only where the cells turn dark.
    if (l + 0.05) / 0.05 >= 4.0 {
        RGBColor(0, 0, 0)
    } else {
        RGBColor(255, 255, 255)
    }
}
