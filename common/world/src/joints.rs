//! Revolute and prismatic joints: rapier's generic joint with the free axis along the
//! joint's (its local frames set from the anchor and axis given in the world at the
//! start), limits, Coulomb friction as a velocity motor whose force is capped at the
//! friction (it holds the joint still below that force, exactly), and viscous damping
//! applied each substep as a force on both bodies (rapier's joint has one motor per
//! axis; damping applied explicitly is exact at steady speed, F/b, and stable while
//! `b h / m < 1`, which is checked).

use crate::error::{invalid, WorldError};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;
use tactile_scenario::world::JointKind;
use tactile_scenario::Environment;

/// The damping of a friction motor, N s/m or N m s/rad: large enough that the motor
/// holds the joint's speed at zero until its force reaches the friction.
const FRICTION_MOTOR_DAMPING: f64 = 1e6;

/// A joint as the world steps it.
#[derive(Debug, Clone)]
pub(crate) struct JointInfo {
    kind: JointKind,
    /// None: the world.
    body1: Option<RigidBodyHandle>,
    body2: RigidBodyHandle,
    frame1: Isometry3<f64>,
    frame2: Isometry3<f64>,
    damping: f64,
}

/// The rotation taking x to `axis` (unit).
fn along(axis: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(&Vector3::x(), axis).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
    })
}

/// The joints as the world steps them, rapier's, and the pairs of bodies they join.
pub(crate) type Joints = (Vec<JointInfo>, ImpulseJointSet, Vec<(usize, usize)>);

/// The world's joints; also the pairs of body indices they join (their contacts and
/// overlap are left out).
pub(crate) fn build(
    env: &Environment,
    bodies: &mut RigidBodySet,
    colliders: &ColliderSet,
    handles: &[RigidBodyHandle],
    h: f64,
) -> Result<Joints, WorldError> {
    let mut set = ImpulseJointSet::new();
    let mut infos = Vec::with_capacity(env.joints.len());
    let mut pairs = Vec::with_capacity(env.joints.len());
    let ground = if env.joints.iter().any(|j| j.body1.is_none()) {
        Some(bodies.insert(RigidBodyBuilder::fixed().build()))
    } else {
        None
    };
    let index = |name: &str| env.bodies.iter().position(|b| b.name == name);
    for (k, j) in env.joints.iter().enumerate() {
        let f = format!("environment.joints[{k}]");
        let unknown = |key: &str| invalid(format!("{f}.{key}"), "names no body");
        let i2 = index(&j.body2).ok_or_else(|| unknown("body2"))?;
        let i1 = j
            .body1
            .as_deref()
            .map(|n| index(n).ok_or_else(|| unknown("body1")))
            .transpose()?;
        let b2 = handles[i2];
        let b1 = i1
            .map(|i| handles[i])
            .or(ground)
            .ok_or_else(|| unknown("body1"))?;
        if let Some(i1) = i1 {
            pairs.push((i1, i2));
        }
        let axis = Vector3::from(j.axis).normalize();
        let world =
            Isometry3::from_parts(Translation3::from(Vector3::from(j.anchor)), along(&axis));
        let pose = |b: RigidBodyHandle| bodies.get(b).map(|r| *r.position()).unwrap_or_default();
        let frame1 = pose(b1).inverse() * world;
        let frame2 = pose(b2).inverse() * world;
        let (locked, free) = match j.kind {
            JointKind::Revolute => (JointAxesMask::LOCKED_REVOLUTE_AXES, JointAxis::AngX),
            JointKind::Prismatic => (JointAxesMask::LOCKED_PRISMATIC_AXES, JointAxis::LinX),
            // Nothing is free: the scenario's check refuses limits, damping and
            // friction on it, so no motor or limit is set on this axis.
            JointKind::Fixed => (JointAxesMask::LOCKED_FIXED_AXES, JointAxis::LinX),
        };
        let mut g = GenericJointBuilder::new(locked)
            .local_frame1(frame1)
            .local_frame2(frame2)
            .contacts_enabled(false);
        if let Some(l) = j.limits {
            g = g.limits(free, l);
        }
        if j.friction > 0.0 {
            g = g
                .motor_model(free, MotorModel::ForceBased)
                .motor_velocity(free, 0.0, FRICTION_MOTOR_DAMPING)
                .motor_max_force(free, j.friction);
        }
        let info = JointInfo {
            kind: j.kind,
            body1: i1.map(|i| handles[i]),
            body2: b2,
            frame1,
            frame2,
            damping: j.damping,
        };
        let inv = info.inverse_inertia(bodies, colliders, &axis);
        if j.damping * h * inv > 1.0 {
            return Err(invalid(
                format!("{f}.damping"),
                format!(
                    "{} with the moving bodies' inverse {} of {inv:.3e} gives b h / m = {:.2} at the substep of {h:.2e} s: above 1 the damping, applied each substep, oscillates; lower it or raise substeps",
                    j.damping,
                    if j.kind == JointKind::Prismatic { "mass" } else { "inertia" },
                    j.damping * h * inv
                ),
            ));
        }
        set.insert(b1, b2, g.build(), true);
        infos.push(info);
    }
    Ok((infos, set, pairs))
}

fn body_inverse(
    b: Option<RigidBodyHandle>,
    bodies: &RigidBodySet,
    colliders: &ColliderSet,
    axis: &Vector3<f64>,
    linear: bool,
) -> f64 {
    let Some(rb) = b.and_then(|b| bodies.get(b)).filter(|r| r.is_dynamic()) else {
        return 0.0;
    };
    let mut m = rapier3d_f64::parry::mass_properties::MassProperties::default();
    for c in rb.colliders() {
        if let Some(c) = colliders.get(*c) {
            m += c.mass_properties();
        }
    }
    if linear {
        return m.inv_mass;
    }
    let r = rb.position().rotation.to_rotation_matrix();
    let inv = r.matrix() * m.reconstruct_inverse_inertia_matrix() * r.matrix().transpose();
    axis.dot(&(inv * axis))
}

impl JointInfo {
    /// The two bodies' inverse mass (prismatic) or inverse inertia about the axis at
    /// their centres (revolute; about the anchor it is smaller, so the check is on the
    /// safe side).
    fn inverse_inertia(
        &self,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        axis: &Vector3<f64>,
    ) -> f64 {
        let linear = self.kind == JointKind::Prismatic;
        body_inverse(Some(self.body2), bodies, colliders, axis, linear)
            + body_inverse(self.body1, bodies, colliders, axis, linear)
    }

    /// The joint's frames in the world now (body1's, body2's).
    fn frames(&self, bodies: &RigidBodySet) -> (Isometry3<f64>, Isometry3<f64>) {
        let pose = |b: Option<RigidBodyHandle>| {
            b.and_then(|b| bodies.get(b))
                .map_or_else(Isometry3::identity, |r| *r.position())
        };
        (
            pose(self.body1) * self.frame1,
            pose(Some(self.body2)) * self.frame2,
        )
    }

    /// Its position: m along the axis, or rad about it, from the start.
    pub(crate) fn position(&self, bodies: &RigidBodySet) -> f64 {
        let (f1, f2) = self.frames(bodies);
        match self.kind {
            JointKind::Fixed => 0.0,
            JointKind::Prismatic => {
                (f2.translation.vector - f1.translation.vector).dot(&(f1.rotation * Vector3::x()))
            }
            JointKind::Revolute => {
                let rel = f1.rotation.inverse() * f2.rotation;
                let q = rel.quaternion();
                let a = 2.0 * q.i.atan2(q.w);
                // (-pi, pi]
                if a > std::f64::consts::PI {
                    a - 2.0 * std::f64::consts::PI
                } else if a <= -std::f64::consts::PI {
                    a + 2.0 * std::f64::consts::PI
                } else {
                    a
                }
            }
        }
    }

    /// Adds the viscous damping's force (or torque) to both bodies for one substep.
    pub(crate) fn damp(&self, bodies: &mut RigidBodySet) {
        if self.damping == 0.0 {
            return;
        }
        let (f1, f2) = self.frames(bodies);
        let axis = f1.rotation * Vector3::x();
        let (p1, p2) = (f1.translation.vector.into(), f2.translation.vector.into());
        let vel = |b: Option<RigidBodyHandle>,
                   bodies: &RigidBodySet,
                   lin: bool,
                   p: &nalgebra::Point3<f64>| {
            b.and_then(|b| bodies.get(b))
                .map_or_else(Vector3::zeros, |r| {
                    if lin {
                        r.velocity_at_point(p)
                    } else {
                        *r.angvel()
                    }
                })
        };
        let lin = self.kind == JointKind::Prismatic;
        let rel = (vel(Some(self.body2), bodies, lin, &p2) - vel(self.body1, bodies, lin, &p1))
            .dot(&axis);
        let push = axis * (-self.damping * rel);
        if let Some(r) = bodies.get_mut(self.body2) {
            if lin {
                r.add_force_at_point(push, p2, true)
            } else {
                r.add_torque(push, true)
            }
        }
        if let Some(r) = self
            .body1
            .and_then(|b| bodies.get_mut(b))
            .filter(|r| r.is_dynamic())
        {
            if lin {
                r.add_force_at_point(-push, p1, true)
            } else {
                r.add_torque(-push, true)
            }
        }
    }
}
