//! The slave's physics world: rigid bodies with friction, meshes and joints
//! (rapier3d-f64), the tool as a body pulled to the arm's tool frame by a virtual
//! coupling, the arm's links as kinematic bodies, and the checks that catch a world
//! going wrong (a body leaving the bounds, energy rising without a source).
//!
//! The slave's controller meets any world through [`World`]: one call per sample
//! with the arm's tool frame (and links), returning what was [`Sensed`]. The coupling's
//! reaction is the wrench h(n) the slave sends back. Built once from the scenario's
//! `[environment]` ([`PhysicsWorld::new`]), a world allocates nothing per step: its
//! buffers are sized at build and reused (Pinocchio's Model/Data split, in spirit).
//! docs/16-physics-world.md is the user's guide; the coupling's passivity argument is
//! there and in [`coupling`].

mod build;
mod contacts;
pub mod coupling;
mod error;
pub mod fuzz;
mod joints;
pub mod mesh;
mod shapes;
mod step;
pub mod task;
#[cfg(test)]
mod tests;
mod watch;

pub use build::PhysicsWorld;
pub use error::WorldError;
pub use shapes::{link_shapes, surface, LinkShape};
pub use task::{TaskMonitor, TaskProgress};
pub use watch::ENERGY_TOLERANCE_J;

/// A pose: position (m) and orientation (quaternion `[x, y, z, w]`), in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Position, m.
    pub position: [f64; 3],
    /// Orientation, `[x, y, z, w]`.
    pub rotation: [f64; 4],
}

impl Default for Pose {
    fn default() -> Self {
        Pose {
            position: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
        }
    }
}

/// The arm's tool frame for one sample, in the world.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ToolState {
    /// Its pose.
    pub pose: Pose,
    /// Linear velocity, m/s.
    pub velocity: [f64; 3],
    /// Angular velocity, rad/s.
    pub angular_velocity: [f64; 3],
}

/// One link of the arm for one sample: its frame in the world, moving (a kinematic
/// body whose collision shapes were given at build, [`LinkShape`], in the same order).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkState {
    /// Its frame's pose.
    pub pose: Pose,
    /// Linear velocity of its frame's origin, m/s.
    pub velocity: [f64; 3],
    /// Angular velocity, rad/s.
    pub angular_velocity: [f64; 3],
}

/// The tool's deepest contact: what the analytic world reports for its one object
/// (the surface point, the object, the depth), so either world can fill the same
/// record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolContact {
    /// The body touched (index into [`PhysicsWorld::body_names`]).
    pub body: usize,
    /// The contact point on the body's surface, m.
    pub point: [f64; 3],
    /// The surface's outward normal there (toward the tool).
    pub normal: [f64; 3],
    /// How deep the tool is in, m (negative: a gap the solver already sees).
    pub depth: f64,
}

/// What a world can go wrong with; each is counted and named in [`Sensed::events`].
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A dynamic body's centre left the world's bounds: it is taken out of the world.
    LeftBounds {
        /// Its name.
        body: String,
    },
    /// The bodies' energy rose by more than every source's work can explain (an
    /// explosion): the node should ramp the force to zero.
    EnergyGain {
        /// The unexplained rise in this sample, J.
        joules: f64,
    },
    /// A body's state became non-finite: it is taken out of the world.
    NonFinite {
        /// Its name.
        body: String,
    },
    /// The arm's tool frame (or a link) came in non-finite: the last good one held.
    BadInput,
    /// The engine failed inside a step (a panic caught): the world is frozen and
    /// senses no force from then on.
    EngineFailed {
        /// The panic's message.
        message: String,
    },
}

impl std::fmt::Display for Event {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Event::LeftBounds { body } => write!(f, "body `{body}` left the world's bounds"),
            Event::EnergyGain { joules } => write!(
                f,
                "the world gained {joules:.3} J that no source explains (an explosion)"
            ),
            Event::NonFinite { body } => write!(f, "body `{body}` became non-finite"),
            Event::BadInput => write!(f, "a non-finite tool or link state came in"),
            Event::EngineFailed { message } => write!(f, "the physics engine failed: {message}"),
        }
    }
}

/// How often each [`Event`] happened in the run so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counters {
    /// Bodies that left the bounds.
    pub left_bounds: u64,
    /// Samples whose energy rose without a source (each episode once).
    pub energy_gains: u64,
    /// Bodies that became non-finite.
    pub non_finite: u64,
    /// Samples with a non-finite tool or link state.
    pub bad_inputs: u64,
    /// Engine failures (at most one: the world freezes).
    pub engine_failures: u64,
}

impl Counters {
    /// Whether anything went wrong at all.
    pub fn any(&self) -> bool {
        *self != Counters::default()
    }
}

/// What the world sensed in one sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sensed {
    /// The wrench on the arm's tool frame, `[fx, fy, fz, tx, ty, tz]` (N, N m, in the
    /// world, torque about the tool frame's origin): the coupling's reaction, mean
    /// over the sample's substeps. The h(n) the slave sends back.
    pub wrench: [f64; 6],
    /// The tool body's pose after the sample.
    pub tool: Pose,
    /// The tool's deepest contact, if it touches anything.
    pub contact: Option<ToolContact>,
    /// Every body touching the tool (indices into [`PhysicsWorld::body_names`]).
    pub touching: Vec<usize>,
    /// Each link's contact wrench `[f; t]` on the link (about its frame's origin, in
    /// the world), mean over the substeps, in the order of the links given at build.
    pub link_wrenches: Vec<[f64; 6]>,
    /// Each body's pose, in the order of [`PhysicsWorld::body_names`].
    pub poses: Vec<Pose>,
    /// Each joint's position (rad or m from the start), in the order of
    /// [`PhysicsWorld::joint_names`].
    pub joint_positions: Vec<f64>,
    /// What went wrong in this sample (empty almost always).
    pub events: Vec<Event>,
    /// Whether the world is in a fault (an event this sample, or the engine frozen):
    /// the node ramps the force to zero while it is.
    pub fault: bool,
    /// The dynamic bodies' kinetic and potential energy after the sample, J.
    pub energy_j: f64,
}

/// A world the slave's arm touches, one sample at a time.
pub trait World {
    /// Steps the world by `dt` seconds with the arm's tool frame at `tool` and its
    /// links at `links` (as many as given at build; fewer leaves the rest where they
    /// were), returning what was sensed. Never panics.
    fn step(&mut self, tool: &ToolState, links: &[LinkState], dt: f64) -> &Sensed;
    /// What went wrong so far.
    fn counters(&self) -> Counters;
}
