//! Model-mediated teleoperation's model: the slave's online estimate of the plane its
//! tool touches, and the test of when an estimate has changed enough to send again.
//!
//! The slave sees its tool's position `x` and the environment's force on the tool `h`.
//! A plane wall pushes back along its outward normal `n` with `h = k (d - n.x) n` while
//! `n.x < d` (the penetration), and not at all outside. The estimator learns `n` from the
//! direction of the contact force, and `d` and `k` by recursive least squares on the
//! force along `n` against the position along `n` (Mitra and Niemeyer, "Model-mediated
//! telemanipulation", IJRR 27(2), 2008; Xu, Cizmeci, Schuwerk and Steinbach,
//! "Model-mediated teleoperation: toward stable and transparent teleoperation
//! systems", IEEE Access 4, 2016). With the regressor centred on the first contact's
//! position, `f = f0 - k (s - s0)`: `f0` and `k` are of one scale whatever the wall's
//! place, and the normal equations stay well conditioned.
//!
//! Forgetting (factor `lambda` per sample) lets the estimate follow a wall that moved
//! or changed, and bounded covariance keeps the gain from winding up while the operator
//! holds still in contact (nothing new is learnt, and plain forgetting would grow the
//! covariance without bound: Åström and Wittenmark, "Adaptive control", 2nd ed., 1995,
//! section 11.2). Free motion where the model says the tool is inside the wall is
//! evidence too: the surface is at least as deep as the tool, and the estimate moves
//! there.

use tactile_math::vec3::{dot, norm};
use tactile_scenario::MAX_STIFFNESS;

/// The estimator's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig {
    /// RLS forgetting factor per sample, in (0, 1]: 1 remembers everything.
    pub forgetting: f64,
    /// A force above this (N) is contact; below it, free motion.
    pub contact_force: f64,
    /// The stiffness assumed at the first contact, before the data says otherwise, N/m.
    pub prior_stiffness: f64,
    /// Samples in contact before a model is given out.
    pub min_contacts: u32,
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        EstimatorConfig {
            forgetting: 0.995,
            contact_force: 0.05,
            prior_stiffness: 300.0,
            min_contacts: 20,
        }
    }
}

/// A plane wall: contact where `normal . x < offset`, force `stiffness * (offset -
/// normal . x) * normal` there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneModel {
    /// Outward unit normal (free space is on its side).
    pub normal: [f64; 3],
    /// The surface's position along the normal, m.
    pub offset: f64,
    /// N/m.
    pub stiffness: f64,
}

/// The softest wall a model may be, N/m: 1 N per metre is no wall a hand can feel.
pub const MIN_STIFFNESS: f64 = 1.0;

/// A contact force further than this from the model's prediction, N, or than
/// [`JUMP_FRACTION`] of the force, is not the model's wall: the world changed (a wall
/// moved, a material hardened) and the fit starts again from here.
pub const JUMP_FORCE: f64 = 0.5;
/// See [`JUMP_FORCE`].
pub const JUMP_FRACTION: f64 = 0.2;
/// A contact force further than this from the model's normal, rad, is another wall
/// too: the normal and the fit start again from it. A flat wall's force wobbles by a
/// few hundredths of a radian (the slave's fixed-point tool); 20 degrees is a face
/// of its own.
pub const JUMP_ANGLE: f64 = 0.35;

/// How much a model must change before the slave sends it again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChangeThresholds {
    /// Relative change of stiffness.
    pub stiffness: f64,
    /// Change of the surface's position, m.
    pub offset: f64,
    /// Change of the normal's direction, rad.
    pub angle: f64,
}

impl Default for ChangeThresholds {
    fn default() -> Self {
        ChangeThresholds {
            stiffness: 0.02,
            offset: 2.0e-4,
            angle: 0.02,
        }
    }
}

impl PlaneModel {
    /// How deep `x` is inside the wall, m (0 outside).
    pub fn penetration(&self, x: [f64; 3]) -> f64 {
        (self.offset - dot(self.normal, x)).max(0.0)
    }

    /// The wall's force on a point at `x`, N.
    pub fn force(&self, x: [f64; 3]) -> [f64; 3] {
        let f = self.stiffness * self.penetration(x);
        self.normal.map(|n| f * n)
    }

    /// The energy the wall stores with a point at `x`, J.
    pub fn energy(&self, x: [f64; 3]) -> f64 {
        let p = self.penetration(x);
        0.5 * self.stiffness * p * p
    }

    /// A model a renderer may use: finite, a unit normal, a stiffness in
    /// [`MIN_STIFFNESS`]..=[`MAX_STIFFNESS`] (a spring of nothing could not continue
    /// the force felt), and an offset within 10 m. Anything a peer sends is
    /// checked with this before it is believed.
    pub fn is_valid(&self) -> bool {
        self.normal.iter().all(|v| v.is_finite())
            && (norm(self.normal) - 1.0).abs() < 1e-6
            && self.offset.is_finite()
            && self.offset.abs() <= 10.0
            && self.stiffness.is_finite()
            && (MIN_STIFFNESS..=MAX_STIFFNESS).contains(&self.stiffness)
    }

    /// True when `self` differs from `sent` by more than a threshold in any parameter.
    pub fn differs(&self, sent: &PlaneModel, th: &ChangeThresholds) -> bool {
        let k_ref = sent.stiffness.abs().max(1.0);
        let cos = dot(self.normal, sent.normal).clamp(-1.0, 1.0);
        (self.stiffness - sent.stiffness).abs() > th.stiffness * k_ref
            || (self.offset - sent.offset).abs() > th.offset
            || cos.acos() > th.angle
    }
}

/// Recursive least squares on `f = theta0 + theta1 n.(x - anchor)`, with forgetting and
/// a bounded covariance.
#[derive(Debug, Clone, Copy)]
struct Rls {
    theta: [f64; 2],
    p: [[f64; 2]; 2],
    /// A point on the first contact: positions are measured from it along the normal,
    /// so a normal that turns a little does not move them by the tool's distance from
    /// the origin times the angle.
    anchor: [f64; 3],
}

/// The covariance's prior and bound: force (1 N)^2 and stiffness (2000 N/m)^2.
const P0: [f64; 2] = [1.0, 4.0e6];
const PRIOR: [[f64; 2]; 2] = [[P0[0], 0.0], [0.0, P0[1]]];

impl Rls {
    fn new(anchor: [f64; 3], f0: f64, k: f64) -> Self {
        Rls {
            theta: [f0, -k],
            p: PRIOR,
            anchor,
        }
    }

    /// A contact sample: `s` the position along the normal from the anchor.
    fn update(&mut self, s: f64, f: f64, lambda: f64) {
        let phi = [1.0, s];
        let p = self.p;
        let pphi = [
            p[0][0] * phi[0] + p[0][1] * phi[1],
            p[1][0] * phi[0] + p[1][1] * phi[1],
        ];
        let denom = lambda + phi[0] * pphi[0] + phi[1] * pphi[1];
        let gain = [pphi[0] / denom, pphi[1] / denom];
        let err = f - self.predict(phi[1]);
        let next = [self.theta[0] + gain[0] * err, self.theta[1] + gain[1] * err];
        if !next.iter().all(|v| v.is_finite()) {
            return;
        }
        self.theta = next;
        for (i, row) in self.p.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                // (P - K phi' P) / lambda, each diagonal held to its prior: without new
                // data forgetting alone would grow it for ever.
                *v = (p[i][j] - gain[i] * pphi[j]) / lambda;
            }
        }
        if !self.p.iter().flatten().all(|v| v.is_finite()) {
            self.p = PRIOR;
        }
        for (i, bound) in P0.iter().enumerate() {
            if self.p[i][i] > *bound {
                let scale = (bound / self.p[i][i]).sqrt();
                for j in 0..2 {
                    self.p[i][j] *= scale;
                    self.p[j][i] *= scale;
                }
            }
        }
    }

    /// The force the fit gives at `s`.
    fn predict(&self, s: f64) -> f64 {
        self.theta[0] + self.theta[1] * s
    }

    fn stiffness(&self) -> f64 {
        (-self.theta[1]).clamp(0.0, MAX_STIFFNESS)
    }

    /// The surface along `normal`: where the force is zero.
    fn offset(&self, normal: [f64; 3]) -> f64 {
        let k = self.stiffness().max(1.0);
        dot(normal, self.anchor) + self.theta[0] / k
    }
}

/// The slave's online estimate of the plane it touches.
#[derive(Debug, Clone)]
pub struct PlaneEstimator {
    cfg: EstimatorConfig,
    /// Forgetting-weighted sum of the contact forces: its direction is the normal.
    direction: [f64; 3],
    rls: Option<Rls>,
    contacts: u32,
    jumps: u32,
}

impl PlaneEstimator {
    /// An estimator that has seen nothing.
    pub fn new(cfg: EstimatorConfig) -> Self {
        PlaneEstimator {
            cfg,
            direction: [0.0; 3],
            rls: None,
            contacts: 0,
            jumps: 0,
        }
    }

    /// Takes one sample: the tool's position `x` (m) and the environment's force on it
    /// `h` (N). Non-finite samples are ignored.
    pub fn update(&mut self, x: [f64; 3], h: [f64; 3]) {
        if !x.iter().chain(h.iter()).all(|v| v.is_finite()) {
            return;
        }
        let magnitude = norm(h);
        if magnitude <= self.cfg.contact_force {
            self.free(x);
            return;
        }
        let lambda = self.cfg.forgetting;
        let turned = self.contacts >= self.cfg.min_contacts
            && dot(self.normal(), h) < JUMP_ANGLE.cos() * magnitude;
        if turned {
            // The force left the plane's normal: another wall (a corner's second
            // face, a tilted body). Averaged into the old normal it tilted the plane
            // under a fit that then read a stiffness of a few N/m and a surface metres
            // away; its own normal from here instead.
            self.direction = [0.0; 3];
        }
        self.direction = std::array::from_fn(|i| lambda * self.direction[i] + h[i] / magnitude);
        let n = self.normal();
        let f = dot(n, h);
        let rls = self
            .rls
            .get_or_insert_with(|| Rls::new(x, f, self.cfg.prior_stiffness));
        let s = dot(n, [0, 1, 2].map(|i| x[i] - rls.anchor[i]));
        let jump = turned || (f - rls.predict(s)).abs() > JUMP_FORCE.max(JUMP_FRACTION * f.abs());
        if jump && self.contacts >= self.cfg.min_contacts {
            // Another wall from here: its surface where this force says with the
            // stiffness so far, which the next samples refine.
            let k = rls.stiffness().max(MIN_STIFFNESS);
            *rls = Rls::new(x, f, k);
            self.jumps = self.jumps.saturating_add(1);
        } else {
            rls.update(s, f, lambda);
        }
        self.contacts = self.contacts.saturating_add(1);
    }

    /// Times the contact force left the model (a changed world) and the fit began
    /// again.
    pub fn jumps(&self) -> u32 {
        self.jumps
    }

    /// Free motion: if the model puts the tool inside the wall, the surface is at least
    /// as deep as the tool. The stiffness is kept; the surface moves to the tool.
    fn free(&mut self, x: [f64; 3]) {
        let Some(model) = self.model() else { return };
        // Below the contact force the tool may still be this deep in the real wall.
        let hidden = 2.0 * self.cfg.contact_force / model.stiffness.max(1.0);
        let s = dot(model.normal, x);
        if s < model.offset - hidden {
            if let Some(rls) = self.rls.as_mut() {
                let k = rls.stiffness();
                *rls = Rls::new(x, 0.0, k);
            }
        }
    }

    fn normal(&self) -> [f64; 3] {
        let m = norm(self.direction);
        if m > 0.0 {
            self.direction.map(|v| v / m)
        } else {
            [0.0, 0.0, 1.0]
        }
    }

    /// The current estimate, once enough contact has been seen.
    pub fn model(&self) -> Option<PlaneModel> {
        if self.contacts < self.cfg.min_contacts {
            return None;
        }
        let rls = self.rls.as_ref()?;
        let m = PlaneModel {
            normal: self.normal(),
            offset: rls.offset(self.normal()),
            stiffness: rls.stiffness(),
        };
        m.is_valid().then_some(m)
    }

    /// Samples in contact so far.
    pub fn contacts(&self) -> u32 {
        self.contacts
    }
}

mod nodes;
mod render;
pub use nodes::{ModelReceiver, ModelSender, Taken};
pub use render::{ModelRenderer, Update};

#[cfg(test)]
mod tests;
