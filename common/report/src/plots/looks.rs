//! How the lines of a plot with several series stay apart where they coincide (two
//! controls with the same metric at a point, a round trip that is all overhead): each
//! series has its own colour, dash pattern and marker, and the series drawn first is
//! the widest, so a later one, drawn over it, is narrower and leaves its edges showing
//! (the one drawn last would otherwise hide the others).

use super::{err, PlotResult, LOOP_COLOURS};
use plotters::coord::ranged1d::Ranged;
use plotters::element::{DashedPathElement, Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::{BackendCoord, DrawingErrorKind};

/// Dash and gap lengths, pixels, per series (solid first): at most a few dozen
/// points per sweep line, and a percentile line of a few hundred, so the dashes stay
/// few.
const DASHES: [Option<(u32, u32)>; 6] = [
    None,
    Some((12, 6)),
    Some((5, 4)),
    Some((2, 4)),
    Some((16, 4)),
    Some((3, 9)),
];

/// The marker shapes, in series order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Marker {
    /// A filled circle.
    Circle,
    /// A filled triangle.
    Triangle,
    /// A filled square.
    Square,
    /// An upright cross.
    Cross,
    /// A hollow circle.
    Ring,
}

const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Triangle,
    Marker::Square,
    Marker::Cross,
    Marker::Ring,
];

/// Widest line and largest marker over the narrowest: the first of 5 series or more
/// is drawn 4 px wider than the last.
const SPREAD: usize = 4;

/// The look of series `k` of `n`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Look {
    /// Its colour.
    pub colour: RGBColor,
    /// Its line's width, pixels: the first drawn widest.
    pub width: u32,
    /// Its dash and gap, or solid.
    pub dash: Option<(u32, u32)>,
    /// Its marker.
    pub marker: Marker,
    /// The marker's size, pixels: the first drawn largest.
    pub size: u32,
}

/// Series `k` of `n`.
pub(crate) fn look(k: usize, n: usize) -> Look {
    let wider = n.saturating_sub(1 + k).min(SPREAD) as u32;
    Look {
        colour: LOOP_COLOURS[k % LOOP_COLOURS.len()],
        width: 2 + wider,
        dash: DASHES[k % DASHES.len()],
        marker: MARKERS[k % MARKERS.len()],
        size: 4 + wider,
    }
}

impl Look {
    /// The line's style.
    pub fn style(&self) -> ShapeStyle {
        ShapeStyle::from(self.colour).stroke_width(self.width)
    }
}

/// Draws `pts` as a line in `look`, with its legend entry `label`.
pub(crate) fn draw_line<'a, DB, X>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, impl Ranged<ValueType = f64>>>,
    pts: Vec<(f64, f64)>,
    look: &Look,
    label: &str,
) -> PlotResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64>,
{
    let style = look.style();
    let anno = match look.dash {
        None => chart.draw_series(LineSeries::new(pts, style)),
        Some((on, off)) => chart.draw_series(DashedLineSeries::new(pts, on, off, style)),
    }
    .map_err(err)?;
    // A solid line's legend is one dash as long as the legend's line.
    let (on, off) = look.dash.unwrap_or((24, 1));
    anno.label(label)
        .legend(move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 24, y)], on, off, style));
    Ok(())
}

/// Draws the series' legend at `at`, framed, on a white ground of opacity `ground`.
pub(crate) fn draw_legend<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    at: SeriesLabelPosition,
    ground: f64,
) -> PlotResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged,
    Y: Ranged,
{
    chart
        .configure_series_labels()
        .position(at)
        .background_style(WHITE.mix(ground))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

/// A text's width in pixels in a sans-serif font of `size` (as plotters takes it: it
/// writes `size / 1.24` px type), about: an average character is 0.45 of the size,
/// a little over what the renderers draw. Where a label fits, where a legend's
/// columns go.
pub(crate) fn text_w(s: &str, size: u32) -> i32 {
    (s.chars().count() as f64 * size as f64 * 0.45).ceil() as i32
}

/// A marker in `look` at a point in any coordinates (a chart's, or a legend's
/// pixels): the shape is drawn in pixels around where the point lands.
#[derive(Debug, Clone)]
pub(crate) struct MarkerAt<C> {
    at: C,
    look: Look,
}

/// The marker of `look` at `at`.
pub(crate) fn marker<C>(at: C, look: &Look) -> MarkerAt<C> {
    MarkerAt { at, look: *look }
}

impl<'a, C> PointCollection<'a, C> for &'a MarkerAt<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for MarkerAt<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut pos: I,
        backend: &mut DB,
        dim: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some(p) = pos.next() else {
            return Ok(());
        };
        let (s, style) = (self.look.size, self.look.style());
        let half = s as i32 - 1;
        let at = std::iter::once(p);
        match self.look.marker {
            Marker::Circle => Circle::new(p, s, style.filled()).draw(at, backend, dim),
            Marker::Ring => Circle::new(p, s, style.stroke_width(2)).draw(at, backend, dim),
            Marker::Triangle => {
                TriangleMarker::new(p, s + 1, style.filled()).draw(at, backend, dim)
            }
            Marker::Cross => Cross::new(p, s, style.stroke_width(2)).draw(at, backend, dim),
            Marker::Square => {
                let corners = [(p.0 - half, p.1 - half), (p.0 + half, p.1 + half)];
                Rectangle::new(corners, style.filled()).draw(corners.into_iter(), backend, dim)
            }
        }
    }
}

/// Reading a plot's SVG back, for tests: its texts and its lines' styles.
#[cfg(test)]
pub(crate) mod svg {
    use std::collections::BTreeMap;

    /// Every `<text>` element's content, trimmed.
    pub fn texts(svg: &str) -> Vec<String> {
        svg.split("</text>")
            .filter_map(|s| s.rsplit_once('>').map(|(_, t)| t.trim().to_string()))
            .filter(|t| !t.is_empty())
            .collect()
    }

    /// The value of attribute `name` in element text `el`.
    fn attr<'a>(el: &'a str, name: &str) -> Option<&'a str> {
        let at = el.find(&format!(" {name}=\""))? + name.len() + 3;
        el[at..].split('"').next()
    }

    /// The integer value of attribute `name` in element text `el`.
    pub fn int_attr(el: &str, name: &str) -> Option<i32> {
        attr(el, name)?.parse().ok()
    }

    /// Every `<text>`'s content, trimmed, with its x and y.
    pub fn placed(svg: &str) -> Vec<(String, i32, i32)> {
        svg.split("<text")
            .skip(1)
            .filter_map(|el| {
                let (open, rest) = el.split_once('>')?;
                let body = rest.split("</text>").next()?.trim();
                Some((body.to_string(), int_attr(open, "x")?, int_attr(open, "y")?))
            })
            .collect()
    }

    /// Per stroke colour of the `<polyline>`s drawn in it: how many, and their widths.
    pub fn polylines(svg: &str) -> BTreeMap<String, (usize, Vec<String>)> {
        let mut out: BTreeMap<String, (usize, Vec<String>)> = BTreeMap::new();
        for el in svg.split("<polyline").skip(1) {
            let (Some(c), Some(w)) = (attr(el, "stroke"), attr(el, "stroke-width")) else {
                continue;
            };
            let e = out.entry(c.to_string()).or_default();
            e.0 += 1;
            if !e.1.iter().any(|x| x == w) {
                e.1.push(w.to_string());
            }
        }
        out
    }

    /// The kinds of element (`circle`, `polygon`, `rect`, `line`) drawn filled or
    /// stroked in `colour`.
    pub fn shapes(svg: &str, colour: &str) -> Vec<&'static str> {
        let mut out = Vec::new();
        for tag in ["circle", "polygon", "rect", "line"] {
            let drawn = svg.split(&format!("<{tag} ")).skip(1).any(|el| {
                let el = el.split('>').next().unwrap_or_default();
                attr(el, "fill") == Some(colour) || attr(el, "stroke") == Some(colour)
            });
            if drawn {
                out.push(tag);
            }
        }
        out
    }
}
