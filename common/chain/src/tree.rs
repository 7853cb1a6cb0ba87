//! A whole URDF robot as a viewer draws it: every joint's transform from its parent
//! link to its child, what `robot_state_publisher` puts on `/tf` (moving joints) and
//! `/tf_static` (fixed ones). A chain ([`crate::Chain`]) knows only the joints from its
//! base to its tip; a viewer needs every link (a gripper's fingers, a flange), so the
//! joints off the chain are drawn at rest: zero, or the nearest limit when zero is out
//! of range.

use crate::error::Error;
use crate::spatial::Frame;
use crate::topology::Index;
use crate::urdf::{JointType, Robot};
use nalgebra::{Unit, Vector3};
use std::collections::HashMap;

/// A transform of the tree: `(parent link, child link, child frame in the parent's)`.
pub type Edge<'a> = (&'a str, &'a str, Frame);

/// A joint that moves.
#[derive(Debug, Clone, PartialEq)]
struct Moving {
    name: String,
    parent: String,
    child: String,
    origin: Frame,
    axis: Unit<Vector3<f64>>,
    prismatic: bool,
    /// `(followed joint, multiplier, offset)` for a mimic joint.
    mimic: Option<(String, f64, f64)>,
    /// Its position when nobody gives one.
    rest: f64,
}

impl Moving {
    fn frame(&self, x: f64) -> Frame {
        let motion = if self.prismatic {
            Frame::translation(self.axis.into_inner() * x)
        } else {
            Frame::rotation(&self.axis, x)
        };
        self.origin.then(&motion)
    }
}

/// Every joint of a URDF robot, for drawing it.
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    /// The link no joint has as its child.
    pub root: String,
    /// The fixed joints (floating and planar ones too, at their origin: a viewer gets
    /// their pose from elsewhere).
    fixed: Vec<(String, String, Frame)>,
    moving: Vec<Moving>,
    /// Each moving joint's rest position by name (what a mimic follows by default).
    rests: HashMap<String, f64>,
}

impl Tree {
    /// The tree of `robot`: one root, every other link the child of one joint.
    pub fn new(robot: &Robot) -> Result<Tree, Error> {
        let index = Index::new(robot)?;
        let mut tree = Tree {
            root: index.root().to_string(),
            fixed: Vec::new(),
            moving: Vec::new(),
            rests: HashMap::new(),
        };
        for j in &robot.joints {
            let edge = (j.parent.clone(), j.child.clone(), j.origin);
            let prismatic = match j.kind {
                JointType::Revolute | JointType::Continuous => false,
                JointType::Prismatic => true,
                JointType::Fixed | JointType::Floating | JointType::Planar => {
                    tree.fixed.push(edge);
                    continue;
                }
            };
            let (lower, upper) = j.limit.map_or((0.0, 0.0), |l| (l.lower, l.upper));
            let rest = if j.kind == JointType::Continuous || lower > upper {
                0.0
            } else {
                0.0_f64.clamp(lower, upper)
            };
            tree.rests.insert(j.name.clone(), rest);
            tree.moving.push(Moving {
                name: j.name.clone(),
                parent: j.parent.clone(),
                child: j.child.clone(),
                origin: j.origin,
                axis: Unit::new_normalize(j.axis),
                prismatic,
                mimic: j
                    .mimic
                    .as_ref()
                    .map(|m| (m.joint.clone(), m.multiplier, m.offset)),
                rest,
            });
        }
        Ok(tree)
    }

    /// The transforms that never move (`/tf_static`).
    pub fn fixed(&self) -> impl Iterator<Item = Edge<'_>> {
        self.fixed
            .iter()
            .map(|(p, c, f)| (p.as_str(), c.as_str(), *f))
    }

    /// The names of the joints that move, in file order.
    pub fn moving_names(&self) -> impl Iterator<Item = &str> {
        self.moving.iter().map(|m| m.name.as_str())
    }

    /// Each moving joint's transform (`/tf`) for the positions `value` gives by joint
    /// name; a mimic joint follows its joint, any other joint `value` does not know
    /// is at rest.
    pub fn moving<'a>(
        &'a self,
        value: &'a dyn Fn(&str) -> Option<f64>,
    ) -> impl Iterator<Item = Edge<'a>> + 'a {
        self.moving.iter().map(move |m| {
            let x = match &m.mimic {
                Some((followed, k, offset)) => {
                    let of = value(followed).or_else(|| self.rest_of(followed));
                    of.map_or(m.rest, |v| k * v + offset)
                }
                None => value(&m.name).unwrap_or(m.rest),
            };
            (m.parent.as_str(), m.child.as_str(), m.frame(x))
        })
    }

    fn rest_of(&self, joint: &str) -> Option<f64> {
        self.rests.get(joint).copied()
    }

    /// Link `link`'s frame in the root's for the positions `value` gives (what
    /// composing the tree's transforms from the root gives); None for no such link.
    pub fn pose(&self, link: &str, value: &dyn Fn(&str) -> Option<f64>) -> Option<Frame> {
        let edges: HashMap<&str, (&str, Frame)> = self
            .fixed()
            .chain(self.moving(value))
            .map(|(p, c, f)| (c, (p, f)))
            .collect();
        let mut at = link;
        let mut frame = Frame::IDENTITY;
        // Each step climbs one joint; a tree of n joints has no path longer than n.
        for _ in 0..=edges.len() {
            if at == self.root {
                return Some(frame);
            }
            let (parent, f) = edges.get(at)?;
            frame = f.then(&frame);
            at = parent;
        }
        None
    }
}
