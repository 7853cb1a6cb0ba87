//! `[cordic]` and `device`: the hybrid arithmetic's fixed-point format and the arms'
//! geometry, as the scenario gives them.

use crate::{invalid, ScenarioError};
use serde::{Deserialize, Serialize};
use tactile_math::cordic::{CordicConfig, Rounding};
use tactile_math::geometry::{Geometry, GeometryError};

/// CORDIC settings in a scenario; missing keys take the [s16.13] defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CordicSettings {
    /// Word length V of [sV.N].
    pub word: u32,
    /// Fractional bits N.
    pub frac: u32,
    /// Iterations; default derived from `frac`.
    pub iterations: Option<u32>,
    /// `truncate` or `nearest`.
    pub rounding: Rounding,
}

impl Default for CordicSettings {
    fn default() -> Self {
        CordicSettings {
            word: CordicConfig::S16_13.word,
            frac: CordicConfig::S16_13.frac,
            iterations: None,
            rounding: CordicConfig::S16_13.rounding,
        }
    }
}

impl CordicSettings {
    /// The validated configuration.
    pub fn config(&self) -> Result<CordicConfig, ScenarioError> {
        CordicConfig::new(self.word, self.frac, self.iterations, self.rounding)
            .map_err(|e| invalid("cordic", e.to_string()))
    }
}

/// A device preset (`"paper"`, `"omni"`) or explicit lengths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum DeviceChoice {
    /// `device = "paper"`.
    Preset(String),
    /// `[device]` with `l1`, `l2`, `l3`, `a`.
    Lengths(Geometry),
}

impl Default for DeviceChoice {
    fn default() -> Self {
        DeviceChoice::Preset("paper".into())
    }
}

impl DeviceChoice {
    /// The validated geometry.
    pub fn geometry(&self) -> Result<Geometry, ScenarioError> {
        match self {
            DeviceChoice::Preset(name) => Geometry::preset(name).ok_or_else(|| {
                invalid(
                    "device",
                    format!("unknown preset {name:?}: expected \"paper\", \"omni\" or a table with l1, l2, l3, a"),
                )
            }),
            DeviceChoice::Lengths(g) => {
                g.validate().map_err(|e| invalid("device", e.to_string()))?;
                Ok(*g)
            }
        }
    }
}

/// A device file (`--device FILE.toml`, or a scenario's `[device]` table): `l1`, `l2`,
/// `l3`, `a` in metres, parsed and validated.
pub fn geometry_from_toml(text: &str) -> Result<Geometry, GeometryError> {
    let g: Geometry =
        toml::from_str(text).map_err(|e| GeometryError::Parse(crate::one_line(text, &e)))?;
    g.validate()?;
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_round_trip_and_errors() {
        let g = geometry_from_toml("l1 = 0.1\nl2 = 0.12\nl3 = 0.02\na = 0.03\n");
        assert_eq!(
            g,
            Ok(Geometry {
                l1: 0.1,
                l2: 0.12,
                l3: 0.02,
                a: 0.03
            })
        );
        let unknown = geometry_from_toml("l1 = 0.1\nl2 = 0.1\nl3 = 0\na = 0\nl5 = 1\n");
        assert!(matches!(unknown, Err(GeometryError::Parse(m)) if m.contains("l5")));
        let mm = geometry_from_toml("l1 = 132.0\nl2 = 0.1\nl3 = 0.0\na = 0.0\n");
        assert!(matches!(
            mm,
            Err(GeometryError::BadLength { field: "l1", .. })
        ));
        let neg = geometry_from_toml("l1 = 0.1\nl2 = 0.1\nl3 = -0.1\na = 0.0\n");
        assert!(matches!(
            neg,
            Err(GeometryError::BadLength { field: "l3", .. })
        ));
    }
}
