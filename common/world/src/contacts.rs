//! Reading the contacts after a substep: the wrench on a collider's body from its
//! contacts, the bodies the tool touches and its deepest contact, and a bound on the
//! work a moving kinematic body (a link) did on the others.
//!
//! A contact's normal impulse is exact; its friction impulse lies in a tangent basis
//! the solver picks from the bodies' velocities at the substep's start, which it does
//! not keep: the wrenches here carry the normal part, and the friction's work is
//! bounded by `sqrt(1 + mu^2)` times the normal's.

/// What a collider belongs to, kept in its `user_data`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Owner {
    /// A body of the scene (its index).
    Body(usize),
    /// The tool.
    Tool,
    /// A link of the arm (its index).
    Link(usize),
}

impl Owner {
    pub(crate) fn encode(self) -> u128 {
        match self {
            Owner::Body(i) => i as u128,
            Owner::Tool => 1 << 64,
            Owner::Link(i) => (2 << 64) | i as u128,
        }
    }

    pub(crate) fn decode(v: u128) -> Owner {
        let i = (v & u128::from(u64::MAX)) as usize;
        match v >> 64 {
            0 => Owner::Body(i),
            1 => Owner::Tool,
            _ => Owner::Link(i),
        }
    }
}

/// Starts every contact's solve from zero impulse. rapier 0.27 reports a contact's
/// impulse as the sum over its internal substeps plus the warm-start impulse it began
/// from (counted again: a body resting on a table read 1.25 m g with 4 iterations);
/// with the warm start at zero the sum is the impulse of the step, exactly. The world
/// runs rapier's solver without warm starting (`tgs_soft_without_warmstart`), so no
/// warm start is lost.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ExactImpulses;

impl PhysicsHooks for ExactImpulses {
    fn modify_solver_contacts(&self, c: &mut ContactModificationContext) {
        for s in c.solver_contacts.iter_mut() {
            s.warmstart_impulse = 0.0;
            s.warmstart_tangent_impulse = Default::default();
        }
    }
}
use crate::ToolContact;
use nalgebra::{Point3, Vector3};
use rapier3d_f64::prelude::*;

/// The contact wrench `[f; t]` on `collider`'s body (torque about `about`), and the
/// bound on the work the body did on the others moving at `velocity_at` in this
/// substep (J), from the last substep's impulses over `h`.
pub(crate) fn wrench(
    narrow: &NarrowPhase,
    colliders: &ColliderSet,
    collider: ColliderHandle,
    about: &Point3<f64>,
    h: f64,
    velocity_at: impl Fn(&Point3<f64>) -> Vector3<f64>,
) -> ([f64; 6], f64) {
    let (mut f, mut t, mut work) = (Vector3::zeros(), Vector3::zeros(), 0.0);
    for pair in narrow.contact_pairs_with(collider) {
        if !pair.has_any_active_contact {
            continue;
        }
        let first = pair.collider1 == collider;
        let (Some(c1), Some(c2)) = (colliders.get(pair.collider1), colliders.get(pair.collider2))
        else {
            continue;
        };
        let mu = (c1.friction() + c2.friction()) / 2.0;
        for m in &pair.manifolds {
            // The force on collider1's body is along -normal.
            let dir = if first { -m.data.normal } else { m.data.normal };
            for p in &m.points {
                let lambda = p.data.impulse;
                if lambda == 0.0 {
                    continue;
                }
                let at = if first {
                    c1.position() * p.local_p1
                } else {
                    c2.position() * p.local_p2
                };
                let force = dir * (lambda / h);
                f += force;
                t += (at - about).cross(&force);
                work += lambda * (1.0 + mu * mu).sqrt() * velocity_at(&at).norm();
            }
        }
    }
    ([f.x, f.y, f.z, t.x, t.y, t.z], work)
}

/// The scene bodies touching `tool` into `touching` (each once, ascending), and the
/// deepest contact among them.
pub(crate) fn touching(
    narrow: &NarrowPhase,
    colliders: &ColliderSet,
    tool: ColliderHandle,
    touching: &mut Vec<usize>,
) -> Option<ToolContact> {
    touching.clear();
    let mut deepest: Option<ToolContact> = None;
    for pair in narrow.contact_pairs_with(tool) {
        if !pair.has_any_active_contact {
            continue;
        }
        let other = if pair.collider1 == tool {
            pair.collider2
        } else {
            pair.collider1
        };
        let Some(c) = colliders.get(other) else {
            continue;
        };
        let Owner::Body(body) = Owner::decode(c.user_data) else {
            continue;
        };
        if !touching.contains(&body) && touching.len() < touching.capacity() {
            touching.push(body);
        }
        let tool_first = pair.collider1 == tool;
        let (Some(c1), Some(c2)) = (colliders.get(pair.collider1), colliders.get(pair.collider2))
        else {
            continue;
        };
        for m in &pair.manifolds {
            // The normal points out of collider1; the surface's outward normal at the
            // body points toward the tool.
            let n = if tool_first {
                -m.data.normal
            } else {
                m.data.normal
            };
            for p in &m.points {
                let depth = -p.dist;
                if deepest.is_some_and(|d| d.depth >= depth) {
                    continue;
                }
                let on_body = if tool_first {
                    c2.position() * p.local_p2
                } else {
                    c1.position() * p.local_p1
                };
                deepest = Some(ToolContact {
                    body,
                    point: on_body.coords.into(),
                    normal: n.into(),
                    depth,
                });
            }
        }
    }
    touching.sort_unstable();
    deepest
}
