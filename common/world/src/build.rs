//! Building the world from the scenario's `[environment]`: bodies, colliders, joints,
//! the tool and the links, checked (the overlap at the start computed with parry), and
//! every buffer a step needs sized once.

use crate::contacts::Owner;
use crate::error::invalid;
use crate::error::WorldError;
use crate::joints::JointInfo;
use crate::shapes::{shared, LinkShape, Use};
use crate::watch::Watch;
use crate::{Counters, Pose, Sensed};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;
use std::path::Path;
use tactile_scenario::world::{BodyConfig, BodyKind, Engine};
use tactile_scenario::Environment;

/// The physics world: rapier's sets and pipeline, the scene's names, the tool and its
/// coupling's gains, the links, and the buffers of [`Sensed`].
pub struct PhysicsWorld {
    pub(crate) pipeline: PhysicsPipeline,
    pub(crate) params: IntegrationParameters,
    pub(crate) gravity: Vector3<f64>,
    pub(crate) islands: IslandManager,
    pub(crate) broad_phase: DefaultBroadPhase,
    pub(crate) narrow_phase: NarrowPhase,
    pub(crate) bodies: RigidBodySet,
    pub(crate) colliders: ColliderSet,
    pub(crate) impulse_joints: ImpulseJointSet,
    pub(crate) multibody_joints: MultibodyJointSet,
    pub(crate) ccd: CCDSolver,
    pub(crate) names: Vec<String>,
    pub(crate) handles: Vec<RigidBodyHandle>,
    pub(crate) tool: RigidBodyHandle,
    pub(crate) tool_collider: ColliderHandle,
    pub(crate) tool_placed: bool,
    pub(crate) coupling: crate::coupling::Gains,
    pub(crate) joints: Vec<JointInfo>,
    pub(crate) joint_names: Vec<String>,
    pub(crate) links: Vec<(RigidBodyHandle, Vec<ColliderHandle>)>,
    pub(crate) link_names: Vec<String>,
    pub(crate) last_tool: crate::ToolState,
    pub(crate) last_links: Vec<crate::LinkState>,
    pub(crate) substeps: u32,
    pub(crate) bounds: ([f64; 3], [f64; 3]),
    pub(crate) out_of_world: Vec<bool>,
    pub(crate) watch: Watch,
    pub(crate) counters: Counters,
    pub(crate) frozen: bool,
    pub(crate) sensed: Sensed,
    pub(crate) time_s: f64,
}

impl std::fmt::Debug for PhysicsWorld {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PhysicsWorld")
            .field("bodies", &self.names)
            .field("joints", &self.joint_names)
            .field("links", &self.link_names)
            .field("substeps", &self.substeps)
            .field("counters", &self.counters)
            .finish_non_exhaustive()
    }
}

/// A pose as rapier's isometry (the quaternion normalised).
pub(crate) fn isometry(p: &Pose) -> Isometry3<f64> {
    let [x, y, z, w] = p.rotation;
    Isometry3::from_parts(
        Translation3::from(Vector3::from(p.position)),
        UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
    )
}

/// rapier's isometry as a pose.
pub(crate) fn pose_of(i: &Isometry3<f64>) -> Pose {
    let q = i.rotation.quaternion();
    Pose {
        position: i.translation.vector.into(),
        rotation: [q.i, q.j, q.k, q.w],
    }
}

/// Penetration at the start past which two bodies overlap, m: touching (a box resting
/// on a table, 0 apart up to rounding) is not overlapping.
const OVERLAP_M: f64 = 1e-6;

impl PhysicsWorld {
    /// The world of `env` (its files read against `base_dir`), with the arm's `links`
    /// as kinematic bodies; `dt` is the loop's sample period (the coupling's and the
    /// joints' damping are checked stable at its substeps). Errors name the field.
    pub fn new(
        env: &Environment,
        base_dir: &Path,
        links: &[LinkShape],
        dt: f64,
    ) -> Result<PhysicsWorld, WorldError> {
        if env.engine != Engine::Physics {
            return Err(invalid(
                "environment.engine",
                "the physics world needs engine = \"physics\"",
            ));
        }
        if !(1e-5..=0.1).contains(&dt) {
            return Err(invalid(
                "rate_hz",
                format!("a sample of {dt} s is outside 10 us to 100 ms"),
            ));
        }
        let h = dt / f64::from(env.substeps);
        let s = &env.solver;
        let mut params = IntegrationParameters {
            dt: h,
            contact_natural_frequency: s.contact_frequency_hz,
            contact_damping_ratio: s.contact_damping_ratio,
            normalized_allowed_linear_error: s.allowed_penetration,
            normalized_prediction_distance: s.prediction_distance,
            ..IntegrationParameters::tgs_soft_without_warmstart()
        };
        params.num_solver_iterations = std::num::NonZeroUsize::new(s.iterations as usize)
            .unwrap_or(params.num_solver_iterations);
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let mut handles = Vec::with_capacity(env.bodies.len());
        let mut shapes = Vec::with_capacity(env.bodies.len());
        for (k, b) in env.bodies.iter().enumerate() {
            let f = format!("environment.bodies[{k}]");
            let use_ = if b.kind == BodyKind::Dynamic {
                Use::Solid
            } else {
                Use::Surface
            };
            let shape = shared(&b.shape, base_dir, use_, &format!("{f}.shape"))?;
            let pose = Pose {
                position: b.position,
                rotation: b.rotation,
            };
            let rb = match b.kind {
                BodyKind::Static => RigidBodyBuilder::fixed(),
                BodyKind::Dynamic => RigidBodyBuilder::dynamic().can_sleep(false),
                BodyKind::Kinematic => RigidBodyBuilder::kinematic_position_based(),
            }
            .position(isometry(&pose))
            .build();
            let handle = bodies.insert(rb);
            colliders.insert_with_parent(collider(b, shape.clone(), k), handle, &mut bodies);
            handles.push(handle);
            shapes.push((isometry(&pose), shape, b.kind));
        }
        let (joints, impulse_joints, joint_pairs) =
            crate::joints::build(env, &mut bodies, &colliders, &handles, h)?;
        overlaps(env, &shapes, &joint_pairs)?;
        let t = &env.tool;
        let tool_shape = shared(&t.shape, base_dir, Use::Solid, "environment.tool.shape")?;
        let tool = bodies.insert(
            RigidBodyBuilder::dynamic()
                .gravity_scale(0.0)
                .can_sleep(false)
                .build(),
        );
        let tool_collider = colliders.insert_with_parent(
            ColliderBuilder::new(tool_shape)
                .mass(t.mass)
                .friction(t.friction)
                .friction_combine_rule(CoefficientCombineRule::Min)
                .restitution(t.restitution)
                .user_data(Owner::Tool.encode())
                .active_hooks(ActiveHooks::MODIFY_SOLVER_CONTACTS)
                .build(),
            tool,
            &mut bodies,
        );
        let coupling = crate::coupling::Gains::of(t, h)?;
        let mut link_bodies = Vec::with_capacity(links.len());
        for (i, l) in links.iter().enumerate() {
            let body = bodies.insert(RigidBodyBuilder::kinematic_position_based().build());
            let mut cs = Vec::with_capacity(l.shapes.len());
            for (j, (pose, shape)) in l.shapes.iter().enumerate() {
                let s = shared(
                    shape,
                    base_dir,
                    Use::Surface,
                    &format!("links[{i}] `{}`.collision[{j}]", l.name),
                )?;
                cs.push(
                    colliders.insert_with_parent(
                        ColliderBuilder::new(s)
                            .position(isometry(pose))
                            .friction(t.friction)
                            .friction_combine_rule(CoefficientCombineRule::Min)
                            .user_data(Owner::Link(i).encode())
                            .active_hooks(ActiveHooks::MODIFY_SOLVER_CONTACTS)
                            .build(),
                        body,
                        &mut bodies,
                    ),
                );
            }
            link_bodies.push((body, cs));
        }
        let names: Vec<String> = env.bodies.iter().map(|b| b.name.clone()).collect();
        let n = names.len();
        let sensed = Sensed {
            touching: Vec::with_capacity(n),
            link_wrenches: vec![[0.0; 6]; links.len()],
            poses: env
                .bodies
                .iter()
                .map(|b| Pose {
                    position: b.position,
                    rotation: b.rotation,
                })
                .collect(),
            joint_positions: vec![0.0; joints.len()],
            events: Vec::with_capacity(8),
            ..Sensed::default()
        };
        let mut w = PhysicsWorld {
            pipeline: PhysicsPipeline::new(),
            params,
            gravity: Vector3::from(env.gravity),
            islands: IslandManager::new(),
            broad_phase: DefaultBroadPhase::new(),
            narrow_phase: NarrowPhase::new(),
            bodies,
            colliders,
            impulse_joints,
            multibody_joints: MultibodyJointSet::new(),
            ccd: CCDSolver::new(),
            names,
            handles,
            tool,
            tool_collider,
            tool_placed: false,
            coupling,
            joint_names: env.joints.iter().map(|j| j.name.clone()).collect(),
            joints,
            links: link_bodies,
            link_names: links.iter().map(|l| l.name.clone()).collect(),
            last_tool: crate::ToolState::default(),
            last_links: vec![crate::LinkState::default(); links.len()],
            substeps: env.substeps,
            bounds: (env.bounds.min, env.bounds.max),
            out_of_world: vec![false; n],
            watch: Watch::default(),
            counters: Counters::default(),
            frozen: false,
            sensed,
            time_s: 0.0,
        };
        w.watch.reset(w.energy());
        Ok(w)
    }

    /// The scene's bodies' names, in the order of [`Sensed::poses`].
    pub fn body_names(&self) -> &[String] {
        &self.names
    }

    /// The joints' names, in the order of [`Sensed::joint_positions`].
    pub fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    /// The links' names, in the order of [`Sensed::link_wrenches`].
    pub fn link_names(&self) -> &[String] {
        &self.link_names
    }

    /// The last sample's sensing.
    pub fn sensed(&self) -> &Sensed {
        &self.sensed
    }

    /// Seconds stepped so far.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }
}

fn collider(b: &BodyConfig, shape: SharedShape, k: usize) -> Collider {
    let mut c = ColliderBuilder::new(shape)
        .friction(b.friction)
        .restitution(b.restitution)
        .contact_skin(b.contact_skin)
        .user_data(Owner::Body(k).encode())
        .active_hooks(ActiveHooks::MODIFY_SOLVER_CONTACTS);
    if b.kind == BodyKind::Dynamic {
        c = match (b.mass, b.density) {
            (Some(m), _) => c.mass(m),
            (None, Some(d)) => c.density(d),
            (None, None) => c.density(1000.0),
        };
    }
    c.build()
}

/// Refuses two bodies overlapping at the start where one of them moves (static
/// bodies may interpenetrate: nothing pushes them apart), except bodies joined by a
/// joint (a hinge's leaves), whose contacts the world leaves out.
fn overlaps(
    env: &Environment,
    shapes: &[(Isometry3<f64>, SharedShape, BodyKind)],
    joined: &[(usize, usize)],
) -> Result<(), WorldError> {
    for i in 0..shapes.len() {
        let (p1, s1, k1) = &shapes[i];
        let a1 = s1.compute_aabb(p1);
        for (j, (p2, s2, k2)) in shapes.iter().enumerate().skip(i + 1) {
            if *k1 != BodyKind::Dynamic && *k2 != BodyKind::Dynamic {
                continue;
            }
            if joined.contains(&(i, j)) || joined.contains(&(j, i)) {
                continue;
            }
            if !a1.intersects(&s2.compute_aabb(p2)) {
                continue;
            }
            let depth = match parry3d_f64::query::contact(p1, s1.as_ref(), p2, s2.as_ref(), 0.0) {
                Ok(Some(c)) => -c.dist,
                Ok(None) => continue,
                // A pair parry cannot test (two triangle meshes): their AABBs meet, so
                // say so rather than start a world that may explode.
                Err(_) => f64::INFINITY,
            };
            if depth > OVERLAP_M {
                let shown = if depth.is_finite() {
                    format!("{:.3} mm", depth * 1e3)
                } else {
                    "an unknown depth (their shapes cannot be tested against each other; their boxes meet)".into()
                };
                return Err(invalid(
                    format!("environment.bodies[{j}].position"),
                    format!(
                        "`{}` overlaps `{}` at the start by {shown}: move it clear",
                        env.bodies[j].name, env.bodies[i].name
                    ),
                ));
            }
        }
    }
    Ok(())
}

impl PhysicsWorld {
    /// The contact wrench `[f; t]` on scene body `body` from the last substep's
    /// contacts (the normal parts; torque about its centre), N and N m: what a
    /// record or a view shows of how hard a body is pressed.
    pub fn body_contact_wrench(&self, body: usize) -> [f64; 6] {
        let Some(r) = self.handles.get(body).and_then(|h| self.bodies.get(*h)) else {
            return [0.0; 6];
        };
        let about = nalgebra::Point3::from(*r.translation());
        let mut sum = [0.0; 6];
        for c in r.colliders() {
            let (w, _) = crate::contacts::wrench(
                &self.narrow_phase,
                &self.colliders,
                *c,
                &about,
                self.params.dt,
                |_| Vector3::zeros(),
            );
            sum.iter_mut().zip(w).for_each(|(s, x)| *s += x);
        }
        sum
    }
}
