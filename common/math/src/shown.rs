//! Values as error messages show them: a number in its shortest form that reads back
//! the same (`1e308`, not 309 digits; `0.001`, not `1e-3`), a list of names cut to its
//! first few (`a, b, ... and 9990 more`), so a message stays one readable line
//! whatever a user's file holds.
//!
//! Why here, in the math crate: both crates that word errors about a user's files
//! need it, `tactile-scenario` (fields beyond their bounds) and `tactile-chain` (a
//! URDF's values and names), and neither depends on the other. `tactile-math` is
//! already a dependency of the scenario crate and of every crate that uses the
//! chain, it is pure (no I/O) and light (serde, thiserror), so the chain depending on
//! it couples least: making the scenario crate depend on the chain would pull
//! nalgebra and roxmltree into every node, and a crate of its own for two functions
//! would be one more crate to build and keep. `tactile_scenario::shown` re-exports
//! this module.

use std::fmt;

/// Names a message lists before it says how many more there are.
pub const NAMES_SHOWN: usize = 10;

/// A number as a message shows it: Rust's shortest round-trip form, with an exponent
/// only where plain digits would be long (past 1e16 or under 1e-4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // `Debug` for f64 is the shortest round trip, switching to an exponent at the
        // extremes; `Display` never does (1e308 is 309 digits).
        let text = format!("{:?}", self.0);
        f.write_str(text.strip_suffix(".0").unwrap_or(&text))
    }
}

/// `names` joined by `, `, the first [`NAMES_SHOWN`] only, then `... and N more`.
pub fn listed<S: AsRef<str>>(names: impl IntoIterator<Item = S>) -> String {
    let mut shown = Vec::new();
    let mut more = 0usize;
    for n in names {
        if shown.len() < NAMES_SHOWN {
            shown.push(n.as_ref().to_string());
        } else {
            more += 1;
        }
    }
    let mut s = shown.join(", ");
    if more > 0 {
        s.push_str(&format!(", ... and {more} more"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_exact() {
        let shown: Vec<String> = [1e308, -1e-300, 0.1, 1.0, 2.5, 1e16, 123456.789, f64::NAN]
            .iter()
            .map(|v| Num(*v).to_string())
            .collect();
        assert_eq!(
            shown,
            [
                "1e308",
                "-1e-300",
                "0.1",
                "1",
                "2.5",
                "1e16",
                "123456.789",
                "NaN"
            ]
        );
        for v in [1e308, 3.0e-7, 0.1 + 0.2, -42.125] {
            assert_eq!(Num(v).to_string().parse::<f64>(), Ok(v));
        }
    }

    #[test]
    fn a_long_list_is_cut() {
        let names: Vec<String> = (0..10_000).map(|k| format!("j{k}")).collect();
        let s = listed(&names);
        assert_eq!(
            s,
            "j0, j1, j2, j3, j4, j5, j6, j7, j8, j9, ... and 9990 more"
        );
        assert_eq!(listed(["a", "b"]), "a, b");
        assert_eq!(listed(Vec::<&str>::new()), "");
    }
}
