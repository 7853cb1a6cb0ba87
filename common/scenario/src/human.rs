//! `[master.human]`: what makes the simulated operator behave like a person where a
//! seed should matter: physiological tremor, a slow wander off the path, and a
//! reaction to a felt force that comes a reaction time after the force does. All off
//! by default, so a scenario without the table runs as it always has.
//!
//! Published ranges the defaults and bounds come from:
//! - Tremor: hand tremor has an RMS amplitude of about 50 to 200 um, in the 8 to 12 Hz
//!   band (MacLachlan, Riviere et al., "Characterization of physiological tremor in
//!   multiple environments", 2013: pmc.ncbi.nlm.nih.gov/articles/PMC3989364, which
//!   measured 144 um 3-D RMS for an unconstrained pointing task).
//! - Reaction: a voluntary response to a mechanical perturbation of the hand begins
//!   about 100 to 150 ms after it, the long-latency reflex at 50 to 100 ms before it
//!   (Pruszynski and Scott, "Optimal feedback control and the long-latency stretch
//!   response", Exp. Brain Res. 218, 2012).

use crate::shown::Num;
use crate::{invalid, positive, ScenarioError};
use serde::{Deserialize, Serialize};

/// What the operator does a reaction time after a felt force crosses `contact_n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Response {
    /// Stop following the path for `pause_ms`, then go on (a person confirming the
    /// contact before continuing: pushing a box goes on, with a hesitation).
    #[default]
    Pause,
    /// Stop following the path while the force is felt (above half `contact_n`), and
    /// go on once it is gone: a press stops where contact was noticed.
    Stop,
    /// Back off `back_off_mm` along the felt force over `back_off_ms`, hold for
    /// `pause_ms`, then return onto the path over `back_off_ms` while it goes on.
    BackOff,
}

/// `[master.human]`: tremor, wander and reaction, each drawn from the run's seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HumanConfig {
    /// Physiological tremor, RMS per axis, um [0: none; a person's: 50 to 200].
    pub tremor_um: f64,
    /// The tremor band's centre, Hz [10: physiological tremor is 8 to 12 Hz].
    pub tremor_hz: f64,
    /// The band's width (half power), Hz [4].
    pub tremor_band_hz: f64,
    /// A slow wander off the path, RMS per axis, mm [0: none].
    pub drift_mm: f64,
    /// The wander's correlation time, s [1].
    pub drift_s: f64,
    /// The mean reaction time to a felt force, ms [0: no reaction].
    pub reaction_ms: f64,
    /// The reaction time's spread (log-normal, so never negative), ms [30].
    pub reaction_sd_ms: f64,
    /// The felt force the operator notices, N [1].
    pub contact_n: f64,
    /// What the operator then does: `pause` (the default), `stop` or `back_off`.
    pub response: Response,
    /// How long a `pause` or a `back_off` holds, ms [250].
    pub pause_ms: f64,
    /// How far a `back_off` retreats, mm [2].
    pub back_off_mm: f64,
    /// How long a `back_off`'s retreat and return each take, ms [200].
    pub back_off_ms: f64,
}

impl Default for HumanConfig {
    fn default() -> Self {
        HumanConfig {
            tremor_um: 0.0,
            tremor_hz: 10.0,
            tremor_band_hz: 4.0,
            drift_mm: 0.0,
            drift_s: 1.0,
            reaction_ms: 0.0,
            reaction_sd_ms: 30.0,
            contact_n: 1.0,
            response: Response::Pause,
            pause_ms: 250.0,
            back_off_mm: 2.0,
            back_off_ms: 200.0,
        }
    }
}

impl HumanConfig {
    /// True when the table changes nothing (the default): the operator is the path.
    pub fn is_off(&self) -> bool {
        self.tremor_um == 0.0 && self.drift_mm == 0.0 && self.reaction_ms == 0.0
    }

    /// Checks the ranges against the loop's rate (the tremor must be below its
    /// Nyquist frequency); errors name `master.human.*`.
    pub fn validate(&self, rate_hz: f64) -> Result<(), ScenarioError> {
        let at_most = |v: f64, field: &str, max: f64, unit: &str| {
            positive(v, &format!("master.human.{field}"), true)?;
            if v > max {
                return Err(invalid(
                    format!("master.human.{field}"),
                    format!("{} {unit} is above {} {unit}", Num(v), Num(max)),
                ));
            }
            Ok(())
        };
        at_most(self.tremor_um, "tremor_um", 5_000.0, "um")?;
        at_most(self.drift_mm, "drift_mm", 50.0, "mm")?;
        at_most(self.reaction_ms, "reaction_ms", 2_000.0, "ms")?;
        at_most(self.reaction_sd_ms, "reaction_sd_ms", 1_000.0, "ms")?;
        at_most(self.pause_ms, "pause_ms", 10_000.0, "ms")?;
        at_most(self.back_off_mm, "back_off_mm", 50.0, "mm")?;
        at_most(self.back_off_ms, "back_off_ms", 5_000.0, "ms")?;
        positive(self.drift_s, "master.human.drift_s", false)?;
        positive(self.contact_n, "master.human.contact_n", false)?;
        positive(self.tremor_band_hz, "master.human.tremor_band_hz", false)?;
        let nyquist = rate_hz / 2.0;
        let top = self.tremor_hz + self.tremor_band_hz / 2.0;
        let bad = !self.tremor_hz.is_finite() || self.tremor_hz <= 0.0;
        if bad || (self.tremor_um > 0.0 && top >= nyquist) {
            return Err(invalid(
                "master.human.tremor_hz",
                format!(
                    "{} Hz (band {} Hz) must be positive and its band below the loop's Nyquist frequency, {} Hz",
                    Num(self.tremor_hz),
                    Num(self.tremor_band_hz),
                    Num(nyquist)
                ),
            ));
        }
        if self.response == Response::BackOff && self.back_off_ms == 0.0 {
            return Err(invalid(
                "master.human.back_off_ms",
                "must be positive with response = \"back_off\"",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::Scenario;

    fn refused(toml: &str) -> String {
        match Scenario::from_toml_str(toml) {
            Ok(_) => panic!("accepted: {toml}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn bad_values_are_refused_naming_the_field() {
        for (toml, field) in [
            ("[master.human]\ntremor_um = -1.0", "master.human.tremor_um"),
            ("[master.human]\ntremor_um = nan", "master.human.tremor_um"),
            ("[master.human]\ndrift_mm = 1e9", "master.human.drift_mm"),
            ("[master.human]\ndrift_s = 0.0", "master.human.drift_s"),
            ("[master.human]\ncontact_n = 0.0", "master.human.contact_n"),
            (
                "[master.human]\nreaction_ms = 1e5",
                "master.human.reaction_ms",
            ),
            // 100 Hz: a 10 Hz tremor fits, a 49 Hz one's band does not.
            (
                "[master.human]\ntremor_um = 100.0\ntremor_hz = 49.0",
                "master.human.tremor_hz",
            ),
            (
                "[master.human]\nresponse = \"back_off\"\nback_off_ms = 0.0",
                "master.human.back_off_ms",
            ),
            ("[master.human]\nresponse = \"flee\"", "response"),
            ("[master.human]\ntremor = 1.0", "tremor"),
        ] {
            let e = refused(toml);
            assert!(e.contains(field), "{toml}: {e}");
        }
    }

    #[test]
    fn a_person_at_the_defaults_fits_the_paper_and_is_off() {
        let sc = Scenario::from_toml_str("[master.human]\ntremor_um = 100.0").expect("valid");
        assert!(!sc.master.human.is_off());
        assert!(Scenario::paper().master.human.is_off());
        // Without a tremor, its band is not held to the loop's Nyquist frequency.
        Scenario::from_toml_str("[master.human]\ntremor_hz = 49.0").expect("no tremor");
    }
}
