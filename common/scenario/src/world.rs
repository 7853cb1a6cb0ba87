//! `[environment] engine = "physics"`: the slave's world as rigid bodies (rapier's),
//! with their shapes, mass, friction and joints, and the tool coupled to the arm.
//!
//! Every key has a default, and every default is left out when the scenario is written
//! back, so a scenario of the analytic springs (the paper's) writes the same TOML as
//! before this table existed. The checks that need no file are here; a mesh file's
//! contents and the bodies' overlap at the start are checked where the world is built
//! (`tactile-world`), naming the same fields.

use serde::{Deserialize, Serialize};

/// Which world the slave's tool touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// The analytic penalty springs of `[[environment.objects]]` (the paper's).
    #[default]
    Analytic,
    /// The rigid-body world of `[[environment.bodies]]` and `[[environment.joints]]`.
    Physics,
}

/// True for a value equal to its type's default: such a key is not written back.
pub(crate) fn is_default<T: Default + PartialEq>(v: &T) -> bool {
    *v == T::default()
}

/// The box of the world, m: a dynamic body whose centre leaves it is counted and named.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldBounds {
    /// Lowest corner, m.
    pub min: [f64; 3],
    /// Highest corner, m.
    pub max: [f64; 3],
}

impl Default for WorldBounds {
    /// 5 m every way from the origin: a table top of a room.
    fn default() -> Self {
        WorldBounds {
            min: [-5.0; 3],
            max: [5.0; 3],
        }
    }
}

/// The contact solver's settings (rapier's `IntegrationParameters`, global to the
/// world: rapier 0.27 has no per-body contact stiffness; a collider's own softness is
/// only its `contact_skin`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverConfig {
    /// The solver's substeps per physics step (rapier's `num_solver_iterations`: its
    /// TGS solver integrates each step in this many substeps, each one iteration).
    pub iterations: u32,
    /// Natural frequency of the contacts' stabilising spring, Hz (rapier's
    /// `contact_natural_frequency`): how fast a penetration is pushed out.
    pub contact_frequency_hz: f64,
    /// Its damping ratio (rapier's `contact_damping_ratio`): larger is stiffer-looking
    /// and less bouncy.
    pub contact_damping_ratio: f64,
    /// Penetration left uncorrected, m (rapier's `normalized_allowed_linear_error`,
    /// with `length_unit` 1).
    pub allowed_penetration: f64,
    /// Distance at which contacts are predicted before they touch, m (rapier's
    /// `normalized_prediction_distance`).
    pub prediction_distance: f64,
}

impl Default for SolverConfig {
    /// rapier's defaults but a 0.1 mm allowed penetration (rapier's 1 mm is two peg
    /// clearances of a 0.5 mm fit).
    fn default() -> Self {
        SolverConfig {
            iterations: 4,
            contact_frequency_hz: 30.0,
            contact_damping_ratio: 5.0,
            allowed_penetration: 1e-4,
            prediction_distance: 2e-3,
        }
    }
}

/// How a body moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum BodyKind {
    /// Never moves (a table, a wall).
    #[default]
    Static,
    /// Moves under forces, gravity and contacts.
    Dynamic,
    /// Moves only as told (its pose set each sample), pushing dynamic bodies.
    Kinematic,
}

/// A body's (or the tool's) shape, in its own frame (about its centre).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Shape {
    /// A box.
    Box {
        /// Half extents along x, y, z, m.
        half_extents: [f64; 3],
    },
    /// A ball.
    Sphere {
        /// Radius, m.
        radius: f64,
    },
    /// A capsule along z: a cylinder of `2 half_height` capped by half balls.
    Capsule {
        /// Half the length of its straight part, m.
        half_height: f64,
        /// Radius, m.
        radius: f64,
    },
    /// A cylinder along z.
    Cylinder {
        /// Half its length, m.
        half_height: f64,
        /// Radius, m.
        radius: f64,
    },
    /// The convex hull of points, given here or as a mesh file's vertices.
    ConvexHull {
        /// The points, m (at least 4, not all in a plane).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        points: Option<Vec<[f64; 3]>>,
        /// An STL or OBJ file whose vertices span the hull (relative to the
        /// scenario's folder).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        file: Option<String>,
        /// Metres per unit of the file (0.001 for a file in millimetres).
        #[serde(default = "one", skip_serializing_if = "is_one")]
        scale: f64,
    },
    /// A triangle mesh from an STL (binary or ASCII) or OBJ file: exact surfaces for a
    /// static or kinematic body; a dynamic body takes its convex hull (a closed mesh
    /// is required of it).
    Mesh {
        /// The file (relative to the scenario's folder).
        file: String,
        /// Metres per unit of the file (0.001 for a file in millimetres).
        #[serde(default = "one", skip_serializing_if = "is_one")]
        scale: f64,
    },
}

fn one() -> f64 {
    1.0
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
}

fn identity() -> [f64; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

fn is_identity(q: &[f64; 4]) -> bool {
    *q == identity()
}

fn half() -> f64 {
    0.5
}

/// One `[[environment.bodies]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyConfig {
    /// Its name, unique (tasks and events name it).
    pub name: String,
    /// `static`, `dynamic` or `kinematic`.
    #[serde(default)]
    pub kind: BodyKind,
    /// Its shape.
    pub shape: Shape,
    /// Its centre at the start, m.
    #[serde(default)]
    pub position: [f64; 3],
    /// Its orientation at the start, a quaternion `[x, y, z, w]` (normalised on load).
    #[serde(default = "identity", skip_serializing_if = "is_identity")]
    pub rotation: [f64; 4],
    /// Mass, kg (a dynamic body: this or `density`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// Density, kg/m^3 (default 1000 when neither is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Coulomb friction coefficient, one for sticking and sliding (rapier has no
    /// separate static coefficient); a contact takes the mean of its two bodies'.
    #[serde(default = "half")]
    pub friction: f64,
    /// Restitution, 0 (no bounce) to 1; a contact takes the mean of its two bodies'.
    #[serde(default)]
    pub restitution: f64,
    /// rapier's `contact_skin`, m: the contact acts this far out of the surface
    /// (a softer-looking, earlier contact; 0 by default).
    #[serde(default, skip_serializing_if = "is_default")]
    pub contact_skin: f64,
}

/// A joint's type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Turns about `axis` through `anchor` (a door).
    Revolute,
    /// Slides along `axis` (a drawer).
    Prismatic,
    /// Holds `body2` to `body1` as they are at the start: one rigid body of two
    /// shapes (a handle on a drawer). No limits, damping or friction.
    Fixed,
}

/// One `[[environment.joints]]`: two bodies (or a body and the world) held together
/// but for one turn or one slide.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointConfig {
    /// Its name, unique (tasks name it).
    pub name: String,
    /// `revolute` or `prismatic`.
    pub kind: JointKind,
    /// The first body; left out, the world.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body1: Option<String>,
    /// The second body (the one that moves: a door, a drawer).
    pub body2: String,
    /// A point on the axis, in the world at the start, m.
    #[serde(default)]
    pub anchor: [f64; 3],
    /// The axis, in the world at the start (normalised on load).
    pub axis: [f64; 3],
    /// Lowest and highest position, rad or m (the joint's position is 0 at the start).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<[f64; 2]>,
    /// Viscous damping, N s/m or N m s/rad.
    #[serde(default)]
    pub damping: f64,
    /// Coulomb friction, N or N m: the force needed to move it.
    #[serde(default)]
    pub friction: f64,
}

/// `[environment.tool]`: the tool body and the virtual coupling (a spring and a
/// damper on position and on orientation) that pulls it to the arm's tool frame. The
/// coupling's force is what the arm feels (the h(n) sent back). docs/16 derives the
/// defaults and why they are passive at 1 kHz with the default substeps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ToolConfig {
    /// Its shape about the tool frame (a 5 mm ball by default; a peg is a `cylinder`
    /// or `capsule`, along the tool frame's z). A mesh is taken as its convex hull.
    pub shape: Shape,
    /// Its mass, kg (weightless: the arm carries it).
    pub mass: f64,
    /// Its friction coefficient, and the arm's links' (a contact of the arm takes the
    /// smaller of this and the body's).
    pub friction: f64,
    /// Its restitution.
    pub restitution: f64,
    /// The coupling's stiffness, N/m.
    pub stiffness: f64,
    /// The coupling's damping, N s/m.
    pub damping: f64,
    /// The coupling's rotational stiffness, N m/rad.
    pub angular_stiffness: f64,
    /// The coupling's rotational damping, N m s/rad.
    pub angular_damping: f64,
}

impl Default for ToolConfig {
    fn default() -> Self {
        ToolConfig {
            shape: Shape::Sphere { radius: 0.005 },
            mass: 0.1,
            friction: 0.3,
            restitution: 0.0,
            stiffness: 1000.0,
            damping: 10.0,
            angular_stiffness: 2.0,
            angular_damping: 0.02,
        }
    }
}

#[cfg(test)]
#[path = "world_tests.rs"]
mod tests;
