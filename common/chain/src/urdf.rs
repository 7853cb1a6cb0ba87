//! URDF, read: the links' inertias and the joints (type, origin, axis, limits,
//! dynamics, mimic), checked as they are read so that a fault names its element.
//! Only what a serial chain and a physics world need: visuals are the viewers'
//! business, collisions are read ([`collision`]).

use crate::error::Error;
use crate::spatial::Frame;
use nalgebra::{Matrix3, Vector3};
use roxmltree::{Document, Node};
use tactile_math::shown::Num;

#[path = "urdf_collision.rs"]
mod collision;
pub use collision::{Collision, Geometry};

/// xacro's XML namespace.
const XACRO: &str = "http://www.ros.org/wiki/xacro";

/// The longest offset an `<origin xyz>` may give, m: no robot's link is 10 km long,
/// and with this bound every sum, product and square the chain and its dynamics
/// form from a file under the slave's size cap stays finite.
pub const MAX_LENGTH_M: f64 = 1e4;

/// The heaviest link, kg (a large excavator's arm is a few tonnes).
pub const MAX_MASS_KG: f64 = 1e6;

/// The largest principal moment of inertia, kg m^2 (the heaviest link spread 30 m
/// from its centre).
pub const MAX_INERTIA: f64 = 1e9;

/// How far, relative to the largest principal moment, a link's inertia may miss
/// positive semi-definiteness: the eigen-decomposition's rounding, no more (a
/// negative moment is refused).
const INERTIA_TOLERANCE: f64 = 1e-6;

/// How far, relative to the largest principal moment, the two smaller may fall short
/// of it together (the triangle inequality). A flat body (disc, plate) sits exactly
/// at `Ixx + Iyy = Izz`, so a CAD export rounded to two significant digits misses it
/// by up to a few percent (`1.2e-5, 1.2e-5, 2.5e-5` misses by 4 %); 5 % takes that
/// and still refuses a body that breaks the inequality (`1, 1, 3`).
const TRIANGLE_TOLERANCE: f64 = 0.05;

/// A link's `<inertial>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Inertial {
    /// The centre of mass frame in the link's.
    pub origin: Frame,
    /// kg.
    pub mass: f64,
    /// Rotational inertia about the centre, in the centre's frame, kg m^2.
    pub inertia: Matrix3<f64>,
}

/// A `<link>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Its name.
    pub name: String,
    /// Its mass properties, if given.
    pub inertial: Option<Inertial>,
    /// Its `<collision>` shapes, in file order.
    pub collisions: Vec<Collision>,
}

/// A joint's type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointType {
    /// Turns within limits.
    Revolute,
    /// Turns without limits.
    Continuous,
    /// Slides within limits.
    Prismatic,
    /// Does not move.
    Fixed,
    /// Six degrees of freedom (not part of a serial arm).
    Floating,
    /// Two translations and a turn (not part of a serial arm).
    Planar,
}

/// A `<limit>`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// Lowest position, rad or m.
    pub lower: f64,
    /// Highest position, rad or m.
    pub upper: f64,
    /// Largest effort, N m or N.
    pub effort: f64,
    /// Largest speed, rad/s or m/s.
    pub velocity: f64,
}

/// A `<mimic>`: this joint's position is `multiplier * q(joint) + offset`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mimic {
    /// The joint it follows.
    pub joint: String,
    /// Gain.
    pub multiplier: f64,
    /// Offset, rad or m.
    pub offset: f64,
}

/// A `<joint>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Its name.
    pub name: String,
    /// Its type.
    pub kind: JointType,
    /// The parent link.
    pub parent: String,
    /// The child link.
    pub child: String,
    /// The child frame at zero position, in the parent's.
    pub origin: Frame,
    /// The unit axis in the child frame.
    pub axis: Vector3<f64>,
    /// Its limits, if given.
    pub limit: Option<Limit>,
    /// Viscous damping, N m s/rad or N s/m.
    pub damping: f64,
    /// Whom it follows, if anyone.
    pub mimic: Option<Mimic>,
}

/// A URDF robot: its links and joints as written.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    /// `<robot name>`.
    pub name: String,
    /// The links, in file order.
    pub links: Vec<Link>,
    /// The joints, in file order.
    pub joints: Vec<Joint>,
}

impl Robot {
    /// Reads a URDF document.
    pub fn parse(xml: &str) -> Result<Robot, Error> {
        // A URDF made by xacro keeps the namespace declaration; only xacro's own
        // elements (or an undeclared `xacro:` prefix) say the macros are unexpanded.
        let doc = Document::parse(xml).map_err(|e| {
            let text = e.to_string();
            if text.contains("xacro") {
                Error::Xacro
            } else {
                Error::Xml(text)
            }
        })?;
        if doc
            .descendants()
            .any(|n| n.tag_name().namespace() == Some(XACRO))
        {
            return Err(Error::Xacro);
        }
        let root = doc.root_element();
        if root.tag_name().name() != "robot" {
            return Err(Error::Xml(format!(
                "the root element is <{}>, not <robot>",
                root.tag_name().name()
            )));
        }
        let mut robot = Robot {
            name: root.attribute("name").unwrap_or_default().to_string(),
            links: Vec::new(),
            joints: Vec::new(),
        };
        for n in root.children().filter(Node::is_element) {
            match n.tag_name().name() {
                "link" => robot.links.push(link(n)?),
                "joint" => robot.joints.push(joint(n)?),
                _ => {}
            }
        }
        Ok(robot)
    }

    /// The link called `name`.
    pub fn link(&self, name: &str) -> Option<&Link> {
        self.links.iter().find(|l| l.name == name)
    }
}

/// The text of every top-level element of `xml` whose tag is one of `tags`, in file
/// order, exactly as written: to put a robot's links and joints into another URDF.
pub fn elements<'a>(xml: &'a str, tags: &[&str]) -> Result<Vec<&'a str>, Error> {
    let doc = Document::parse(xml).map_err(|e| Error::Xml(e.to_string()))?;
    Ok(doc
        .root_element()
        .children()
        .filter(|n| n.is_element() && tags.contains(&n.tag_name().name()))
        .map(|n| &xml[n.range()])
        .collect())
}

/// What an element is, for errors: `joint `panda_joint1``.
fn what(n: Node) -> String {
    format!(
        "{} `{}`",
        n.tag_name().name(),
        n.attribute("name").unwrap_or("?")
    )
}

fn named(n: Node) -> Result<String, Error> {
    match n.attribute("name") {
        Some(s) if !s.is_empty() => Ok(s.to_string()),
        _ => Err(Error::Field {
            at: format!("a <{}>", n.tag_name().name()),
            field: "name".into(),
            problem: "missing".into(),
        }),
    }
}

fn child<'a>(n: Node<'a, 'a>, tag: &str) -> Option<Node<'a, 'a>> {
    n.children().find(|c| c.has_tag_name(tag))
}

fn bad(at: &Node, field: &str, problem: impl Into<String>) -> Error {
    Error::Field {
        at: what(*at),
        field: field.into(),
        problem: problem.into(),
    }
}

/// A finite number attribute, `default` when absent.
fn number(owner: &Node, n: Node, attr: &str, default: Option<f64>) -> Result<f64, Error> {
    let field = format!("{} {attr}", n.tag_name().name());
    match n.attribute(attr) {
        None => default.ok_or_else(|| bad(owner, &field, "missing")),
        Some(s) => match s.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(bad(owner, &field, format!("`{s}` is not a finite number"))),
        },
    }
}

/// Three finite numbers, `[0; 3]` when absent.
fn triple(owner: &Node, n: Node, attr: &str) -> Result<[f64; 3], Error> {
    let Some(s) = n.attribute(attr) else {
        return Ok([0.0; 3]);
    };
    let field = format!("{} {attr}", n.tag_name().name());
    let v: Vec<f64> = s
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| bad(owner, &field, format!("`{s}` is not three finite numbers")))?;
    <[f64; 3]>::try_from(v).map_err(|_| bad(owner, &field, format!("`{s}` is not three numbers")))
}

/// An `<origin>`: each offset within [`MAX_LENGTH_M`], so that the frames the chain
/// composes stay finite.
fn origin(owner: &Node, holder: Node) -> Result<Frame, Error> {
    let Some(o) = child(holder, "origin") else {
        return Ok(Frame::IDENTITY);
    };
    let xyz = triple(owner, o, "xyz")?;
    if let Some(x) = xyz.iter().find(|x| x.abs() > MAX_LENGTH_M) {
        return Err(bad(
            owner,
            "origin xyz",
            format!(
                "{} m is further than {MAX_LENGTH_M} m: not a robot's link",
                Num(*x)
            ),
        ));
    }
    let f = Frame::from_xyz_rpy(xyz, triple(owner, o, "rpy")?);
    match f.r.iter().chain(f.p.iter()).all(|v| v.is_finite()) {
        true => Ok(f),
        false => Err(bad(owner, "origin", "does not make a finite transform")),
    }
}

fn link(n: Node) -> Result<Link, Error> {
    let name = named(n)?;
    let collisions = collision::collisions(n)?;
    let Some(i) = child(n, "inertial") else {
        return Ok(Link {
            name,
            inertial: None,
            collisions,
        });
    };
    let mass = child(i, "mass").ok_or_else(|| bad(&n, "inertial mass", "missing"))?;
    let mass = number(&n, mass, "value", None)?;
    if !(0.0..=MAX_MASS_KG).contains(&mass) {
        return Err(bad(
            &n,
            "mass value",
            format!("{} kg is outside 0 to {MAX_MASS_KG} kg", Num(mass)),
        ));
    }
    let t = child(i, "inertia").ok_or_else(|| bad(&n, "inertial inertia", "missing"))?;
    let e = |a: &str| number(&n, t, a, Some(0.0));
    let (xx, xy, xz, yy, yz, zz) = (
        e("ixx")?,
        e("ixy")?,
        e("ixz")?,
        e("iyy")?,
        e("iyz")?,
        e("izz")?,
    );
    let inertia = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    physical(&inertia).map_err(|p| bad(&n, "inertia", p))?;
    Ok(Link {
        name,
        inertial: Some(Inertial {
            origin: origin(&n, i)?,
            mass,
            inertia,
        }),
        collisions,
    })
}

/// Whether a rotational inertia is one a rigid body can have: its principal moments
/// non-negative, at most [`MAX_INERTIA`], and none larger than the other two together
/// (the triangle inequality: `Ixx + Iyy >= Izz` about the principal axes). Anything
/// else makes the articulated-body algorithm's inertias indefinite, and every step of
/// the dynamics fails or diverges.
fn physical(i: &Matrix3<f64>) -> Result<(), String> {
    let mut m: Vec<f64> = i.symmetric_eigen().eigenvalues.iter().copied().collect();
    m.sort_by(f64::total_cmp);
    let (a, b, c) = (m[0], m[1], m[2]);
    let tol = INERTIA_TOLERANCE * c.abs();
    let moments = format!(
        "principal moments {}, {}, {} kg m^2",
        Num(a),
        Num(b),
        Num(c)
    );
    if !(a.is_finite() && c.is_finite()) || c > MAX_INERTIA {
        return Err(format!("{moments}: not within 0 to {MAX_INERTIA:e}"));
    }
    if a < -tol {
        return Err(format!(
            "{moments}: one is negative (not positive semi-definite)"
        ));
    }
    if a + b < c - TRIANGLE_TOLERANCE * c.abs() {
        return Err(format!(
            "{moments}: the largest exceeds the other two together (the triangle inequality)"
        ));
    }
    Ok(())
}

fn kind(n: &Node) -> Result<JointType, Error> {
    Ok(match n.attribute("type").unwrap_or("") {
        "revolute" => JointType::Revolute,
        "continuous" => JointType::Continuous,
        "prismatic" => JointType::Prismatic,
        "fixed" => JointType::Fixed,
        "floating" => JointType::Floating,
        "planar" => JointType::Planar,
        other => {
            return Err(bad(
                n,
                "type",
                format!("`{other}` is not a URDF joint type"),
            ))
        }
    })
}

fn link_of(n: &Node, tag: &str) -> Result<String, Error> {
    child(*n, tag)
        .and_then(|c| c.attribute("link"))
        .filter(|s| !s.is_empty())
        .map(str::to_string)
        .ok_or_else(|| bad(n, &format!("{tag} link"), "missing"))
}

/// A moving joint's unit axis. A fixed or floating joint's is not read: URDF (and
/// urdfdom) ignore it, and real files write `0 0 0` there. The vector is scaled by
/// its largest component before its norm is taken, so no finite axis overflows.
fn axis(n: &Node, k: JointType) -> Result<Vector3<f64>, Error> {
    let a = match child(*n, "axis") {
        Some(a) if !matches!(k, JointType::Fixed | JointType::Floating) => a,
        _ => return Ok(Vector3::x()),
    };
    let v = Vector3::from(triple(n, a, "xyz")?);
    let big = v.amax();
    if big < 1e-9 {
        return Err(bad(n, "axis xyz", "is zero"));
    }
    Ok((v / big).normalize())
}

/// A joint's `<limit>`: required for revolute and prismatic joints, with its `effort`
/// and `velocity` (as URDF and urdfdom require them); a fixed joint's is ignored.
fn limit(n: &Node, k: JointType) -> Result<Option<Limit>, Error> {
    if k == JointType::Fixed {
        return Ok(None);
    }
    let Some(l) = child(*n, "limit") else {
        return match k {
            JointType::Revolute | JointType::Prismatic => {
                Err(bad(n, "limit", "missing (required for this type)"))
            }
            _ => Ok(None),
        };
    };
    let lim = Limit {
        lower: number(n, l, "lower", Some(0.0))?,
        upper: number(n, l, "upper", Some(0.0))?,
        effort: required(
            n,
            l,
            "effort",
            "the motor's largest effort, N m (N for a prismatic joint)",
        )?,
        velocity: required(
            n,
            l,
            "velocity",
            "the largest speed, rad/s (m/s for a prismatic joint)",
        )?,
    };
    if k != JointType::Continuous && lim.lower > lim.upper {
        return Err(bad(
            n,
            "limit",
            format!("lower {} is above upper {}", Num(lim.lower), Num(lim.upper)),
        ));
    }
    if lim.velocity < 0.0 || lim.effort < 0.0 {
        return Err(bad(n, "limit", "velocity and effort must not be negative"));
    }
    Ok(Some(lim))
}

/// A number URDF requires; missing, the error says what to write.
fn required(owner: &Node, n: Node, attr: &str, what: &str) -> Result<f64, Error> {
    match n.attribute(attr) {
        None => Err(bad(
            owner,
            &format!("limit {attr}"),
            format!("missing: URDF requires it; write {attr}=\"...\", {what}"),
        )),
        Some(_) => number(owner, n, attr, None),
    }
}

/// `<dynamics damping friction>`: neither may be negative (a negative damping pumps
/// energy into the joint every step).
fn damping(n: &Node) -> Result<f64, Error> {
    let Some(d) = child(*n, "dynamics") else {
        return Ok(0.0);
    };
    for attr in ["damping", "friction"] {
        let v = number(n, d, attr, Some(0.0))?;
        if v < 0.0 {
            return Err(bad(
                n,
                &format!("dynamics {attr}"),
                format!(
                    "{} is negative: it would push the joint, not resist it",
                    Num(v)
                ),
            ));
        }
    }
    number(n, d, "damping", Some(0.0))
}

fn joint(n: Node) -> Result<Joint, Error> {
    let name = named(n)?;
    let k = kind(&n)?;
    let damping = damping(&n)?;
    let mimic = match child(n, "mimic") {
        None => None,
        Some(m) => Some(Mimic {
            joint: m
                .attribute("joint")
                .filter(|s| !s.is_empty())
                .ok_or_else(|| bad(&n, "mimic joint", "missing"))?
                .to_string(),
            multiplier: number(&n, m, "multiplier", Some(1.0))?,
            offset: number(&n, m, "offset", Some(0.0))?,
        }),
    };
    Ok(Joint {
        kind: k,
        parent: link_of(&n, "parent")?,
        child: link_of(&n, "child")?,
        origin: origin(&n, n)?,
        axis: axis(&n, k)?,
        limit: limit(&n, k)?,
        damping,
        mimic,
        name,
    })
}

#[cfg(test)]
#[path = "urdf_tests.rs"]
mod tests;
