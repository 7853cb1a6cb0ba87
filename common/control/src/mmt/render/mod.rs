//! The master's rendering of the slave's latest model, against its own handle, every
//! sample, with no delay in the haptic loop.
//!
//! A model change must not kick the operator. What is rendered is always a plane wall
//! (a conservative spring at each instant, whose stored energy is what model changes
//! are booked by): the *rendered* plane, which follows the latest model at a bounded
//! rate. A new model is taken with the force at the handle continuous, vector and all:
//! the rendered normal stays where it was, and the rendered surface is placed where
//! the new stiffness gives the force felt now. The rendered normal then turns towards
//! the model's, the handle's depth kept, by at most `step / F` a sample (`F` the force
//! rendered), so the force's direction changes by at most `step` newtons a sample; an
//! earlier renderer switched the normal at once, and where two walls meet at a corner
//! the estimate's normal swings between them and the operator felt steps of a newton.
//! Once the normals agree the surface returns to the model's, as the update rule
//! ([`Update`]) allows:
//!
//! - **`Passive`, the energy check** (Mitra and Niemeyer 2008; Xu et al. 2016): only
//!   changes that do not raise the energy the rendered spring stores at the handle. While
//!   the handle is outside, the model at once but its surface never past the handle;
//!   inside, only a surface that is out of the model's moves, deeper, so that the force
//!   eases off by `step` newtons a sample. A stiffer model is taken at once (at the same
//!   force the stored energy `F^2 / 2k` falls); a softer one waits until the handle is
//!   outside. A wall first felt late (the handle already deep when the first model
//!   arrives) stays that much farther until the handle next leaves it.
//! - **`Blend`**: as `Passive`, and inside the wall a surface deeper than the model's
//!   moves out so that the force rises by `step` a sample, and a softer model is taken
//!   at once (its surface then eases deeper). The force changes by at most `step` a
//!   sample, so there is no kick.
//!
//! The net energy changes add at the handle is booked in [`ModelRenderer::injected`],
//! under either rule (a turning normal can add some under `Passive` where the force
//! limit cuts one axis and not another), as the rendered spring stores it *after the
//! force limit*: the work the limited force gives back on the way out of the wall
//! (`k p^2 / 2` while the force is inside the limit, then the limit times the depth
//! beyond). The unlimited spring's `k p^2 / 2`, its rises summed and its falls left
//! out, booked 0.132 J on `wall-change.toml` where the felt force did 0.045 J of work
//! in all.

use super::PlaneModel;
use tactile_math::vec3::{dot, norm};

/// How a rendered model's surface returns to the model's after a change (see
/// [`ModelRenderer`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Update {
    /// Only changes that add no energy at the handle.
    Passive,
    /// Towards the model at a bounded rate either way, the energy added booked.
    Blend,
}

/// See the module's documentation.
#[derive(Debug, Clone)]
pub struct ModelRenderer {
    /// The latest model (its stiffness the one rendered: a softer one may wait).
    model: Option<PlaneModel>,
    /// A softer stiffness waiting for the handle to leave the wall (`Passive`).
    softer: Option<f64>,
    /// The rendered plane's outward normal, turning towards the model's.
    normal: [f64; 3],
    /// The rendered plane's surface along `normal`, m.
    surface: f64,
    /// N a sample.
    step: f64,
    update: Update,
    /// The force limit each axis is clamped to after the renderer, N (infinite: none).
    limit: f64,
    /// Energy model changes added at the handle, J.
    injected: f64,
}

impl ModelRenderer {
    /// `step`: how fast the felt force may change as the rendered plane follows the
    /// model's, N per sample; no force limit.
    pub fn new(step: f64, update: Update) -> Self {
        ModelRenderer {
            model: None,
            softer: None,
            normal: [0.0, 0.0, 1.0],
            surface: 0.0,
            step: step.abs(),
            update,
            limit: f64::INFINITY,
            injected: 0.0,
        }
    }

    /// The force limit each axis of the rendered force is clamped to downstream (the
    /// master's `force_limit`), N: the energy booked is the limited spring's.
    pub fn with_force_limit(self, limit: f64) -> Self {
        ModelRenderer {
            limit: limit.abs(),
            ..self
        }
    }

    /// The plane rendered now, if any model has arrived.
    pub fn rendered(&self) -> Option<PlaneModel> {
        self.model.map(|m| PlaneModel {
            normal: self.normal,
            offset: self.surface,
            stiffness: m.stiffness,
        })
    }

    /// The latest model as received (the stiffness it renders once allowed).
    pub fn model(&self) -> Option<PlaneModel> {
        self.model.map(|m| PlaneModel {
            stiffness: self.softer.unwrap_or(m.stiffness),
            ..m
        })
    }

    /// The net energy model changes have added at the handle, J: what the rendered
    /// spring's changes (not the handle's moves) put into what it stores, less what
    /// they took out. Whatever the handle does, the work the rendered force does on it
    /// is this less what the spring still stores (the energy balance of a spring
    /// whose rest length is moved), so the operator never gets more than it.
    pub fn injected(&self) -> f64 {
        self.injected
    }

    /// Takes a model from the slave with the handle at `x`. The force on the handle now
    /// is the rendered plane's; before the first model it is `arrived`, what came over
    /// the channel. An invalid model is refused (false) and changes nothing.
    pub fn receive(&mut self, new: PlaneModel, x: [f64; 3], arrived: [f64; 3]) -> bool {
        if !new.is_valid() || !x.iter().chain(arrived.iter()).all(|v| v.is_finite()) {
            return false;
        }
        // The first model takes over the force that arrived over the channel, whose
        // energy the channel's observers book, along that force's own direction; from
        // then on changes are this one's, continuous with what it renders (never with
        // a force it is told, which could be larger and so store more).
        let shown = self.rendered();
        let before = shown.map_or(0.0, |m| self.stored(&m, x));
        let felt = shown.map_or(arrived, |m| m.force(x));
        let f = norm(felt);
        let mut k = new.stiffness;
        self.softer = None;
        if let (Some(old), Update::Passive) = (self.model, self.update) {
            if f > 0.0 && k < old.stiffness {
                self.softer = Some(k);
                k = old.stiffness;
            }
        }
        self.model = Some(PlaneModel {
            stiffness: k,
            ..new
        });
        if f > 0.0 {
            // Where the spring gives the felt force at the handle, in its direction
            // (which then turns towards the model's normal, whatever it is).
            self.normal = felt.map(|v| v / f);
            self.surface = dot(self.normal, x) + f / k;
        } else {
            // Nothing felt: the model's surface, no deeper than the handle.
            self.normal = new.normal;
            self.surface = new.offset.min(dot(new.normal, x));
        }
        if shown.is_some() {
            self.book(before, x);
        }
        true
    }

    /// Moves the model by `d` (a re-clutch carried the handle that far while the robot
    /// held): the handle then meets it as it did before the clutch was released.
    pub fn translate(&mut self, d: [f64; 3]) {
        if let Some(m) = self.model.as_mut() {
            m.offset += dot(m.normal, d);
            self.surface += dot(self.normal, d);
        }
    }

    /// The force on the handle at `x`, N, once a model has arrived; `None` before (the
    /// node renders what arrives). Moves the rendered plane towards the model's as the
    /// update rule allows.
    pub fn force(&mut self, x: [f64; 3]) -> Option<[f64; 3]> {
        let m = self.model?;
        let before = self.rendered().map_or(0.0, |r| self.stored(&r, x));
        let depth = self.surface - dot(self.normal, x);
        if depth <= 0.0 {
            // Nothing stored, nothing felt: the model's plane at once, its surface never
            // past the handle.
            self.normal = m.normal;
            self.surface = m.offset.min(dot(m.normal, x));
            if let Some(k) = self.softer.take() {
                self.model = Some(PlaneModel { stiffness: k, ..m });
            }
        } else if self.normal != m.normal {
            // A turn of at most `step` newtons of the force's direction, the depth kept.
            let most = self.step / (m.stiffness * depth);
            self.normal = turn(self.normal, m.normal, most);
            self.surface = dot(self.normal, x) + depth;
        } else {
            self.relax(m);
        }
        self.book(before, x);
        self.rendered().map(|r| r.force(x))
    }

    /// The rendered surface towards the model's by the move that changes the force by
    /// `step`: deeper always (the force eases off), out only with `Blend`.
    fn relax(&mut self, m: PlaneModel) {
        let by = self.step / m.stiffness.max(1.0);
        if self.surface > m.offset {
            self.surface = (self.surface - by).max(m.offset);
        } else if self.update == Update::Blend {
            self.surface = (self.surface + by).min(m.offset);
        }
    }

    /// What the rendered plane `m` stores with the handle at `x`, J, as the force limit
    /// lets it be felt: per axis `i`, the spring `k n_i` clamped to the limit,
    /// integrated over the depth along the normal.
    fn stored(&self, m: &PlaneModel, x: [f64; 3]) -> f64 {
        let p = m.penetration(x);
        if self.limit.is_infinite() {
            return m.energy(x);
        }
        m.normal
            .iter()
            .map(|n| {
                let a = m.stiffness * n.abs();
                let knee = if a > 0.0 {
                    self.limit / a
                } else {
                    f64::INFINITY
                };
                let e = if p <= knee {
                    0.5 * a * p * p
                } else {
                    0.5 * self.limit * knee + self.limit * (p - knee)
                };
                n.abs() * e
            })
            .sum()
    }

    /// Books a change of the rendered plane with the handle still at `x`: what it
    /// stores now less what it stored, either sign. A stiffness estimate that wobbles
    /// raises and lowers `F^2 / 2k` in turn; booking only the rises added up energy
    /// that never reached the handle (13.9 J in a corner where the felt force did
    /// 0.19 J of work).
    fn book(&mut self, before: f64, x: [f64; 3]) {
        let after = self.rendered().map_or(0.0, |m| self.stored(&m, x));
        self.injected += after - before;
    }
}

/// The unit vector `a` turned towards the unit vector `b` by at most `most` radians,
/// in the plane they span; `b` itself once within reach.
fn turn(a: [f64; 3], b: [f64; 3], most: f64) -> [f64; 3] {
    let angle = dot(a, b).clamp(-1.0, 1.0).acos();
    if angle <= most || !most.is_finite() {
        return b;
    }
    // The direction in the plane of a and b perpendicular to a, towards b (for b
    // opposite a, any perpendicular).
    let towards = [0, 1, 2].map(|i| b[i] - dot(a, b) * a[i]);
    let t = norm(towards);
    let perp = if t > 1e-12 {
        towards.map(|v| v / t)
    } else {
        let e = if a[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let c = tactile_math::vec3::cross(a, e);
        let n = norm(c);
        c.map(|v| v / n)
    };
    let (s, c) = most.sin_cos();
    [0, 1, 2].map(|i| a[i] * c + perp[i] * s)
}

#[cfg(test)]
mod tests;
