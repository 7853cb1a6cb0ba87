//! A physics world as `run.mcap` draws it (`engine = "physics"`, docs/16): every body
//! of `[[environment.bodies]]` as a marker in the frame the arm is drawn in (the paper
//! slave's base, or a URDF arm's base link: the world's frame is the arm's), the
//! static ones and the task's target with the environment (once a second), the moving
//! ones and the tool body each sample at their recorded poses (`/slave/bodies`).
//!
//! Shapes: a box, a sphere and a cylinder as those markers; a capsule as a cylinder
//! and two spheres; a convex hull or a mesh as a TRIANGLE_LIST of its file's
//! triangles (a hull's surface), read as the world reads them.

use std::path::Path;
use tactile_records::slave::{BodyPose, WorldSample};
use tactile_ros::msg::{Header, Marker, IDENTITY};
use tactile_scenario::world::{BodyKind, Engine, Shape};
use tactile_scenario::{Scenario, TaskConfig};
use tactile_world::WorldError;

/// Markers a body may take (a capsule's three): a body's ids are `PARTS k ..`.
const PARTS: i32 = 3;

/// The colours: static bodies grey, moving ones orange, the tool blue, the target
/// a translucent green.
const STATIC: [f32; 4] = [0.6, 0.6, 0.65, 0.8];
const MOVING: [f32; 4] = [0.95, 0.55, 0.15, 1.0];
const TOOL: [f32; 4] = [0.2, 0.45, 0.9, 1.0];
const TARGET: [f32; 4] = [0.1, 0.8, 0.3, 0.35];

/// A body's markers about its own frame (each marker's pose is relative to the
/// body's), and the body's id base.
#[derive(Debug, Clone)]
struct Drawn {
    parts: Vec<Marker>,
}

impl Drawn {
    /// The markers at pose `at`, stamped `log` in `frame`.
    fn at<'a>(
        &'a self,
        at: &'a BodyPose,
        frame: &str,
        log: u64,
    ) -> impl Iterator<Item = Marker> + 'a {
        let header = Header::at(log, frame);
        self.parts.iter().map(move |m| {
            let (position, orientation) = compose(at, m.position, m.orientation);
            Marker {
                header: header.clone(),
                position,
                orientation,
                ..m.clone()
            }
        })
    }
}

/// A physics world's scene: each body's markers, which move, the tool's and the
/// target's.
#[derive(Debug, Clone)]
pub struct BodyScene {
    frame: String,
    /// Every body in `[[environment.bodies]]` order with its start pose.
    bodies: Vec<(Drawn, BodyPose, BodyKind)>,
    /// The moving bodies' indices in `bodies`, in the record's order.
    moving: Vec<usize>,
    /// The moving bodies' last recorded poses.
    last: Vec<BodyPose>,
    tool: Drawn,
    target: Option<Marker>,
}

impl BodyScene {
    /// The scene of a physics scenario, drawn in `frame`; None for the analytic one.
    /// A mesh file that cannot be read is an error naming the field.
    pub fn of(scenario: &Scenario, frame: &str) -> Result<Option<BodyScene>, WorldError> {
        let env = &scenario.environment;
        if env.engine != Engine::Physics {
            return Ok(None);
        }
        let mut bodies = Vec::with_capacity(env.bodies.len());
        for (k, b) in env.bodies.iter().enumerate() {
            let field = format!("environment.bodies[{k}].shape");
            let colour = if b.kind == BodyKind::Static {
                STATIC
            } else {
                MOVING
            };
            let parts = shape_markers(&b.shape, &field, colour, "bodies", PARTS * k as i32)?;
            let pose = BodyPose {
                position: b.position,
                rotation: b.rotation,
            };
            bodies.push((Drawn { parts }, pose, b.kind));
        }
        let moving: Vec<usize> = (0..bodies.len())
            .filter(|&k| bodies[k].2 != BodyKind::Static)
            .collect();
        let last = moving.iter().map(|&k| bodies[k].1).collect();
        let tool = Drawn {
            parts: shape_markers(&env.tool.shape, "environment.tool.shape", TOOL, "tool", 0)?,
        };
        Ok(Some(BodyScene {
            frame: frame.to_string(),
            bodies,
            moving,
            last,
            tool,
            target: scenario.task.as_ref().and_then(target),
        }))
    }

    /// The static bodies at their places and the task's target, stamped `log`.
    pub fn fixed(&self, log: u64) -> Vec<Marker> {
        let mut v: Vec<Marker> = self
            .bodies
            .iter()
            .filter(|b| b.2 == BodyKind::Static)
            .flat_map(|(d, pose, _)| d.at(pose, &self.frame, log))
            .collect();
        if let Some(t) = &self.target {
            v.push(Marker {
                header: Header::at(log, &self.frame),
                ..t.clone()
            });
        }
        v
    }

    /// The moving bodies and the tool at the sample's recorded poses (a body the
    /// sample does not hold, recorded in turns, where it was last), stamped `log`.
    pub fn moving(&mut self, world: &WorldSample, log: u64) -> Vec<Marker> {
        for (k, p) in world.poses() {
            if let Some(slot) = self.last.get_mut(k) {
                *slot = *p;
            }
        }
        let mut v: Vec<Marker> = self
            .moving
            .iter()
            .zip(&self.last)
            .flat_map(|(&k, pose)| self.bodies[k].0.at(pose, &self.frame, log))
            .collect();
        v.extend(self.tool.at(&world.tool, &self.frame, log));
        v
    }
}

/// The task's goal as a translucent marker: a pose task's sphere of its tolerance at
/// the target, an insertion's at the depth it asks for, of its radial tolerance; a
/// joint's has no place of its own.
fn target(task: &TaskConfig) -> Option<Marker> {
    let (position, radius) = match task {
        TaskConfig::Pose {
            position,
            tolerance,
            ..
        } => (*position, *tolerance),
        TaskConfig::Insert {
            mouth,
            axis,
            depth,
            radial_tolerance,
            ..
        } => {
            let n = axis.iter().map(|a| a * a).sum::<f64>().sqrt().max(1e-12);
            (
                [0, 1, 2].map(|k| mouth[k] + axis[k] / n * depth),
                *radial_tolerance,
            )
        }
        TaskConfig::Joint { .. } => return None,
    };
    Some(Marker {
        ns: "task".into(),
        id: 0,
        kind: Marker::SPHERE,
        position,
        orientation: IDENTITY,
        scale: [2.0 * radius; 3],
        color: TARGET,
        ..Marker::default()
    })
}

/// A shape's markers about its centre, ids from `id`.
fn shape_markers(
    shape: &Shape,
    field: &str,
    color: [f32; 4],
    ns: &str,
    id: i32,
) -> Result<Vec<Marker>, WorldError> {
    let part = |kind, position: [f64; 3], scale: [f64; 3], k: i32| Marker {
        ns: ns.to_string(),
        id: id + k,
        kind,
        position,
        orientation: IDENTITY,
        scale,
        color,
        ..Marker::default()
    };
    Ok(match shape {
        Shape::Box { half_extents } => vec![part(
            Marker::CUBE,
            [0.0; 3],
            half_extents.map(|h| 2.0 * h),
            0,
        )],
        Shape::Sphere { radius } => vec![part(Marker::SPHERE, [0.0; 3], [2.0 * radius; 3], 0)],
        Shape::Cylinder {
            half_height,
            radius,
        } => vec![part(
            Marker::CYLINDER,
            [0.0; 3],
            [2.0 * radius, 2.0 * radius, 2.0 * half_height],
            0,
        )],
        Shape::Capsule {
            half_height,
            radius,
        } => {
            let d = 2.0 * radius;
            vec![
                part(Marker::CYLINDER, [0.0; 3], [d, d, 2.0 * half_height], 0),
                part(Marker::SPHERE, [0.0, 0.0, *half_height], [d; 3], 1),
                part(Marker::SPHERE, [0.0, 0.0, -half_height], [d; 3], 2),
            ]
        }
        Shape::ConvexHull { .. } | Shape::Mesh { .. } => {
            // The recorded scenario's files are absolute.
            let mesh = tactile_world::surface(shape, Path::new(""), field)?.unwrap_or_else(|| {
                tactile_world::mesh::Mesh {
                    vertices: Vec::new(),
                    triangles: Vec::new(),
                }
            });
            let points = mesh
                .triangles
                .iter()
                .flat_map(|t| t.map(|i| mesh.vertices.get(i as usize).copied().unwrap_or_default()))
                .collect();
            vec![Marker {
                points,
                ..part(Marker::TRIANGLE_LIST, [0.0; 3], [1.0; 3], 0)
            }]
        }
    })
}

/// The pose `at` applied to a part's pose (`p`, `q`) in the body's frame: the part's
/// pose in the world.
fn compose(at: &BodyPose, p: [f64; 3], q: [f64; 4]) -> ([f64; 3], [f64; 4]) {
    let [x, y, z, w] = at.rotation;
    let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
    let [qx, qy, qz, qw] = q;
    let local =
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(qw, qx, qy, qz));
    let pos = r * nalgebra::Vector3::from(p) + nalgebra::Vector3::from(at.position);
    let o = r * local;
    (pos.into(), [o.i, o.j, o.k, o.w])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A part off the body's centre turns with the body: a capsule's top cap, the
    /// body turned a quarter about x, sits along -y of the centre.
    #[test]
    fn a_part_is_placed_by_its_bodys_pose() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let at = BodyPose {
            position: [1.0, 2.0, 3.0],
            rotation: [h, 0.0, 0.0, h],
        };
        let (p, q) = compose(&at, [0.0, 0.0, 0.5], IDENTITY);
        assert!(
            (p[0] - 1.0).abs() < 1e-12 && (p[1] - 1.5).abs() < 1e-12 && (p[2] - 3.0).abs() < 1e-12,
            "{p:?}"
        );
        assert!(
            (q[0] - h).abs() < 1e-12 && (q[3] - h).abs() < 1e-12,
            "{q:?}"
        );
    }
}
