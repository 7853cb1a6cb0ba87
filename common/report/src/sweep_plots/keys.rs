//! Which swept key goes where in a sweep's figures, and how its values read on an
//! axis. A key swept over one value is a setting, said once in the caption, never a
//! line or a panel; the first key that varies is the x axis, the next one the lines,
//! and every later one a panel of its own per value (small multiples), so no line ever
//! joins points that differ in a key it does not name.

use crate::sweep::{numeric, unit, Axis};

/// The role of each swept key, by its index among the axes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Roles {
    /// The keys with more than one value, in the order swept.
    pub varying: Vec<usize>,
    /// The keys swept over one value: settings, not variables.
    pub fixed: Vec<usize>,
}

impl Roles {
    /// The roles of `axes`.
    pub fn of(axes: &[Axis]) -> Roles {
        let (varying, fixed) = (0..axes.len()).partition(|&i| axes[i].values.len() > 1);
        Roles { varying, fixed }
    }

    /// The key on the x axis: the first that varies, else the first (a sweep of one
    /// combination still plots its point).
    pub fn x(&self) -> Option<usize> {
        self.varying.first().or(self.fixed.first()).copied()
    }

    /// The key with a line per value (none: one line).
    pub fn lines(&self) -> Option<usize> {
        self.varying.get(1).copied()
    }

    /// The keys with a panel per combination of their values (none: one panel).
    pub fn panels(&self) -> &[usize] {
        self.varying.get(2..).unwrap_or_default()
    }
}

/// `KEY=VALUE`, with the key's unit after a number: `network.forward.delay_ms=100 ms`,
/// `control.kind=tdpa`.
pub fn setting(axis: &Axis, i: usize) -> String {
    let v = &axis.values[i];
    match unit(&axis.key) {
        Some(u) => format!("{}={v} {u}", axis.key),
        None => format!("{}={v}", axis.key),
    }
}

/// The settings of the keys `which`, each at its value in `combo` (`None`: its only
/// value), joined for a caption.
pub fn settings(axes: &[Axis], which: &[usize], combo: Option<&[usize]>) -> String {
    let parts: Vec<String> = which
        .iter()
        .map(|&a| setting(&axes[a], combo.map_or(0, |c| c[a])))
        .collect();
    parts.join(", ")
}

/// Every combination of the values of the keys `which` (the first varying slowest),
/// as a full combination's indices where only those keys' count.
pub fn sub_combinations(axes: &[Axis], which: &[usize]) -> Vec<Vec<usize>> {
    let mut out = vec![vec![0; axes.len()]];
    for &a in which {
        out = out
            .into_iter()
            .flat_map(|c| {
                (0..axes[a].values.len()).map(move |i| {
                    let mut c = c.clone();
                    c[a] = i;
                    c
                })
            })
            .collect();
    }
    out
}

/// Where a key's values sit on an axis.
#[derive(Debug, Clone, PartialEq)]
pub enum Scale {
    /// At their numbers (each distinct: a number, or a vector of one number repeated).
    Numbers(Vec<f64>),
    /// At 0, 1, 2, ..., each labelled as written: words, vectors of different
    /// elements, or numbers that would coincide.
    Categories(Vec<String>),
}

impl Scale {
    /// The scale of `axis`'s values.
    pub fn of(axis: &Axis) -> Scale {
        let nums: Option<Vec<f64>> = axis.values.iter().map(|v| numeric(v)).collect();
        match nums {
            Some(n) if distinct(&n) => Scale::Numbers(n),
            _ => Scale::Categories(axis.values.clone()),
        }
    }

    /// Where value `i` sits.
    pub fn at(&self, i: usize) -> f64 {
        match self {
            Scale::Numbers(n) => n[i],
            Scale::Categories(_) => i as f64,
        }
    }
}

fn distinct(v: &[f64]) -> bool {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s.windows(2).all(|w| w[0] != w[1])
}

/// A swept number as a tick reads it: as short as it is exact (`100`, `0.5`, `1e-6`).
pub fn number(x: f64) -> String {
    if x == 0.0 {
        "0".to_string()
    } else if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{x:.0}")
    } else {
        format!("{x}")
    }
}

/// The fewest decimals (at most 12) that write every tick of `ticks` as itself, to a
/// thousandth of the smallest gap between them: 0 for `0, 50, 100`, 1 for `0, 0.5`, 2
/// for `0, 0.25, 0.5`.
pub fn decimals(ticks: &[f64]) -> usize {
    let mut sorted = ticks.to_vec();
    sorted.sort_by(f64::total_cmp);
    let gap = sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|g| *g > 0.0)
        .fold(f64::INFINITY, f64::min);
    let tolerance = if gap.is_finite() { gap * 1e-3 } else { 0.0 };
    (0..12)
        .find(|&d| {
            ticks.iter().all(|t| {
                let back: f64 = format!("{t:.d$}").parse().unwrap_or(f64::NAN);
                (back - t).abs() <= tolerance
            })
        })
        .unwrap_or(12)
}

/// A tick at `x` with `d` decimals, never `-0`.
pub fn fixed(x: f64, d: usize) -> String {
    let s = format!("{x:.d$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::axis;

    #[test]
    fn a_key_of_one_value_is_a_setting_and_the_next_varying_key_the_x_axis() {
        let axes = [
            axis("samples=16000").expect("a"),
            axis("operator.move_s=1,2").expect("b"),
            axis("network.forward.delay_ms=100").expect("c"),
            axis("control.kind=tdpa,wave").expect("d"),
            axis("seed=1,2,3").expect("e"),
        ];
        let r = Roles::of(&axes);
        assert_eq!((r.x(), r.lines(), r.panels()), (Some(1), Some(3), &[4][..]));
        assert_eq!(r.fixed, [0, 2]);
        assert_eq!(
            settings(&axes, &r.fixed, None),
            "samples=16000, network.forward.delay_ms=100 ms"
        );
        assert_eq!(sub_combinations(&axes, r.panels()).len(), 3);
    }

    #[test]
    fn words_vectors_of_different_elements_and_coinciding_numbers_are_categories() {
        let scale = |s: &str| Scale::of(&axis(s).expect("axis"));
        assert_eq!(
            scale("network.forward.delay=[0,0,0],[10,10,10]"),
            Scale::Numbers(vec![0.0, 10.0])
        );
        assert_eq!(
            scale("control.kind=none,tdpa"),
            Scale::Categories(vec!["none".into(), "tdpa".into()])
        );
        assert!(matches!(
            scale("network.forward.delay=[0,3,6],[3,3,3]"),
            Scale::Categories(_)
        ));
        assert!(matches!(scale("rate_hz=1000,1e3"), Scale::Categories(_)));
    }

    #[test]
    fn ticks_read_as_short_as_they_are_exact() {
        assert_eq!(number(100.0), "100");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(-0.0), "0");
        assert_eq!(decimals(&[0.0, 50.0, 100.0]), 0);
        assert_eq!(decimals(&[0.0, 0.5, 1.0]), 1);
        assert_eq!(decimals(&[0.0, 0.25, 0.5]), 2);
        assert_eq!(decimals(&[0.002, 0.004]), 3);
        assert_eq!(fixed(-1e-17, 2), "0.00");
        assert_eq!(fixed(-0.5, 1), "-0.5");
    }
}
