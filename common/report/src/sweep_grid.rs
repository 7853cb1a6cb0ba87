//! Whether two sweeps are one: their grids compared as values, not as text, so a
//! sweep started by the command and the same one started from Python (which writes
//! `"tdpa"` and `10.0` where a shell writes `tdpa` and `10`) resume each other, and
//! a value given twice is found whatever its spelling.

use crate::sweep::Axis;

/// True if `a` and `b` mean one value: equal, a whole number and a float counting
/// as equal numbers (`10` and `10.0`, as `--set` and Python write them), lists and
/// tables element by element.
pub fn same_value(a: &toml::Value, b: &toml::Value) -> bool {
    use toml::Value::{Array, Float, Integer, Table};
    match (a, b) {
        (Integer(x), Float(y)) | (Float(y), Integer(x)) => *x as f64 == *y,
        (Array(x), Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(p, q)| same_value(p, q))
        }
        (Table(x), Table(y)) => {
            x.len() == y.len()
                && x.iter()
                    .all(|(k, v)| y.get(k).is_some_and(|w| same_value(v, w)))
        }
        _ => a == b,
    }
}

/// True if two grids are one: the same keys in the same order, paired alike, each
/// with the same values ([`same_value`]), however they were written (`tdpa` or
/// `"tdpa"`, `1` or `1.0`, with spaces or without).
pub fn same_grid(a: &[Axis], b: &[Axis]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.key == y.key
                && x.paired == y.paired
                && x.sets.len() == y.sets.len()
                && x.sets
                    .iter()
                    .zip(&y.sets)
                    .all(|(p, q)| same_value(&p.value, &q.value))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::axis;

    #[test]
    fn one_grid_however_it_is_written() {
        let grid =
            |sets: &[&str]| -> Vec<Axis> { sets.iter().map(|s| axis(s).expect("axis")).collect() };
        let cli = grid(&[
            "network.forward.delay_ms=0,10",
            "control.kind=none,tdpa",
            "x=[1,2]",
        ]);
        let py = grid(&[
            "network.forward.delay_ms=0.0, 10",
            "control.kind=\"none\",\"tdpa\"",
            "x=[1.0,2]",
        ]);
        assert!(same_grid(&cli, &py));
        for other in [
            grid(&[
                "network.forward.delay_ms=0,11",
                "control.kind=none,tdpa",
                "x=[1,2]",
            ]),
            grid(&[
                "network.forward.delay_ms=0,10",
                "control.kind=tdpa,none",
                "x=[1,2]",
            ]),
            grid(&[
                "network.forward.delay_ms=0,10",
                "+control.kind=none,tdpa",
                "x=[1,2]",
            ]),
            grid(&["network.forward.delay_ms=0,10", "control.kind=none,tdpa"]),
            grid(&[
                "network.forward.delay_ms=0,10",
                "control.kind=none,tdpa",
                "x=[1,2,3]",
            ]),
            grid(&[
                "network.forward.delay_ms=0,10",
                "control.kind=none,tdpa",
                "x=\"[1,2]\"",
            ]),
        ] {
            assert!(!same_grid(&cli, &other), "{other:?}");
        }
    }
}
