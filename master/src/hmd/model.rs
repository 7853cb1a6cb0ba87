//! [`Master`]'s side of MMT: the model each answer carries taken, and the latest
//! rendered against the handle (or what arrived, before the first and without MMT).

use super::Master;
use tactile_control::mmt::Taken;
use tactile_messages::samples::Backward;

impl Master {
    /// MMT: takes the model `q` carries and renders the latest against the handle;
    /// before the first model, and without MMT, the force that `arrived`. Either way the
    /// force then passes the control's books and the force limit.
    pub(super) fn rendered(&mut self, q: &Backward, arrived: [f64; 3]) -> [f64; 3] {
        if let Some(r) = self.mmt.as_mut() {
            match r.take(&q.model, self.handle, arrived) {
                Taken::New => self.counters.models_received += 1,
                Taken::Refused => self.counters.models_refused += 1,
                Taken::Nothing => {}
            }
        }
        self.model_force(arrived)
    }

    /// MMT's model rendered against the handle, once one has come; `otherwise` before
    /// that and without MMT.
    pub(super) fn model_force(&mut self, otherwise: [f64; 3]) -> [f64; 3] {
        let handle = self.handle;
        self.mmt
            .as_mut()
            .and_then(|r| r.force(handle))
            .unwrap_or(otherwise)
    }
}
