//! The energy check: the dynamic bodies' kinetic and potential energy may rise only by
//! the work the sources did (the coupling on the tool, the arm's links pushing): a rise
//! beyond that, by more than [`ENERGY_TOLERANCE_J`] in one sample, is an explosion.

/// Unexplained energy one sample may gain before it is an event, J, plus 5 % of the
/// sources' work in the sample: the contact solver's position correction adds a
/// little energy at each new contact (measured under a millijoule in the tests' scenes).
pub const ENERGY_TOLERANCE_J: f64 = 0.01;

/// The energy before a sample and whether the last sample was already an episode.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Watch {
    energy: f64,
    in_episode: bool,
}

impl Watch {
    pub(crate) fn reset(&mut self, energy: f64) {
        self.energy = energy;
        self.in_episode = false;
    }

    /// The sample's unexplained gain if it is an event (once per episode: the first
    /// sample of a run of such samples).
    pub(crate) fn check(&mut self, energy: f64, work_bound: f64) -> Option<f64> {
        let gain = energy - self.energy - work_bound;
        self.energy = energy;
        let bad = gain > ENERGY_TOLERANCE_J + 0.05 * work_bound.abs() || !energy.is_finite();
        let new = bad && !self.in_episode;
        self.in_episode = bad;
        new.then_some(gain)
    }
}
