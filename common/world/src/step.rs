//! One sample of the physics world: the links moved, the coupling's force and the
//! joints' damping applied, the engine stepped `substeps` times, then what was sensed
//! and what went wrong.

use crate::build::{isometry, pose_of, PhysicsWorld};
use crate::coupling::rotation_error;
use crate::{Counters, Event, LinkState, Pose, Sensed, ToolState, World};
use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;

fn finite(p: &Pose, v: &[f64; 3], w: &[f64; 3]) -> bool {
    let q = p.rotation;
    p.position
        .iter()
        .chain(v)
        .chain(w)
        .chain(&q)
        .all(|x| x.is_finite())
        && q.iter().map(|x| x * x).sum::<f64>() > 1e-12
}

/// Where a frame moving at `v`, `w` is `t` seconds on.
fn ahead(p: &Pose, v: &[f64; 3], w: &[f64; 3], t: f64) -> Isometry3<f64> {
    let i = isometry(p);
    let turn = UnitQuaternion::from_scaled_axis(Vector3::from(*w) * t);
    Isometry3::from_parts(
        Translation3::from(i.translation.vector + Vector3::from(*v) * t),
        turn * i.rotation,
    )
}

impl PhysicsWorld {
    /// The dynamic bodies' kinetic and potential energy (the tool's too), J.
    pub(crate) fn energy(&self) -> f64 {
        self.bodies
            .iter()
            .filter(|(_, r)| r.is_dynamic() && r.is_enabled())
            .map(|(_, r)| {
                r.kinetic_energy()
                    - r.mass() * r.gravity_scale() * self.gravity.dot(&r.center_of_mass().coords)
            })
            .sum()
    }

    fn tool_inv_inertia(&self) -> Matrix3<f64> {
        self.bodies.get(self.tool).map_or_else(Matrix3::zeros, |r| {
            let s = r.mass_properties().effective_world_inv_inertia_sqrt;
            s * (s * Matrix3::identity())
        })
    }

    /// Puts the tool and the links where the arm is at the first sample (from where
    /// the world was built, they would sweep through whatever lies between).
    fn place_tool(&mut self, t: &ToolState) {
        if let Some(r) = self.bodies.get_mut(self.tool) {
            r.set_position(isometry(&t.pose), true);
            r.set_linvel(Vector3::from(t.velocity), true);
            r.set_angvel(Vector3::from(t.angular_velocity), true);
        }
        for ((body, _), l) in self.links.iter().zip(&self.last_links) {
            if let Some(r) = self.bodies.get_mut(*body) {
                r.set_position(isometry(&l.pose), true);
            }
        }
        self.tool_placed = true;
    }

    /// Adds the coupling's force and torque to the tool for the substep starting `t`
    /// seconds into the sample; returns them.
    fn couple(&mut self, a: &ToolState, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let target = ahead(&a.pose, &a.velocity, &a.angular_velocity, t);
        let inv_i = self.tool_inv_inertia();
        let Some(r) = self.bodies.get_mut(self.tool) else {
            return (Vector3::zeros(), Vector3::zeros());
        };
        let e = target.translation.vector - r.translation();
        let f = self
            .coupling
            .force(r.mass(), e, Vector3::from(a.velocity), *r.linvel());
        let theta = rotation_error(&target.rotation, r.rotation());
        let tq = self.coupling.torque(
            &inv_i,
            theta,
            Vector3::from(a.angular_velocity),
            *r.angvel(),
        );
        r.add_force(f, true);
        r.add_torque(tq, true);
        (f, tq)
    }

    fn engine_step(&mut self) -> Result<(), String> {
        let run = std::panic::AssertUnwindSafe(|| {
            self.pipeline.step(
                &self.gravity,
                &self.params,
                &mut self.islands,
                &mut self.broad_phase,
                &mut self.narrow_phase,
                &mut self.bodies,
                &mut self.colliders,
                &mut self.impulse_joints,
                &mut self.multibody_joints,
                &mut self.ccd,
                &crate::contacts::ExactImpulses,
                &(),
            );
        });
        std::panic::catch_unwind(run).map_err(|p| {
            p.downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".into())
        })
    }

    /// Takes the inputs, holding the last good ones in place of non-finite ones.
    fn inputs(&mut self, tool: &ToolState, links: &[LinkState]) -> ToolState {
        let mut bad = false;
        if finite(&tool.pose, &tool.velocity, &tool.angular_velocity) {
            self.last_tool = *tool;
        } else {
            bad = true;
        }
        for (last, l) in self.last_links.iter_mut().zip(links) {
            if finite(&l.pose, &l.velocity, &l.angular_velocity) {
                *last = *l;
            } else {
                bad = true;
            }
        }
        if bad {
            self.counters.bad_inputs += 1;
            self.sensed.events.push(Event::BadInput);
        }
        self.last_tool
    }

    fn move_links(&mut self, t: f64) {
        for ((body, _), l) in self.links.iter().zip(&self.last_links) {
            if let Some(r) = self.bodies.get_mut(*body) {
                r.set_next_kinematic_position(ahead(&l.pose, &l.velocity, &l.angular_velocity, t));
            }
        }
    }

    /// The links' contact wrenches of the last substep added to `sensed.link_wrenches`;
    /// the bound on their work.
    fn link_contacts(&mut self, h: f64) -> f64 {
        let mut work = 0.0;
        for (i, (body, cs)) in self.links.iter().enumerate() {
            let Some(r) = self.bodies.get(*body) else {
                continue;
            };
            let about = Point3::from(*r.translation());
            for c in cs {
                let (w, wk) = crate::contacts::wrench(
                    &self.narrow_phase,
                    &self.colliders,
                    *c,
                    &about,
                    h,
                    |p| r.velocity_at_point(p),
                );
                for (s, x) in self.sensed.link_wrenches[i].iter_mut().zip(w) {
                    *s += x;
                }
                work += wk;
            }
        }
        work
    }

    /// Bodies out of the bounds or non-finite: events, and taken out of the world.
    fn check_bodies(&mut self) {
        let (lo, hi) = self.bounds;
        for (k, h) in self.handles.iter().enumerate() {
            if self.out_of_world[k] {
                continue;
            }
            let Some(r) = self.bodies.get_mut(*h) else {
                continue;
            };
            if !r.is_dynamic() {
                continue;
            }
            let p = r.translation();
            let finite = p
                .iter()
                .chain(r.linvel().iter())
                .chain(r.angvel().iter())
                .all(|x| x.is_finite());
            let inside = (0..3).all(|i| p[i] >= lo[i] && p[i] <= hi[i]);
            if finite && inside {
                continue;
            }
            r.set_enabled(false);
            self.out_of_world[k] = true;
            let body = self.names[k].clone();
            if finite {
                self.counters.left_bounds += 1;
                self.sensed.events.push(Event::LeftBounds { body });
            } else {
                self.counters.non_finite += 1;
                self.sensed.events.push(Event::NonFinite { body });
            }
        }
    }

    fn sense(&mut self, f: Vector3<f64>, t: Vector3<f64>, n: f64) {
        let s = &mut self.sensed;
        s.wrench = [-f.x / n, -f.y / n, -f.z / n, -t.x / n, -t.y / n, -t.z / n];
        for w in &mut s.link_wrenches {
            w.iter_mut().for_each(|x| *x /= n);
        }
        for (p, h) in s.poses.iter_mut().zip(&self.handles) {
            if let Some(r) = self.bodies.get(*h) {
                *p = pose_of(r.position());
            }
        }
        for (q, j) in s.joint_positions.iter_mut().zip(&self.joints) {
            *q = j.position(&self.bodies);
        }
        if let Some(r) = self.bodies.get(self.tool) {
            s.tool = pose_of(r.position());
        }
        s.contact = crate::contacts::touching(
            &self.narrow_phase,
            &self.colliders,
            self.tool_collider,
            &mut s.touching,
        );
    }

    fn freeze(&mut self, message: String) {
        self.frozen = true;
        self.counters.engine_failures += 1;
        self.sensed.events.push(Event::EngineFailed { message });
    }
}

impl World for PhysicsWorld {
    fn step(&mut self, tool: &ToolState, links: &[LinkState], dt: f64) -> &Sensed {
        self.sensed.events.clear();
        if self.frozen || !(1e-5..=0.1).contains(&dt) {
            self.sensed.wrench = [0.0; 6];
            self.sensed.fault = true;
            return &self.sensed;
        }
        let a = self.inputs(tool, links);
        if !self.tool_placed {
            self.place_tool(&a);
        }
        let n = self.substeps;
        let h = dt / f64::from(n);
        self.params.dt = h;
        self.coupling.h = h;
        self.sensed
            .link_wrenches
            .iter_mut()
            .for_each(|w| *w = [0.0; 6]);
        let before = self.energy();
        let (mut fsum, mut tsum, mut work) = (Vector3::zeros(), Vector3::zeros(), 0.0);
        for i in 0..n {
            let t0 = f64::from(i) * h;
            self.move_links(t0 + h);
            for (_, r) in self.bodies.iter_mut() {
                if r.is_dynamic() {
                    r.reset_forces(false);
                    r.reset_torques(false);
                }
            }
            for j in &self.joints {
                j.damp(&mut self.bodies);
            }
            let (f, tq) = self.couple(&a, t0);
            let x0 = self
                .bodies
                .get(self.tool)
                .map(|r| *r.translation())
                .unwrap_or_default();
            if let Err(message) = self.engine_step() {
                self.freeze(message);
                self.sensed.wrench = [0.0; 6];
                self.sensed.fault = true;
                return &self.sensed;
            }
            if let Some(r) = self.bodies.get(self.tool) {
                work += f.dot(&(r.translation() - x0)) + tq.dot(r.angvel()) * h;
            }
            work += self.link_contacts(h);
            fsum += f;
            tsum += tq;
        }
        self.sense(fsum, tsum, f64::from(n));
        self.check_bodies();
        let energy = self.energy();
        // A body taken out of the world takes its energy with it: start anew.
        if self
            .sensed
            .events
            .iter()
            .any(|e| matches!(e, Event::LeftBounds { .. } | Event::NonFinite { .. }))
        {
            self.watch.reset(energy);
        } else if let Some(joules) = self.watch.check(energy, work.max(0.0)) {
            self.counters.energy_gains += 1;
            self.sensed.events.push(Event::EnergyGain { joules });
        }
        let _ = before;
        self.sensed.energy_j = energy;
        self.sensed.fault = !self.sensed.events.is_empty();
        if self.sensed.wrench.iter().any(|x| !x.is_finite()) {
            self.sensed.wrench = [0.0; 6];
            self.sensed.fault = true;
        }
        self.time_s += dt;
        &self.sensed
    }

    fn counters(&self) -> Counters {
        self.counters
    }
}
