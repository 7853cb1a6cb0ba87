//! Device geometry of a PHANToM Omni class 3-DoF arm.
//!
//! The paper's figure names four lengths: the two arm segments `L1` and `L2`, the
//! offset `L3` of the first joint above the base, and `L4 = L1 + A`. The paper's text
//! gives `L1 = 0.135` "mm" (it means metres), but the waypoints printed in its Results
//! section are reproduced exactly only by `L1 = L2 = 0.132 m` (the paper's errata: docs/08-kernels-and-the-paper.md).
//! Hence two presets: [`Geometry::PAPER`] reproduces the paper's results, and
//! [`Geometry::OMNI`] carries the published Omni lengths.

use crate::arith::Real;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Link lengths in metres. Loaded from TOML with exactly these four keys.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// Upper arm segment `L1`, metres.
    pub l1: f64,
    /// Forearm segment `L2`, metres.
    pub l2: f64,
    /// Height offset `L3` of the shoulder, metres.
    pub l3: f64,
    /// Offset `A` in `L4 = L1 + A`, metres.
    pub a: f64,
}

/// A geometry that cannot describe an arm.
#[derive(Debug, Error, PartialEq)]
pub enum GeometryError {
    /// A length is NaN, infinite, negative (or zero for a segment), or absurdly long.
    #[error("field `{field}` = {value}: {problem}")]
    BadLength {
        /// The TOML key.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// The TOML text did not parse into the four lengths.
    #[error("{0}")]
    Parse(String),
}

impl Geometry {
    /// Lengths that reproduce the paper's published waypoints.
    pub const PAPER: Geometry = Geometry {
        l1: 0.132,
        l2: 0.132,
        l3: 0.025,
        a: 0.035,
    };
    /// Published PHANToM Omni lengths (the paper's text, in metres).
    pub const OMNI: Geometry = Geometry {
        l1: 0.135,
        l2: 0.135,
        l3: 0.025,
        a: 0.035,
    };

    /// Longest segment accepted: beyond this a file almost surely used millimetres.
    pub const MAX_LENGTH_M: f64 = 10.0;

    /// `L4 = L1 + A`.
    pub fn l4(&self) -> f64 {
        self.l1 + self.a
    }

    /// A preset by name (`paper` or `omni`).
    pub fn preset(name: &str) -> Option<Geometry> {
        match name {
            "paper" => Some(Self::PAPER),
            "omni" => Some(Self::OMNI),
            _ => None,
        }
    }

    /// Checks every length is finite, within range, and the segments are non-zero.
    pub fn validate(&self) -> Result<(), GeometryError> {
        let fields = [
            ("l1", self.l1, true),
            ("l2", self.l2, true),
            ("l3", self.l3, false),
            ("a", self.a, false),
        ];
        for (field, value, segment) in fields {
            let problem = if !value.is_finite() {
                Some("must be a finite number of metres")
            } else if value < 0.0 {
                Some("must not be negative")
            } else if segment && value == 0.0 {
                Some("an arm segment must be longer than zero")
            } else if value > Self::MAX_LENGTH_M {
                Some("longer than 10 m: lengths are in metres, not millimetres")
            } else {
                None
            };
            if let Some(problem) = problem {
                return Err(GeometryError::BadLength {
                    field,
                    value,
                    problem,
                });
            }
        }
        Ok(())
    }

    /// The lengths rounded to the kernel's scalar type (f32 constants in the FPGA).
    pub fn lengths<R: Real>(&self) -> Lengths<R> {
        Lengths {
            l1: R::from_f64(self.l1),
            l2: R::from_f64(self.l2),
            l3: R::from_f64(self.l3),
            l4: R::from_f64(self.l4()),
        }
    }
}

/// The constants a kernel multiplies by, in its own scalar type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lengths<R> {
    /// `L1`.
    pub l1: R,
    /// `L2`.
    pub l2: R,
    /// `L3`.
    pub l3: R,
    /// `L4 = L1 + A`.
    pub l4: R,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate() {
        assert_eq!(Geometry::PAPER.validate(), Ok(()));
        assert_eq!(Geometry::OMNI.validate(), Ok(()));
        assert!((Geometry::PAPER.l4() - 0.167).abs() < 1e-15);
    }
}
