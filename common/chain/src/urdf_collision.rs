//! A link's `<collision>` elements: the shapes a physics world gives the link (a box,
//! a cylinder along the element's z, a sphere, or a mesh file named as written,
//! `package://` paths included: resolving them is the world's business).

use super::{bad, child, number, origin, triple};
use crate::spatial::Frame;
use roxmltree::Node;
use tactile_math::shown::Num;

/// A `<collision>`'s geometry.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// `<box size>`: full sizes along x, y, z, m.
    Box {
        /// Sizes, m.
        size: [f64; 3],
    },
    /// `<cylinder radius length>`, along z.
    Cylinder {
        /// Radius, m.
        radius: f64,
        /// Length, m.
        length: f64,
    },
    /// `<sphere radius>`.
    Sphere {
        /// Radius, m.
        radius: f64,
    },
    /// `<mesh filename scale>`.
    Mesh {
        /// As written (`package://...`, a relative or absolute path).
        filename: String,
        /// Scale per axis (default 1).
        scale: [f64; 3],
    },
}

/// A `<collision>`: its geometry at `origin` in the link's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Collision {
    /// The geometry's frame in the link's.
    pub origin: Frame,
    /// The shape.
    pub geometry: Geometry,
}

fn size(owner: &Node, v: f64, field: &str) -> Result<f64, crate::Error> {
    if v > 0.0 && v <= super::MAX_LENGTH_M {
        return Ok(v);
    }
    Err(bad(
        owner,
        field,
        format!(
            "{} m must be positive and at most {} m",
            Num(v),
            super::MAX_LENGTH_M
        ),
    ))
}

/// The `<collision>` elements of link element `n` whose geometry is one of URDF's four
/// (any other element inside `<geometry>` is left out, as urdfdom leaves it out).
pub(super) fn collisions(n: Node) -> Result<Vec<Collision>, crate::Error> {
    let mut out = Vec::new();
    for c in n.children().filter(|c| c.has_tag_name("collision")) {
        let Some(g) = child(c, "geometry").and_then(|g| g.children().find(Node::is_element)) else {
            continue;
        };
        let geometry = match g.tag_name().name() {
            "box" => {
                let s = triple(&n, g, "size")?;
                for (i, v) in s.iter().enumerate() {
                    size(&n, *v, &format!("collision box size[{i}]"))?;
                }
                Geometry::Box { size: s }
            }
            "cylinder" => Geometry::Cylinder {
                radius: size(
                    &n,
                    number(&n, g, "radius", None)?,
                    "collision cylinder radius",
                )?,
                length: size(
                    &n,
                    number(&n, g, "length", None)?,
                    "collision cylinder length",
                )?,
            },
            "sphere" => Geometry::Sphere {
                radius: size(
                    &n,
                    number(&n, g, "radius", None)?,
                    "collision sphere radius",
                )?,
            },
            "mesh" => Geometry::Mesh {
                filename: g
                    .attribute("filename")
                    .filter(|f| !f.is_empty())
                    .ok_or_else(|| bad(&n, "collision mesh filename", "missing"))?
                    .to_string(),
                scale: match g.attribute("scale") {
                    None => [1.0; 3],
                    Some(_) => {
                        let s = triple(&n, g, "scale")?;
                        for (i, v) in s.iter().enumerate() {
                            size(&n, *v, &format!("collision mesh scale[{i}]"))?;
                        }
                        s
                    }
                },
            },
            _ => continue,
        };
        out.push(Collision {
            origin: origin(&n, c)?,
            geometry,
        });
    }
    Ok(out)
}
