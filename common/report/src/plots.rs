//! SVG plots of a run: the overhead histogram, master and slave positions over time,
//! and forces over time. Written with plotters' SVG backend, which needs no system
//! library or font file.
//!
//! Time series are thinned as they are gathered: each series keeps, per bucket of
//! consecutive samples, the smallest and the largest value, and doubles the bucket when
//! there are more buckets than pixel columns. A plot of a million samples is
//! then as small and as readable as one of a thousand, and no spike is lost.

use crate::analysis::Latency;
use crate::trace::TraceRow;
use plotters::prelude::*;
use std::path::Path;
use tactile_messages::samples::Flags;

pub(crate) mod looks;
mod percentiles;
mod stretches;
pub(crate) mod ticked;
mod timeplot;
pub(crate) use looks::{draw_legend, draw_line, look};
pub use percentiles::percentile_plot;
use stretches::Stretches;
pub(crate) use timeplot::{tick, time_series};

/// Why a plot could not be drawn: plotters' fault (its SVG backend's, or an element's),
/// or the file's.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// plotters could not draw (the fault as plotters gives it, kept as the source).
    #[error("{0}")]
    Draw(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// The plot's file could not be written, renamed or removed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

pub type PlotResult<T = ()> = Result<T, PlotError>;

/// plotters' error, kept whole.
pub(crate) fn err(e: impl std::error::Error + Send + Sync + 'static) -> PlotError {
    PlotError::Draw(Box::new(e))
}

const AXES: [&str; 3] = ["x", "y", "z"];
const COLOURS: [RGBColor; 3] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];

/// Width of the time-series plots, pixels.
pub const WIDTH: u32 = 1000;

/// One series thinned to the pixel width, keeping the extremes of each bucket.
#[derive(Debug, Clone)]
pub struct Thinned {
    bucket: u64,
    in_bucket: u64,
    cur: Option<(f64, f64, f64)>,
    points: Vec<(f64, f64, f64)>,
}

impl Default for Thinned {
    fn default() -> Self {
        Thinned {
            bucket: 1,
            in_bucket: 0,
            cur: None,
            points: Vec::new(),
        }
    }
}

impl Thinned {
    /// Adds the value at time `t`; NaN leaves a gap in the bucket's extremes.
    pub fn push(&mut self, t: f64, v: f64) {
        if v.is_finite() {
            self.cur = Some(match self.cur {
                None => (t, v, v),
                Some((t0, lo, hi)) => (t0, lo.min(v), hi.max(v)),
            });
        }
        self.in_bucket += 1;
        if self.in_bucket < self.bucket {
            return;
        }
        self.in_bucket = 0;
        if let Some(p) = self.cur.take() {
            self.points.push(p);
        }
        if self.points.len() >= WIDTH as usize {
            self.points = self
                .points
                .chunks(2)
                .map(|c| {
                    c.iter()
                        .skip(1)
                        .fold(c[0], |(t, lo, hi), &(_, l, h)| (t, lo.min(l), hi.max(h)))
                })
                .collect();
            self.bucket *= 2;
        }
    }

    /// True once buckets hold more than one sample: the plot shows each pixel
    /// column's extremes, not every sample.
    pub fn thinned(&self) -> bool {
        self.bucket > 1
    }

    /// The points to draw: each bucket's minimum then maximum.
    pub fn points(&self) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(2 * self.points.len() + 2);
        for &(t, lo, hi) in self.points.iter().chain(self.cur.iter()) {
            out.push((t, lo));
            if hi != lo {
                out.push((t, hi));
            }
        }
        out
    }
}

/// The time series of a run, gathered row by row.
#[derive(Debug, Clone, Default)]
pub struct Series {
    handle: [Thinned; 3],
    tool: [Thinned; 3],
    force: [Thinned; 3],
    felt: [Thinned; 3],
    channel: Thinned,
    observer_m: Thinned,
    observer_s: Thinned,
    dissipated: Thinned,
    slave_net: f64,
    dissipated_sum: f64,
    /// The stretches the operator's clutch was released, s (a 6-DoF run's).
    released: Stretches,
}

impl Series {
    /// Adds one row at its time.
    pub fn add(&mut self, row: &TraceRow, t_s: f64) {
        let t = row.n as f64 * t_s;
        if row.flags_f.intersects(Flags::RELEASED) {
            self.released.mark(t, t_s);
        }
        let low = |w: [f64; 3]| w.iter().copied().fold(f64::INFINITY, f64::min);
        if row.stepped {
            self.slave_net = row.port_net_s;
        }
        self.dissipated_sum += row.dissipated_m + row.dissipated_s;
        self.channel
            .push(t, 1e3 * (row.port_net_m + self.slave_net));
        self.observer_m.push(t, 1e3 * low(row.observer_m));
        let s = if row.stepped {
            1e3 * low(row.observer_s)
        } else {
            f64::NAN
        };
        self.observer_s.push(t, s);
        self.dissipated.push(t, 1e3 * self.dissipated_sum);
        for i in 0..3 {
            self.handle[i].push(t, row.handle[i]);
            self.tool[i].push(t, if row.stepped { row.tool[i] } else { f64::NAN });
            self.force[i].push(t, if row.stepped { row.h[i] } else { f64::NAN });
            self.felt[i].push(t, row.felt[i]);
        }
    }

    /// Writes `positions.svg`, `forces.svg` and `passivity.svg` into `out`.
    pub fn write(&self, out: &Path) -> PlotResult {
        // A plot that does not show every sample or every release says so.
        let thinned = if self.channel.thinned() {
            " (min and max per pixel column)"
        } else {
            ""
        };
        let merged = if self.released.merged() {
            " (merged to the plot's width)"
        } else {
            ""
        };
        let spans = self.released.spans();
        whole_svg(&out.join("positions.svg"), |p| {
            timeplot::time_series(
                p,
                (
                    &format!("Master handle and slave tool position{thinned}"),
                    "position (m)",
                ),
                &pairs(&self.handle, &self.tool, "master handle", "slave tool", ""),
                (spans, &format!("clutch released: the robot holds{merged}")),
            )
        })?;
        whole_svg(&out.join("forces.svg"), |p| {
            timeplot::time_series(
                p,
                (
                    &format!("Contact force (slave) and feedback force (master){thinned}"),
                    "force (N)",
                ),
                &pairs(&self.felt, &self.force, "felt", "slave h(n)", "F"),
                (
                    spans,
                    &format!("clutch released: the clutch spring is felt{merged}"),
                ),
            )
        })?;
        // No line here is another's reference: all are drawn plain.
        let grey = RGBColor(90, 90, 90);
        let plain =
            |label: &str, colour, t: &Thinned| (label.to_string(), colour, false, t.points());
        let lines = [
            plain("channel energy", COLOURS[0], &self.channel),
            plain(
                "master observer (lowest axis)",
                COLOURS[1],
                &self.observer_m,
            ),
            plain("slave observer (lowest axis)", COLOURS[2], &self.observer_s),
            plain("dissipated by the control", grey, &self.dissipated),
        ];
        whole_svg(&out.join("passivity.svg"), |p| {
            timeplot::time_series(
                p,
                (
                    &format!("Channel energy (below zero: the channel made energy), observers, dissipation{thinned}"),
                    "energy (mJ)",
                ),
                &lines,
                (&[], ""),
            )
        })
    }
}

/// Per axis, a full-colour line of `a` (the reference) and a lighter one of `b`.
fn pairs(a: &[Thinned; 3], b: &[Thinned; 3], la: &str, lb: &str, pre: &str) -> Vec<Line> {
    let mut v = Vec::new();
    for i in 0..3 {
        let name = |l: &str| format!("{pre}{} {l}", AXES[i]);
        v.push((name(la), COLOURS[i], true, a[i].points()));
        v.push((name(lb), COLOURS[i], false, b[i].points()));
    }
    v
}

/// Draws `path` by `draw` under its temporary name, renamed when whole (a report cut
/// short leaves the old plot or none, never half of one).
pub fn whole_svg(path: &Path, draw: impl FnOnce(&Path) -> PlotResult) -> PlotResult {
    crate::out::whole(path, draw)
}

/// Histogram of the system overhead per round trip, in microseconds.
pub fn overhead_histogram(lat: &Latency, path: &Path) -> PlotResult {
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let Some(p) = lat.percentiles() else {
        return root.present().map_err(err);
    };
    // Cut the axis at 1.5 x p99 so the body of the distribution stays visible; the
    // tail goes into the last bin (and is in the percentiles and the .hgrm file).
    let hi = (p.p99 as f64 / 1000.0).max(1.0) * 1.5;
    let bins = 100usize;
    let width = hi / bins as f64;
    let mut counts = vec![0u64; bins];
    for (v, n) in lat.counts() {
        let k = ((v as f64 / 1000.0 / width) as usize).min(bins - 1);
        counts[k] += n;
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

/// A percentile distribution as an `.hgrm` file gives it: (percentile as a fraction,
/// value in us) per line, the lines of the header and footer skipped.
pub fn read_hgrm(text: &str) -> Vec<(f64, f64)> {
    text.lines()
        .filter_map(|l| {
            let mut f = l.split_whitespace();
            let v: f64 = f.next()?.parse().ok()?;
            let q: f64 = f.next()?.parse().ok()?;
            (v.is_finite() && (0.0..=1.0).contains(&q)).then_some((q, v))
        })
        .collect()
}

/// Colours of the series of a plot with several (percentile lines, a sweep's lines).
pub(crate) const LOOP_COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// A series: label, colour, whether it is a reference (see `timeplot`), points.
type Line = (String, RGBColor, bool, Vec<(f64, f64)>);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_hgrm_file_reads_back_as_its_distribution() {
        let mut lat = Latency::default();
        for ns in 1..=10_000i64 {
            lat.record(ns * 1000);
        }
        let pts = read_hgrm(&lat.hgrm());
        assert!(pts.len() > 20);
        assert!(pts.windows(2).all(|w| w[0].0 <= w[1].0 && w[0].1 <= w[1].1));
        let (q, v) = pts[pts.len() - 1];
        assert_eq!(q, 1.0);
        assert!((v - 10_000.0).abs() < 10.0, "{v}");
        // The median sits near 5000 us.
        let mid = pts.iter().find(|p| p.0 >= 0.5).expect("median");
        assert!((mid.1 - 5000.0).abs() < 10.0, "{mid:?}");
        let dir = tempfile::tempdir().expect("tmp");
        let svg = dir.path().join("p.svg");
        percentile_plot(&svg, "t", &[("a".into(), pts)]).expect("plot");
        let text: String = std::fs::read_to_string(&svg)
            .expect("svg")
            .split_whitespace()
            .collect();
        for label in [">90%<", ">99.9%<", ">99.99%<", ">a<"] {
            assert!(text.contains(label), "{label}");
        }
    }

    /// A clutch flapping every sample: one grey band per release made a 45 MB SVG at
    /// 10^6 samples; merged to the plot's width, the file stays small and says so.
    #[test]
    fn a_flapping_clutch_makes_a_small_plot_that_says_it_was_merged() {
        let mut s = Series::default();
        for n in 0..200_000u64 {
            let row = TraceRow {
                n,
                flags_f: if n % 2 == 0 {
                    Flags::RELEASED
                } else {
                    Flags::NONE
                },
                ..TraceRow::default()
            };
            s.add(&row, 1e-3);
        }
        let dir = tempfile::tempdir().expect("tempdir");
        s.write(dir.path()).expect("plots");
        let svg = std::fs::read_to_string(dir.path().join("positions.svg")).expect("svg");
        assert!(svg.len() < 400_000, "{} bytes", svg.len());
        assert!(svg.contains("merged to the plot"), "the plot says so");
        assert!(svg.contains("min and max per pixel column"), "thinned too");
    }

    #[test]
    fn thinning_keeps_the_extremes_and_bounds_the_points() {
        let mut s = Thinned::default();
        let n = 1_000_000u64;
        for k in 0..n {
            let v = if k == 777_777 {
                50.0
            } else if k == 123_456 {
                -9.0
            } else {
                (k as f64 * 1e-3).sin()
            };
            s.push(k as f64, v);
        }
        let p = s.points();
        assert!(p.len() <= 2 * WIDTH as usize + 2, "{} points", p.len());
        let max = p.iter().map(|x| x.1).fold(f64::MIN, f64::max);
        let min = p.iter().map(|x| x.1).fold(f64::MAX, f64::min);
        assert_eq!((min, max), (-9.0, 50.0));
    }
}
