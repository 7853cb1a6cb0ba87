//! MMT in the nodes: the scenario's settings, the model as it crosses the network, the
//! slave's side (estimate, send the changes, numbered) and the master's (take each new
//! model once, refuse garbage, render).

use super::{ChangeThresholds, EstimatorConfig, ModelRenderer, PlaneEstimator, PlaneModel, Update};
use tactile_math::vec3::dot;
use tactile_messages::samples::Model;
use tactile_scenario::{MmtConfig, MmtUpdate};

impl EstimatorConfig {
    /// The scenario's `[control.mmt]`.
    pub fn of(c: &MmtConfig) -> Self {
        EstimatorConfig {
            forgetting: c.forgetting,
            contact_force: c.contact_force,
            prior_stiffness: c.prior_stiffness,
            min_contacts: c.min_contacts,
        }
    }
}

impl ChangeThresholds {
    /// The scenario's `[control.mmt]`.
    pub fn of(c: &MmtConfig) -> Self {
        ChangeThresholds {
            stiffness: c.stiffness_change,
            offset: c.offset_change,
            angle: c.angle_change,
        }
    }
}

impl PlaneModel {
    /// The model as it crosses the network, numbered `seq`.
    pub fn to_message(&self, seq: u64) -> Model {
        Model {
            normal: self.normal,
            offset: self.offset,
            stiffness: self.stiffness,
            seq,
        }
    }

    /// The model a message carries (`None` for "no model yet"); not yet checked.
    pub fn of_message(m: &Model) -> Option<PlaneModel> {
        (m.seq != 0).then_some(PlaneModel {
            normal: m.normal,
            offset: m.offset,
            stiffness: m.stiffness,
        })
    }
}

/// The slave's side of MMT: the estimator, and the model last sent, numbered. A model
/// is sent again only when the estimate differs from it by more than a threshold.
#[derive(Debug, Clone)]
pub struct ModelSender {
    estimator: PlaneEstimator,
    thresholds: ChangeThresholds,
    sent: Model,
}

impl ModelSender {
    /// As `[control.mmt]` says.
    pub fn new(cfg: &MmtConfig) -> Self {
        ModelSender {
            estimator: PlaneEstimator::new(EstimatorConfig::of(cfg)),
            thresholds: ChangeThresholds::of(cfg),
            sent: Model::default(),
        }
    }

    /// Takes one sample (the tool at `x`, the environment's force `h`); true when the
    /// model changed enough to send it again. `shift` is where the operator's clutch
    /// puts the tool relative to the master's handle (zero without a clutch): the
    /// estimate stays in the tool's space, where the wall stands still through a
    /// re-clutch, and the model is sent in the handle's, which the master renders
    /// against. A re-clutch moves the model sent, and so sends it.
    pub fn update(&mut self, x: [f64; 3], h: [f64; 3], shift: [f64; 3]) -> bool {
        self.estimator.update(x, h);
        let Some(mut m) = self.estimator.model() else {
            return false;
        };
        m.offset -= dot(m.normal, shift);
        let new = PlaneModel::of_message(&self.sent)
            .is_none_or(|sent| m.differs(&sent, &self.thresholds));
        if new {
            self.sent = m.to_message(self.sent.seq + 1);
        }
        new
    }

    /// The model last sent (`seq` 0: none yet), carried by every backward sample.
    pub fn sent(&self) -> Model {
        self.sent
    }
}

/// What became of the model a backward sample carried.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Taken {
    /// No model, or the one already taken.
    Nothing,
    /// A new model, now rendered.
    New,
    /// A new model that is not a valid plane (corrupted, or a peer's garbage): refused,
    /// counted once.
    Refused,
}

/// The master's side of MMT: the renderer, fed the models the samples carry.
#[derive(Debug, Clone)]
pub struct ModelReceiver {
    renderer: ModelRenderer,
    taken: u64,
    refused: u64,
    /// Where the handle was when the operator's clutch was released (`None`: engaged).
    released_at: Option<[f64; 3]>,
}

impl ModelReceiver {
    /// As `[control.mmt]` says, for a master sampled every `t_s` seconds whose force
    /// is clamped to `force_limit` on each axis (N).
    pub fn new(cfg: &MmtConfig, t_s: f64, force_limit: f64) -> Self {
        ModelReceiver {
            renderer: ModelRenderer::new(
                cfg.force_rate * t_s,
                match cfg.update {
                    MmtUpdate::Passive => Update::Passive,
                    MmtUpdate::Blend => Update::Blend,
                },
            )
            .with_force_limit(force_limit),
            taken: 0,
            refused: 0,
            released_at: None,
        }
    }

    /// The operator's clutch at this sample, with the handle at `x`. At an engage the
    /// model moves as far as the handle did while released: the robot held, so that
    /// is where the slave's re-clutch puts the wall relative to the handle, and the
    /// master renders it there at once instead of a round trip later, when the slave's
    /// re-sent model arrives (which then changes nothing). A model the slave sent in
    /// the round trip before its own re-clutch is in the frame before it: it is taken
    /// like any change (force-continuous, blended) until that re-sent model comes.
    pub fn clutch(&mut self, released: bool, x: [f64; 3]) {
        match (released, self.released_at) {
            (true, None) => self.released_at = Some(x),
            (false, Some(at)) => {
                self.released_at = None;
                self.renderer.translate([0, 1, 2].map(|i| x[i] - at[i]));
            }
            _ => {}
        }
    }

    /// The model a sample carried, with the handle at `x` and the force that arrived
    /// with it. Numbers only go up: an older model (a reordered packet) is nothing new.
    pub fn take(&mut self, m: &Model, x: [f64; 3], arrived: [f64; 3]) -> Taken {
        if m.seq <= self.taken {
            return Taken::Nothing;
        }
        let accepted =
            PlaneModel::of_message(m).is_some_and(|p| self.renderer.receive(p, x, arrived));
        match (accepted, m.seq == self.refused) {
            (true, _) => {
                self.taken = m.seq;
                Taken::New
            }
            // Refused and counted already: the next sample's copy may still come whole.
            (false, true) => Taken::Nothing,
            (false, false) => {
                self.refused = m.seq;
                Taken::Refused
            }
        }
    }

    /// The model's force on the handle at `x`, once a model has been taken.
    pub fn force(&mut self, x: [f64; 3]) -> Option<[f64; 3]> {
        self.renderer.force(x)
    }

    /// The renderer (its model, the energy its changes added).
    pub fn renderer(&self) -> &ModelRenderer {
        &self.renderer
    }
}
