//! `[master.ros2.watch]` and `[slave.ros2.watch]`: when a device's or robot's samples
//! stop being trusted (stale, then lost).

use crate::shown::Num;
use crate::{invalid, positive, ScenarioError};
use serde::{Deserialize, Serialize};

/// When a device's samples stop being trusted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WatchConfig {
    /// A sample older than this many loop periods is stale: held and counted.
    pub stale_periods: u32,
    /// Silent this long, ms, the device is lost: the master renders zero force, the
    /// slave holds its last safe reference; counted, and the run goes on.
    pub timeout_ms: f64,
}

impl Default for WatchConfig {
    fn default() -> Self {
        WatchConfig {
            stale_periods: 3,
            timeout_ms: 100.0,
        }
    }
}

impl WatchConfig {
    pub(crate) fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        if self.stale_periods == 0 {
            return Err(invalid(
                format!("{field}.stale_periods"),
                "must be at least 1",
            ));
        }
        positive(self.timeout_ms, &format!("{field}.timeout_ms"), false)
    }

    /// The timeout must outlast the stale window, or loss would come only after it.
    pub fn validate_at(&self, field: &str, rate_hz: f64) -> Result<(), ScenarioError> {
        let stale_ms = f64::from(self.stale_periods) * 1e3 / rate_hz;
        if self.timeout_ms <= stale_ms {
            return Err(invalid(
                format!("{field}.timeout_ms"),
                format!(
                    "{} ms is not longer than the stale window ({} periods, {} ms)",
                    Num(self.timeout_ms),
                    self.stale_periods,
                    Num(stale_ms)
                ),
            ));
        }
        Ok(())
    }
}
