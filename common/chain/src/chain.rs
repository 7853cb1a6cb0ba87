//! A serial chain from a base link to a tip link, built from a URDF: its moving joints
//! in order, each with its origin (fixed joints folded in), axis, the joint it follows
//! if it is a mimic, and the mass of everything that moves with it. Links off the
//! chain (a gripper's fingers, a camera) ride rigidly on the link they hang from, at
//! their zero position, as Pinocchio's reduced models lock them.

use crate::error::Error;
use crate::spatial::{inertia, inertia_to_parent, Frame};
use crate::topology::Index;
use crate::urdf::{Joint as UrdfJoint, JointType, Robot};
use nalgebra::{Matrix6, Unit, Vector3};
use std::collections::{BTreeMap, HashSet};

/// How a moving joint moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// About its axis, rad.
    Revolute,
    /// Along its axis, m.
    Prismatic,
}

/// One degree of freedom: a joint the arm's controller commands.
#[derive(Debug, Clone, PartialEq)]
pub struct Dof {
    /// The URDF joint's name (what JointState and controllers call it).
    pub name: String,
    /// Lowest position (`-inf` for a continuous joint), rad or m.
    pub lower: f64,
    /// Highest position (`inf` for a continuous joint).
    pub upper: f64,
    /// Largest speed (`inf` where the URDF gives none), rad/s or m/s.
    pub velocity: f64,
    /// Largest effort as the URDF gives it (`inf` for a continuous joint without a
    /// `<limit>`), N m or N: the dynamics refuse anything but a positive finite one.
    pub effort: f64,
    /// Viscous damping, N m s/rad or N s/m.
    pub damping: f64,
}

/// A moving joint of the chain.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// The URDF joint's name.
    pub name: String,
    /// How it moves.
    pub kind: Kind,
    /// Its frame at zero position in the previous moving joint's frame (the base's for
    /// the first): the fixed joints between them folded in.
    pub origin: Frame,
    /// Its unit axis in its own frame.
    pub axis: Unit<Vector3<f64>>,
    /// The degree of freedom that drives it.
    pub dof: usize,
    /// Its position is `multiplier * q[dof] + offset` (1 and 0 unless a mimic).
    pub multiplier: f64,
    /// See `multiplier`.
    pub offset: f64,
    /// Spatial inertia of every link that moves rigidly with it, in its frame.
    pub body: Matrix6<f64>,
}

impl Joint {
    /// Its position for the arm's joint values `q`.
    pub fn position(&self, q: &[f64]) -> f64 {
        self.multiplier * q[self.dof] + self.offset
    }

    /// Its frame in the previous moving joint's at position `x`.
    pub fn frame(&self, x: f64) -> Frame {
        match self.kind {
            Kind::Revolute => self.origin.then(&Frame::rotation(&self.axis, x)),
            Kind::Prismatic => self
                .origin
                .then(&Frame::translation(self.axis.into_inner() * x)),
        }
    }
}

/// A serial arm from `base` to `tip`.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// The URDF's robot name.
    pub robot: String,
    /// The base link: poses and Jacobians are in its frame.
    pub base: String,
    /// The tip link: the pose the IK moves.
    pub tip: String,
    /// The moving joints, base to tip.
    pub joints: Vec<Joint>,
    /// The degrees of freedom, in chain order (mimic joints have none of their own).
    pub dofs: Vec<Dof>,
    /// The tip's frame in the last moving joint's.
    pub tip_frame: Frame,
}

fn chain_error(base: &str, tip: &str, problem: impl Into<String>) -> Error {
    Error::Chain {
        base: base.into(),
        tip: tip.into(),
        problem: problem.into(),
    }
}

impl Chain {
    /// Reads `xml` and makes the chain from `base` to `tip`.
    pub fn from_urdf(xml: &str, base: &str, tip: &str) -> Result<Chain, Error> {
        Chain::new(&Robot::parse(xml)?, base, tip)
    }

    /// The chain of `robot` from `base` to `tip`.
    pub fn new(robot: &Robot, base: &str, tip: &str) -> Result<Chain, Error> {
        let err = |p: String| chain_error(base, tip, p);
        // Two scans of the links: a link asked for that is not there says so first.
        for l in [base, tip] {
            if robot.link(l).is_none() {
                return Err(err(format!("the robot `{}` has no link `{l}`", robot.name)));
            }
        }
        let index = Index::new(robot)?;
        let path = path(&index, base, tip)?;
        let mut joints = Vec::new();
        // Each link on the chain: its body (None for the base's) and frame in it.
        let mut at: BTreeMap<&str, (Option<usize>, Frame)> = BTreeMap::new();
        at.insert(base, (None, Frame::IDENTITY));
        let mut acc = Frame::IDENTITY;
        for j in &path {
            let kind = match j.kind {
                JointType::Fixed => {
                    acc = acc.then(&j.origin);
                    let body = at.get(j.parent.as_str()).and_then(|b| b.0);
                    at.insert(&j.child, (body, acc));
                    continue;
                }
                JointType::Revolute | JointType::Continuous => Kind::Revolute,
                JointType::Prismatic => Kind::Prismatic,
                JointType::Floating | JointType::Planar => {
                    return Err(err(format!(
                        "joint `{}` is {:?}: a serial arm's joints turn or slide along one axis",
                        j.name, j.kind
                    )))
                }
            };
            joints.push(Joint {
                name: j.name.clone(),
                kind,
                origin: acc.then(&j.origin),
                axis: Unit::new_normalize(j.axis),
                dof: 0,
                multiplier: 1.0,
                offset: 0.0,
                body: Matrix6::zeros(),
            });
            acc = Frame::IDENTITY;
            at.insert(&j.child, (Some(joints.len() - 1), Frame::IDENTITY));
        }
        if joints.is_empty() {
            return Err(err("no joint moves between them".into()));
        }
        let dofs = assign_dofs(&path, &mut joints).map_err(err)?;
        fold_masses(&index, &path, at, &mut joints);
        Ok(Chain {
            robot: robot.name.clone(),
            base: base.into(),
            tip: tip.into(),
            joints,
            dofs,
            tip_frame: acc,
        })
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.dofs.len()
    }

    /// Whether some joint follows another (the dynamics refuse such chains).
    pub fn has_mimic(&self) -> bool {
        self.joints.len() != self.dofs.len()
    }

    /// `q` clamped into the joint limits.
    pub fn clamp(&self, q: &mut [f64]) -> usize {
        let mut n = 0;
        for (x, d) in q.iter_mut().zip(&self.dofs) {
            let c = x.clamp(d.lower, d.upper);
            n += usize::from(c != *x);
            *x = c;
        }
        n
    }

    /// An error unless `q` has one value per degree of freedom.
    pub fn check_len(&self, what: &'static str, q: &[f64]) -> Result<(), Error> {
        if q.len() == self.dof() {
            Ok(())
        } else {
            Err(Error::Length {
                what,
                got: q.len(),
                dof: self.dof(),
            })
        }
    }
}

/// The URDF joints from `base` down to `tip`, in that order.
fn path<'a>(index: &Index<'a>, base: &str, tip: &str) -> Result<Vec<&'a UrdfJoint>, Error> {
    let mut out = Vec::new();
    let mut link = tip;
    // The index is a tree: climbing from the tip ends at the root.
    while link != base {
        let Some(j) = index.parent_joint(link) else {
            return Err(chain_error(
                base,
                tip,
                format!("`{tip}` does not hang from `{base}`"),
            ));
        };
        out.push(j);
        link = &j.parent;
    }
    out.reverse();
    Ok(out)
}

/// Numbers the degrees of freedom and ties each mimic joint to the one it follows.
fn assign_dofs(path: &[&UrdfJoint], joints: &mut [Joint]) -> Result<Vec<Dof>, String> {
    let moving: Vec<&UrdfJoint> = path
        .iter()
        .copied()
        .filter(|j| j.kind != JointType::Fixed)
        .collect();
    let mut dofs = Vec::new();
    let mut index = BTreeMap::new();
    for (j, u) in joints.iter_mut().zip(&moving) {
        if u.mimic.is_some() {
            continue;
        }
        let lim = u.limit;
        let continuous = u.kind == JointType::Continuous;
        let or_inf = |v: f64| if v > 0.0 { v } else { f64::INFINITY };
        dofs.push(Dof {
            name: u.name.clone(),
            lower: if continuous {
                f64::NEG_INFINITY
            } else {
                lim.map_or(0.0, |l| l.lower)
            },
            upper: if continuous {
                f64::INFINITY
            } else {
                lim.map_or(0.0, |l| l.upper)
            },
            velocity: or_inf(lim.map_or(0.0, |l| l.velocity)),
            effort: lim.map_or(f64::INFINITY, |l| l.effort),
            damping: u.damping,
        });
        j.dof = dofs.len() - 1;
        index.insert(u.name.as_str(), j.dof);
    }
    for (j, u) in joints.iter_mut().zip(&moving) {
        if let Some(m) = &u.mimic {
            j.dof = *index.get(m.joint.as_str()).ok_or_else(|| {
                format!("joint `{}` mimics `{}`, which is not a joint of the chain that moves on its own", u.name, m.joint)
            })?;
            j.multiplier = m.multiplier;
            j.offset = m.offset;
        }
    }
    Ok(dofs)
}

/// Adds every link's inertia to the body it moves with: the links on the chain where
/// the chain put them, the others (off the chain, beyond the tip) at zero position.
fn fold_masses<'a>(
    index: &Index<'a>,
    path: &[&UrdfJoint],
    mut at: BTreeMap<&'a str, (Option<usize>, Frame)>,
    joints: &mut [Joint],
) {
    let on_path: HashSet<&str> = path.iter().map(|j| j.name.as_str()).collect();
    let mut todo: Vec<&'a str> = at.keys().copied().collect();
    while let Some(link) = todo.pop() {
        let (body, frame) = at[link];
        for j in index
            .children_of(link)
            .filter(|j| !on_path.contains(j.name.as_str()))
        {
            let x = j.mimic.as_ref().map_or(0.0, |m| m.offset);
            let axis = Unit::new_normalize(j.axis);
            let motion = match j.kind {
                JointType::Revolute | JointType::Continuous => Frame::rotation(&axis, x),
                JointType::Prismatic => Frame::translation(axis.into_inner() * x),
                _ => Frame::IDENTITY,
            };
            if !at.contains_key(j.child.as_str()) {
                at.insert(&j.child, (body, frame.then(&j.origin).then(&motion)));
                todo.push(&j.child);
            }
        }
    }
    for (link, (body, frame)) in at {
        let (Some(b), Some(i)) = (body, index.link(link).and_then(|l| l.inertial.as_ref())) else {
            continue;
        };
        let com = frame.then(&i.origin);
        let local = inertia(i.mass, &Vector3::zeros(), &i.inertia);
        joints[b].body += inertia_to_parent(&com, &local);
    }
}
