//! The scenario's shapes as rapier's: primitives directly, hulls from points or a
//! mesh file's vertices, triangle meshes from files. Every file is read through
//! [`crate::mesh::read`] (size and triangle caps), every vertex scaled to metres and
//! bounded, and the engine's own constructors (which may panic on degenerate input in
//! some versions) run inside a guard, so a bad file is an error naming the field.

use crate::error::{invalid, WorldError};
use crate::mesh::{self, Mesh};
use crate::Pose;
use nalgebra::{Point3, Vector3};
use rapier3d_f64::prelude::{SharedShape, TriMeshFlags};
use std::path::Path;
use tactile_scenario::world::Shape;
use tactile_scenario::MAX_SIZE_M;

/// One link of the arm as the world sees it: its name and its collision shapes, each
/// at a pose in the link's frame (a URDF link's `<collision>` elements).
#[derive(Debug, Clone, PartialEq)]
pub struct LinkShape {
    /// The link's name.
    pub name: String,
    /// Its shapes (box, sphere, capsule, cylinder; a mesh is read from its file).
    pub shapes: Vec<(Pose, Shape)>,
}

/// Whether the shape must enclose a volume (a dynamic body's): a mesh is then taken
/// as its convex hull, after it is checked closed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Use {
    /// A static or kinematic body: any surface.
    Surface,
    /// A dynamic body (or the tool): a solid.
    Solid,
}

/// Runs one of the engine's constructors, a panic turned into an error.
fn guarded<T>(field: &str, f: impl FnOnce() -> Option<T>) -> Result<T, WorldError> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(Some(s)) => Ok(s),
        Ok(None) => Err(invalid(
            field,
            "the engine cannot make a solid of it (fewer than 4 points not in one plane?)",
        )),
        Err(_) => Err(invalid(
            field,
            "the engine failed on it (degenerate geometry)",
        )),
    }
}

fn points(v: &[[f64; 3]], field: &str) -> Result<Vec<Point3<f64>>, WorldError> {
    v.iter()
        .enumerate()
        .map(|(k, p)| {
            if p.iter().any(|x| !x.is_finite() || x.abs() > MAX_SIZE_M) {
                return Err(invalid(
                    field,
                    format!("vertex {k} is beyond {MAX_SIZE_M} m once scaled"),
                ));
            }
            Ok(Point3::from(*p))
        })
        .collect()
}

fn load(file: &str, base_dir: &Path, field: &str) -> Result<Mesh, WorldError> {
    let path = base_dir.join(file);
    mesh::read(&path).map_err(|e| match e {
        mesh::MeshError::Io { .. }
        | mesh::MeshError::TooLarge { .. }
        | mesh::MeshError::UnknownFormat { .. } => invalid(field, e.to_string()),
        _ => invalid(field, format!("{}: {e}", path.display())),
    })
}

/// A convex hull's points, scaled and checked, and the field they came from
/// (`points` or `file`); errors name it. One reading for the engine's shape and the
/// viewer's surface.
fn hull_points(
    shape: &Shape,
    base_dir: &Path,
    field: &str,
) -> Result<(Vec<Point3<f64>>, String), WorldError> {
    match shape {
        Shape::ConvexHull {
            points: Some(p),
            scale,
            ..
        } => {
            let f = format!("{field}.points");
            let scaled: Vec<[f64; 3]> = p.iter().map(|v| v.map(|x| x * scale)).collect();
            Ok((points(&scaled, &f)?, f))
        }
        Shape::ConvexHull {
            file: Some(file),
            scale,
            ..
        } => {
            let f = format!("{field}.file");
            let m = load(file, base_dir, &f)?;
            Ok((points(&m.scaled(*scale), &f)?, f))
        }
        _ => Err(invalid(field, "a convex_hull takes `points` or `file`")),
    }
}

/// The rapier shape of `shape`; `field` names it in errors (`...shape`).
pub(crate) fn shared(
    shape: &Shape,
    base_dir: &Path,
    use_: Use,
    field: &str,
) -> Result<SharedShape, WorldError> {
    Ok(match shape {
        Shape::Box { half_extents: h } => SharedShape::cuboid(h[0], h[1], h[2]),
        Shape::Sphere { radius } => SharedShape::ball(*radius),
        Shape::Capsule {
            half_height,
            radius,
        } => SharedShape::capsule_z(*half_height, *radius),
        Shape::Cylinder {
            half_height,
            radius,
        } => {
            // rapier's cylinder stands along y; the scenario's along z.
            let turn = nalgebra::Isometry3::rotation(Vector3::x() * std::f64::consts::FRAC_PI_2);
            SharedShape::compound(vec![(turn, SharedShape::cylinder(*half_height, *radius))])
        }
        Shape::ConvexHull { .. } => {
            let (pts, f) = hull_points(shape, base_dir, field)?;
            guarded(&f, || SharedShape::convex_hull(&pts))?
        }
        Shape::Mesh { file, scale } => {
            let f = format!("{field}.file");
            let m = load(file, base_dir, &f)?;
            let pts = points(&m.scaled(*scale), &f)?;
            if use_ == Use::Solid {
                m.check_closed().map_err(|e| {
                    invalid(&f, format!("{e}: a dynamic body's mesh must be closed (it is taken as its convex hull)"))
                })?;
                guarded(&f, || SharedShape::convex_hull(&pts))?
            } else {
                let tris = m.triangles.clone();
                guarded(&f, || {
                    SharedShape::trimesh_with_flags(pts, tris, TriMeshFlags::FIX_INTERNAL_EDGES)
                        .ok()
                })?
            }
        }
    })
}

/// The triangles a viewer draws for a hull or a mesh, m in the body's frame: a mesh
/// file's own triangles (scaled), a hull's surface (the engine's convex hull of its
/// points or its file's vertices); None for the primitives, which a viewer has shapes
/// of. Files are read as the world reads them (`base_dir` resolves a relative one);
/// errors name `field`.
pub fn surface(shape: &Shape, base_dir: &Path, field: &str) -> Result<Option<Mesh>, WorldError> {
    let hull = |pts: Vec<Point3<f64>>, f: &str| {
        let (v, t) = guarded(f, || {
            rapier3d_f64::parry::transformation::try_convex_hull(&pts).ok()
        })?;
        Ok::<_, WorldError>(Some(Mesh {
            vertices: v.iter().map(|p| [p.x, p.y, p.z]).collect(),
            triangles: t,
        }))
    };
    match shape {
        Shape::ConvexHull {
            points: None,
            file: None,
            ..
        } => Ok(None),
        Shape::ConvexHull { .. } => {
            let (pts, f) = hull_points(shape, base_dir, field)?;
            hull(pts, &f)
        }
        Shape::Mesh { file, scale } => {
            let f = format!("{field}.file");
            let m = load(file, base_dir, &f)?;
            let vertices = m.scaled(*scale);
            points(&vertices, &f)?;
            Ok(Some(Mesh {
                vertices,
                triangles: m.triangles,
            }))
        }
        _ => Ok(None),
    }
}

/// The collision shapes of the arm's `links` (by name, in that order) from its URDF:
/// boxes, cylinders and spheres as they are, meshes by the file `resolve` finds for
/// their `filename` (a `package://` path, a path relative to the URDF). A link
/// without a `<collision>` has no shape (it touches nothing); a link the robot does not
/// have, a mesh `resolve` cannot find or one scaled unevenly is an error naming it.
pub fn link_shapes(
    robot: &tactile_chain::Robot,
    links: &[&str],
    resolve: impl Fn(&str) -> Option<std::path::PathBuf>,
) -> Result<Vec<LinkShape>, WorldError> {
    use tactile_chain::urdf::Geometry;
    links
        .iter()
        .map(|name| {
            let link = robot
                .link(name)
                .ok_or_else(|| invalid(format!("link `{name}`"), "is not a link of the URDF"))?;
            let mut shapes = Vec::with_capacity(link.collisions.len());
            for (k, c) in link.collisions.iter().enumerate() {
                let at = format!("link `{name}` collision[{k}]");
                let shape = match &c.geometry {
                    Geometry::Box { size } => Shape::Box {
                        half_extents: size.map(|s| s / 2.0),
                    },
                    Geometry::Cylinder { radius, length } => Shape::Cylinder {
                        half_height: length / 2.0,
                        radius: *radius,
                    },
                    Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
                    Geometry::Mesh { filename, scale } => {
                        if scale.iter().any(|s| *s != scale[0]) {
                            return Err(invalid(at, format!("mesh {filename} is scaled unevenly ({scale:?}): a world takes one scale")));
                        }
                        let file = resolve(filename)
                            .ok_or_else(|| invalid(&at, format!("mesh {filename} is not found")))?;
                        Shape::Mesh {
                            file: file.display().to_string(),
                            scale: scale[0],
                        }
                    }
                };
                let q = nalgebra::UnitQuaternion::from_matrix(&c.origin.r);
                let pose = Pose {
                    position: c.origin.p.into(),
                    rotation: [q.i, q.j, q.k, q.w],
                };
                shapes.push((pose, shape));
            }
            Ok(LinkShape {
                name: (*name).to_string(),
                shapes,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What a viewer draws: a hull's surface (a tetrahedron's four faces, the point
    /// inside left out), a mesh's own triangles scaled, nothing for a primitive.
    #[test]
    fn a_hull_or_a_mesh_is_drawn_as_triangles_and_a_primitive_is_not() {
        let hull = Shape::ConvexHull {
            points: Some(vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.1, 0.1, 0.1],
            ]),
            file: None,
            scale: 0.5,
        };
        let m = surface(&hull, Path::new(""), "f")
            .expect("hull")
            .expect("triangles");
        assert_eq!((m.vertices.len(), m.triangles.len()), (4, 4));
        assert!(m
            .vertices
            .iter()
            .all(|v| v.iter().all(|x| (0.0..=0.5).contains(x))));
        let dir = tempfile::tempdir().expect("tempdir");
        let peg = Mesh::prism(6, 1.0, 2.0);
        std::fs::write(dir.path().join("peg.obj"), crate::mesh::to_obj(&peg)).expect("write");
        let mesh = Shape::Mesh {
            file: "peg.obj".into(),
            scale: 0.01,
        };
        let m = surface(&mesh, dir.path(), "f")
            .expect("mesh")
            .expect("triangles");
        assert_eq!(m.triangles, peg.triangles);
        assert_eq!(m.vertices, peg.scaled(0.01));
        let ball = Shape::Sphere { radius: 0.1 };
        assert_eq!(surface(&ball, dir.path(), "f").expect("ball"), None);
    }
}
