//! `sweep-METRIC.svg`: each metric of a sweep against the first key that varies, one
//! line per value of the next, a panel per combination of any later ones (small
//! multiples), so a line joins only runs that differ in its x key; a key swept over one
//! value is a setting, said under the title. A marker at every combination, and with
//! `--seeds` the 95 % confidence interval as an error bar.
//!
//! The x axis places numbers at their values (a vector of one number repeated,
//! `[25,25,25]`, at 25) and everything else as categories, each labelled as written:
//! words (`control.kind`), vectors of different elements, numbers that would coincide.
//! Categories are not joined by lines (a line between `tdpa` and `wave` would say
//! something lies between them); their markers stand side by side.
//!
//! The y axis says the metric in words and in the unit a reader expects ([`shown`]);
//! the legend, in a strip under the panels where it covers no point, names each line
//! (`control.kind=tdpa`). A metric no run has a value for gets no plot (an empty figure
//! would read as a plot of nothing measured); a line with none says `(no values)` in
//! the legend. Where lines coincide (controls that agree at a point) all show: each
//! has its own colour, dash and marker, the first drawn widest (`plots::looks`).

mod figure;
pub mod keys;
pub mod shown;
#[cfg(test)]
mod tests;

use crate::sweep::{labelled, Axis, FAILED, METRICS};
use keys::{settings, sub_combinations, Roles, Scale};
use shown::shown_or_name;
use std::path::Path;

/// One combination's values: its value index on each axis, and per metric the mean
/// and (with seeds) the interval's half width.
pub type Point = (Vec<usize>, Vec<(Option<f64>, Option<f64>)>);

/// A line of a panel: per combination, x, y and the interval's half width (y and the
/// interval in the axis's unit).
type Line = Vec<(f64, f64, f64)>;

/// One panel: its title (the later keys' values; empty for a single panel) and its
/// lines, in the order of the legend's entries.
#[derive(Debug, Clone)]
struct Panel {
    title: String,
    lines: Vec<Line>,
}

/// Everything a metric's figure shows.
#[derive(Debug, Clone)]
struct Figure {
    title: String,
    /// The settings (keys of one value), and a word on the error bars.
    subtitle: String,
    x_desc: String,
    y_desc: String,
    x: Scale,
    panels: Vec<Panel>,
    /// The legend's entries, one per line (none for a single line).
    legend: Vec<String>,
}

/// Writes `sweep-METRIC.svg` into `out` for every metric some run has a value of,
/// removing an older one of a metric with none; returns the files written.
pub fn sweep_plots(
    out: &Path,
    axes: &[Axis],
    points: &[Point],
) -> crate::plots::PlotResult<Vec<String>> {
    let roles = Roles::of(axes);
    let Some(x) = roles.x() else {
        return Ok(Vec::new());
    };
    let mut written = Vec::new();
    for (m, (name, _)) in METRICS.iter().enumerate() {
        if *name == FAILED {
            continue;
        }
        let file = format!("sweep-{name}.svg");
        let path = out.join(&file);
        let Some(fig) = figure(axes, &roles, x, points, m) else {
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e.into()),
                _ => continue,
            }
        };
        crate::plots::whole_svg(&path, |p| figure::draw(p, &fig))?;
        written.push(file);
    }
    Ok(written)
}

/// Metric `m`'s figure, `None` when no combination has a value of it.
fn figure(axes: &[Axis], roles: &Roles, x: usize, points: &[Point], m: usize) -> Option<Figure> {
    let name = METRICS[m].0;
    let shown = shown_or_name(name);
    let scale = Scale::of(&axes[x]);
    let n_lines = roles.lines().map_or(1, |l| axes[l].values.len());
    let mut panels = Vec::new();
    let mut intervals = false;
    for combo in sub_combinations(axes, roles.panels()) {
        let mut lines = vec![Line::new(); n_lines];
        for (c, v) in points {
            if roles.panels().iter().any(|&a| c[a] != combo[a]) {
                continue;
            }
            let (Some(mean), ci) = v[m] else { continue };
            let line = roles.lines().map_or(0, |l| c[l]);
            let ci = ci.unwrap_or(0.0) * shown.scale;
            intervals |= ci > 0.0;
            let at = scale.at(c[x]) + dodge(&scale, line, n_lines);
            lines[line].push((at, mean * shown.scale, ci));
        }
        for l in &mut lines {
            l.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let title = match roles.panels() {
            [] => String::new(),
            which => settings(axes, which, Some(&combo)),
        };
        panels.push(Panel { title, lines });
    }
    let empty = |k: usize| panels.iter().all(|p| p.lines[k].is_empty());
    if (0..n_lines).all(empty) {
        return None;
    }
    let legend = roles.lines().map_or_else(Vec::new, |l| {
        (0..n_lines)
            .map(|k| {
                let s = keys::setting(&axes[l], k);
                if empty(k) {
                    format!("{s} (no values)")
                } else {
                    s
                }
            })
            .collect()
    });
    let mut subtitle = settings(axes, &roles.fixed, None);
    if intervals {
        let bars = "error bars: 95 % confidence interval of the mean over the seeds";
        subtitle = [subtitle.as_str(), bars]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join("; ");
    }
    Some(Figure {
        title: format!("{} against {}", shown.label, axes[x].key),
        subtitle,
        x_desc: labelled(&axes[x].key),
        y_desc: shown.axis(),
        x: scale,
        panels,
        legend,
    })
}

/// How far line `k` of `n` stands beside its category (0 on a numeric axis), so the
/// markers of a category stand side by side within it.
fn dodge(scale: &Scale, k: usize, n: usize) -> f64 {
    match scale {
        Scale::Numbers(_) => 0.0,
        Scale::Categories(_) => {
            let step = (0.6 / n as f64).min(0.15);
            (k as f64 - (n as f64 - 1.0) / 2.0) * step
        }
    }
}
