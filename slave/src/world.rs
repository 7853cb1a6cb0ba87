//! What the slave's arm touches: the paper's analytic springs or a physics world
//! (`tactile-world`), one sample at a time.
//!
//! The two differ in where contact is worked out. The analytic scene is a function of
//! the tool's position, so the arm's integrator evaluates it at each of its own
//! integration steps ([`Touch::Scene`]), as the paper's SD does. A physics world is a
//! state of its own that steps once a sample with the arm's tool frame and answers
//! with its coupling's wrench; the arm's dynamics take that wrench held over the next
//! sample ([`Touch::Held`]), as a real arm takes what its force-torque sensor read,
//! and the slave sends it back as h(n). Either way the contact the slave records and
//! sends is computed once a sample, in [`crate::hsd::Slave`].

use crate::environment::Scene;
use std::path::Path;
use tactile_records::slave::{
    BodyPose, TaskResult, TaskSample, WorldCounters, WorldSample, BODIES_PER_SAMPLE,
    JOINTS_PER_SAMPLE,
};
use tactile_scenario::world::{BodyKind, Engine};
use tactile_scenario::{Change, Scenario};
use tactile_world::{PhysicsWorld, Pose, TaskMonitor, TaskProgress, ToolState, World, WorldError};

/// What pushes on the arm's tool while its dynamics integrate one sample.
#[derive(Debug, Clone, Copy)]
pub enum Touch<'a> {
    /// The analytic scene's springs, evaluated at every integration step.
    Scene(&'a Scene),
    /// A force on the tool held over the sample, N in the arm's frame: a physics
    /// world's coupling force of the sample before.
    Held([f64; 3]),
}

/// The world of a scenario's `[environment]`.
#[derive(Debug)]
pub enum SlaveWorld {
    /// `engine = "analytic"`: the springs of `[[environment.objects]]`.
    Analytic(Scene),
    /// `engine = "physics"`: rigid bodies stepped by rapier.
    Physics(Box<Physics>),
}

impl SlaveWorld {
    /// The scenario's world, its mesh files read against `base_dir`. A physics world
    /// that cannot be built (a mesh that is no mesh, bodies overlapping at the start)
    /// is refused naming the field.
    pub fn of_scenario(scenario: &Scenario, base_dir: &Path) -> Result<SlaveWorld, WorldError> {
        let env = &scenario.environment;
        Ok(match env.engine {
            Engine::Analytic => SlaveWorld::Analytic(Scene::new(&env.objects)),
            Engine::Physics => {
                let world = PhysicsWorld::new(env, base_dir, &[], scenario.t_s())?;
                let task = scenario
                    .task
                    .as_ref()
                    .and_then(|t| TaskMonitor::new(t, &world));
                let moving = env
                    .bodies
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| b.kind != BodyKind::Static)
                    .map(|(k, _)| k)
                    .collect();
                SlaveWorld::Physics(Box::new(Physics::new(world, task, moving)))
            }
        })
    }

    /// What the arm's dynamics take this sample.
    pub fn touch(&self) -> Touch<'_> {
        match self {
            SlaveWorld::Analytic(scene) => Touch::Scene(scene),
            SlaveWorld::Physics(p) => Touch::Held(p.held_force()),
        }
    }

    /// An `[[environment.changes]]` entry (the analytic scene's only: a physics
    /// scenario has none).
    pub fn apply(&mut self, c: &Change) {
        if let SlaveWorld::Analytic(scene) = self {
            scene.apply(c);
        }
    }

    /// A physics world's state after the last sample, for the record (None for the
    /// analytic scene).
    pub fn sample(&self) -> Option<WorldSample> {
        match self {
            SlaveWorld::Analytic(_) => None,
            SlaveWorld::Physics(p) => Some(p.sample),
        }
    }

    /// What the world counted so far (all zero for the analytic scene).
    pub fn counters(&self) -> WorldCounters {
        match self {
            SlaveWorld::Analytic(_) => WorldCounters::default(),
            SlaveWorld::Physics(p) => p.counters(),
        }
    }
}

/// How long the force to the operator takes to ramp to zero when the world faults,
/// and back once it has been quiet for [`QUIET_S`], s: the device's force must never
/// step (chapter 5's mode switches ramp over the same 0.1 s).
pub const RAMP_S: f64 = 0.1;

/// How long a world must go without a fault before the force ramps back, s.
pub const QUIET_S: f64 = 0.5;

/// What the physics world answered for one sample, in the arm's frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Felt {
    /// The coupling's force on the arm's tool, N, scaled by the fault ramp.
    pub force: [f64; 3],
    /// Its torque about the tool frame, N m, scaled alike.
    pub torque: [f64; 3],
    /// The tool's deepest contact: its point on the body's surface (m) and the body.
    pub contact: Option<([f64; 3], u32)>,
}

/// A physics world as the slave steps it: the world, the task's monitor, the wrench
/// held for the arm's next sample and the fault ramp.
#[derive(Debug)]
pub struct Physics {
    world: PhysicsWorld,
    task: Option<TaskMonitor>,
    /// The coupling's wrench of the last sample, unramped: what the arm feels.
    held: [f64; 6],
    /// The tool frame's position at the last sample (its velocity is the difference).
    last: Option<[f64; 3]>,
    /// The fault ramp's gain on the force sent back, 0 to 1.
    gain: f64,
    /// Seconds since the last fault (infinite: none yet).
    quiet_s: f64,
    /// Samples whose force was ramped down.
    ramped_steps: u64,
    /// The task's outcome so far (the world counts its own faults).
    task_result: Option<TaskResult>,
    /// The moving (dynamic and kinematic) bodies: indices into the world's bodies.
    moving: Vec<usize>,
    /// The world after the last sample, as the record holds it.
    sample: WorldSample,
}

impl Physics {
    fn new(world: PhysicsWorld, task: Option<TaskMonitor>, moving: Vec<usize>) -> Physics {
        Physics {
            moving,
            sample: WorldSample::default(),
            world,
            task_result: task.as_ref().map(|_| TaskResult::default()),
            task,
            held: [0.0; 6],
            last: None,
            gain: 1.0,
            quiet_s: f64::INFINITY,
            ramped_steps: 0,
        }
    }

    /// The force the arm's dynamics take over the next sample, N in the arm's frame.
    pub fn held_force(&self) -> [f64; 3] {
        [self.held[0], self.held[1], self.held[2]]
    }

    /// Steps the world one sample of `dt` s with the arm's tool frame at `tool` (in
    /// the arm's frame, which is the world's). Events are appended to `events` as
    /// text for the run's record.
    pub fn step(&mut self, tool: Pose, dt: f64, events: &mut Vec<String>) -> Felt {
        let velocity = match self.last {
            Some(p) => [0, 1, 2].map(|k| (tool.position[k] - p[k]) / dt),
            None => [0.0; 3],
        };
        self.last = Some(tool.position);
        let state = ToolState {
            pose: tool,
            velocity,
            angular_velocity: [0.0; 3],
        };
        let time_s = self.world.time_s() + dt;
        let sensed = self.world.step(&state, &[], dt);
        events.extend(sensed.events.iter().map(|e| e.to_string()));
        let fault = sensed.fault;
        self.held = sensed.wrench;
        // A contact the solver sees: touching, or within its prediction distance
        // (a resting contact may sit a hair apart under soft contacts).
        let contact = sensed.contact.map(|c| (c.point, c.body as u32));
        let progress = self.task.as_mut().map(|t| t.update(sensed, time_s));
        self.ramp(fault, dt);
        self.record(progress);
        self.keep();
        let g = self.gain;
        Felt {
            force: [0, 1, 2].map(|k| g * self.held[k]),
            torque: [3, 4, 5].map(|k| g * self.held[k]),
            contact,
        }
    }

    /// Down toward zero while the world has faulted within [`QUIET_S`], back up
    /// after, at 1 / [`RAMP_S`] a second either way.
    fn ramp(&mut self, fault: bool, dt: f64) {
        self.quiet_s = if fault { 0.0 } else { self.quiet_s + dt };
        let rate = dt / RAMP_S;
        self.gain = if self.quiet_s < QUIET_S {
            (self.gain - rate).max(0.0)
        } else {
            (self.gain + rate).min(1.0)
        };
        if self.gain < 1.0 {
            self.ramped_steps += 1;
        }
    }

    /// The world's state after this sample into [`Physics::sample`]: the tool, the
    /// next turn of the moving bodies (all of them each sample up to
    /// [`BODIES_PER_SAMPLE`]) and of the joints, and the task. Allocates nothing.
    fn keep(&mut self) {
        let sensed = self.world.sensed();
        let w = &mut self.sample;
        w.tool = pose(&sensed.tool);
        let first = next_turn(w.first_body, w.bodies, self.moving.len());
        let bodies = &self.moving[first..(first + BODIES_PER_SAMPLE).min(self.moving.len())];
        for (slot, &k) in w.poses.iter_mut().zip(bodies) {
            *slot = sensed.poses.get(k).map_or_else(BodyPose::default, pose);
        }
        w.first_body = first as u32;
        w.bodies = bodies.len() as u32;
        let q = &sensed.joint_positions;
        let first = next_turn(w.first_joint, w.joints, q.len());
        let joints = &q[first..(first + JOINTS_PER_SAMPLE).min(q.len())];
        w.joint_positions[..joints.len()].copy_from_slice(joints);
        w.first_joint = first as u32;
        w.joints = joints.len() as u32;
        w.task = self.task.as_ref().map(|t| {
            let p = t.progress();
            TaskSample {
                distance: p.distance,
                met: p.met,
                success: p.success,
            }
        });
    }

    /// The task's outcome after this sample's `progress`.
    fn record(&mut self, progress: Option<TaskProgress>) {
        if let (Some(p), Some(t)) = (progress, self.task_result.as_mut()) {
            t.success = p.success;
            t.completion_s = p.completion_s;
            t.distance = p.distance;
            t.closest = if t.steps == 0 {
                p.distance
            } else {
                t.closest.min(p.distance)
            };
            t.steps += 1;
        }
    }

    /// The world's faults as it counts them, the ramp's and the task's.
    fn counters(&self) -> WorldCounters {
        let c = self.world.counters();
        WorldCounters {
            physics: true,
            left_bounds: c.left_bounds,
            energy_gains: c.energy_gains,
            non_finite: c.non_finite,
            bad_inputs: c.bad_inputs,
            engine_failures: c.engine_failures,
            ramped_steps: self.ramped_steps,
            task: self.task_result,
        }
    }
}

/// A world's pose as the record holds it.
fn pose(p: &Pose) -> BodyPose {
    BodyPose {
        position: p.position,
        rotation: p.rotation,
    }
}

/// Where the next turn of `of` items starts after the turn that started at `first`
/// and held `held`: on from there, back to 0 past the end (a world whose items all fit
/// in one turn starts at 0 every sample).
fn next_turn(first: u32, held: u32, of: usize) -> usize {
    let next = first as usize + held as usize;
    if held == 0 || next >= of {
        0
    } else {
        next
    }
}

#[cfg(test)]
mod tests {
    use super::next_turn;

    /// Twenty moving bodies go in turns of 16 then 4; five all at once every sample.
    #[test]
    fn the_moving_bodies_are_recorded_in_turns() {
        assert_eq!(next_turn(0, 0, 20), 0);
        assert_eq!(next_turn(0, 16, 20), 16);
        assert_eq!(next_turn(16, 4, 20), 0);
        assert_eq!(next_turn(0, 5, 5), 0);
        assert_eq!(next_turn(0, 0, 0), 0);
    }
}
