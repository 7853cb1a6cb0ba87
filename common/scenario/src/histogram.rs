//! `delay_histogram = { path = "...", format = "...", correlation = C }` (or `{ name =
//! "..." }`, a shipped one): each packet's whole delay drawn from a measured
//! distribution, a histogram file. The drawing is `tactile-netem`'s; the settings, the
//! formats and the histograms shipped with Tactile are here (the shipped ones compiled
//! in, so a name means the same bins from any folder, in a clone or a wheel, and a
//! run's `scenario.toml` reruns anywhere).

use crate::shown::{listed, Num};
use crate::{invalid, ScenarioError};
use serde::{Deserialize, Serialize};

/// Where a channel's delays are drawn from: a file or a shipped histogram, and the
/// correlation of successive packets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HistogramConfig {
    /// The file, relative to the scenario's folder (as `replay.path`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    /// A histogram shipped with Tactile ([`SHIPPED_HISTOGRAMS`]) instead of a file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The file's format, with `path` only [csv].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<HistogramFormat>,
    /// Correlation of successive packets' delays, 0 to 1 (lag-1, of the driving
    /// Gaussian process, as `jitter.correlation`) [0].
    #[serde(default)]
    pub correlation: f64,
}

/// Histogram files. In each, a line gives a bin's lower edge and its count; the bin
/// reaches to the next line's edge, and the last line only closes the last bin (its
/// count must be 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum HistogramFormat {
    /// A header `delay_ms,count`, then one bin a line: its lower edge in ms, its count.
    #[default]
    Csv,
    /// DETERMINISTIC6G's NetworkDelayEmulator (`userspace_delay`): no header, one bin
    /// a line, `lower,count,unit` (unit `ns`, `us`, `ms` or `s`; its emulator wants ns).
    D6g,
    /// The raw files of the `deterministic6g_data` repository: no header, one bin a
    /// line, its lower edge in ms, a TAB, its (relative) count.
    D6gData,
}

/// One histogram shipped with Tactile: its name, its file under `deploy/networks/`
/// (unmodified; `deploy/networks/PROVENANCE` says where it comes from), the file's
/// format and text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShippedHistogram {
    /// What `delay_histogram = { name = "..." }` takes.
    pub name: &'static str,
    /// The file, relative to `deploy/networks/`.
    pub file: &'static str,
    /// Its format.
    pub format: HistogramFormat,
    /// Its text.
    pub text: &'static str,
}

macro_rules! shipped {
    ($name:literal, $file:literal) => {
        ShippedHistogram {
            name: $name,
            file: $file,
            format: HistogramFormat::D6gData,
            text: include_str!(concat!("../../../deploy/networks/", $file)),
        }
    };
}

/// The 5G delay histograms of DETERMINISTIC6G: a 28 GHz URLLC network and a 3.7 GHz
/// one, each direction.
pub const SHIPPED_HISTOGRAMS: [ShippedHistogram; 4] = [
    shipped!(
        "5g-28ghz-urllc-downlink",
        "deterministic6g/PD-Wireless-5G-3a/5G-URLLC-mmW-Downlink_PD-Wireless-5G-3a.csv"
    ),
    shipped!(
        "5g-28ghz-urllc-uplink",
        "deterministic6g/PD-Wireless-5G-3a/5G-URLLC-mmW-Uplink_PD-Wireless-5G-3a.csv"
    ),
    shipped!(
        "5g-3.7ghz-downlink",
        "deterministic6g/PD-Wireless-5G-2a/5G-midband-Downlink_PD-Wireless-5G-2a.csv"
    ),
    shipped!(
        "5g-3.7ghz-uplink",
        "deterministic6g/PD-Wireless-5G-2a/5G-midband-Uplink_PD-Wireless-5G-2a.csv"
    ),
];

/// The shipped histogram of that name.
pub fn shipped_histogram(name: &str) -> Option<&'static ShippedHistogram> {
    SHIPPED_HISTOGRAMS.iter().find(|h| h.name == name)
}

impl HistogramConfig {
    /// Checks the fields; errors name `FIELD.delay_histogram.*`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        let f = |k: &str| format!("{field}.delay_histogram.{k}");
        let names = || listed(SHIPPED_HISTOGRAMS.iter().map(|h| h.name));
        match (&self.path, &self.name) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    f("name"),
                    "and `path` both set: give a file (path) or a shipped histogram (name)",
                ))
            }
            (None, None) => {
                return Err(invalid(
                    format!("{field}.delay_histogram"),
                    format!(
                        "has neither `path` (a histogram file) nor `name` (a shipped one: {})",
                        names()
                    ),
                ))
            }
            (Some(p), None) if p.is_empty() => return Err(invalid(f("path"), "is empty")),
            (None, Some(n)) if shipped_histogram(n).is_none() => {
                return Err(invalid(
                    f("name"),
                    format!("{n:?} is no shipped histogram; they are {}", names()),
                ))
            }
            (None, Some(_)) if self.format.is_some() => {
                return Err(invalid(
                    f("format"),
                    "is for a file (`path`): a shipped histogram's format is known",
                ))
            }
            _ => {}
        }
        let c = self.correlation;
        if !c.is_finite() || !(0.0..1.0).contains(&c) {
            return Err(invalid(
                f("correlation"),
                format!("{} is outside [0, 1)", Num(c)),
            ));
        }
        Ok(())
    }
}
