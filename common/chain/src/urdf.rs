//! URDF, read: the links' inertias and the joints (type, origin, axis, limits,
//! dynamics, mimic), checked as they are read so that a fault names its element.
//! Only what a serial chain needs; visuals and collisions are the viewers' business.

use crate::error::Error;
use crate::spatial::Frame;
use nalgebra::{Matrix3, Vector3};
use roxmltree::{Document, Node};

/// xacro's XML namespace.
const XACRO: &str = "http://www.ros.org/wiki/xacro";

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

fn origin(owner: &Node) -> Result<Frame, Error> {
    match child(*owner, "origin") {
        None => Ok(Frame::IDENTITY),
        Some(o) => Ok(Frame::from_xyz_rpy(
            triple(owner, o, "xyz")?,
            triple(owner, o, "rpy")?,
        )),
    }
}

fn link(n: Node) -> Result<Link, Error> {
    let name = named(n)?;
    let Some(i) = child(n, "inertial") else {
        return Ok(Link {
            name,
            inertial: None,
        });
    };
    let mass = child(i, "mass").ok_or_else(|| bad(&n, "inertial mass", "missing"))?;
    let mass = number(&n, mass, "value", None)?;
    if mass < 0.0 {
        return Err(bad(&n, "mass value", format!("{mass} is negative")));
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
    Ok(Link {
        name,
        inertial: Some(Inertial {
            origin: origin(&i)?,
            mass,
            inertia: Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz),
        }),
    })
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

fn axis(n: &Node) -> Result<Vector3<f64>, Error> {
    let Some(a) = child(*n, "axis") else {
        return Ok(Vector3::x());
    };
    let v = Vector3::from(triple(n, a, "xyz")?);
    if v.norm() < 1e-9 {
        return Err(bad(n, "axis xyz", "is zero"));
    }
    Ok(v.normalize())
}

fn limit(n: &Node, k: JointType) -> Result<Option<Limit>, Error> {
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
        effort: number(n, l, "effort", Some(0.0))?,
        velocity: number(n, l, "velocity", Some(0.0))?,
    };
    if k != JointType::Continuous && lim.lower > lim.upper {
        return Err(bad(
            n,
            "limit",
            format!("lower {} is above upper {}", lim.lower, lim.upper),
        ));
    }
    if lim.velocity < 0.0 || lim.effort < 0.0 {
        return Err(bad(n, "limit", "velocity and effort must not be negative"));
    }
    Ok(Some(lim))
}

fn joint(n: Node) -> Result<Joint, Error> {
    let name = named(n)?;
    let k = kind(&n)?;
    let damping = match child(n, "dynamics") {
        Some(d) => number(&n, d, "damping", Some(0.0))?,
        None => 0.0,
    };
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
        origin: origin(&n)?,
        axis: axis(&n)?,
        limit: limit(&n, k)?,
        damping,
        mimic,
        name,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO: &str = r#"<robot name="two">
      <link name="base"/>
      <link name="a"><inertial><origin xyz="0 0 0.1"/><mass value="1.5"/>
        <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
        <origin xyz="0 0 0.2" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 2"/>
        <limit lower="-1" upper="1" effort="10" velocity="2"/><dynamics damping="0.5"/></joint>
    </robot>"#;

    #[test]
    fn a_urdf_reads_into_links_and_joints() {
        let r = Robot::parse(TWO).expect("parses");
        assert_eq!(r.name, "two");
        assert_eq!(r.links.len(), 2);
        let j = &r.joints[0];
        assert_eq!(
            (j.kind, j.parent.as_str(), j.child.as_str()),
            (JointType::Revolute, "base", "a")
        );
        assert_eq!(j.axis, Vector3::z());
        assert_eq!(j.damping, 0.5);
        assert_eq!(j.limit.map(|l| l.velocity), Some(2.0));
        assert!((j.origin.p.z - 0.2).abs() < 1e-15);
        assert_eq!(
            r.link("a")
                .and_then(|l| l.inertial.as_ref())
                .map(|i| i.mass),
            Some(1.5)
        );
    }

    #[test]
    fn faults_name_the_element_and_the_field() {
        let cases = [
            (TWO.replace("xyz=\"0 0 0.2\"", "xyz=\"0 0\""), "joint `j1`: origin xyz"),
            (TWO.replace("lower=\"-1\"", "lower=\"2\""), "joint `j1`: limit: lower 2 is above upper 1"),
            (TWO.replace("<mass value=\"1.5\"/>", "<mass value=\"nan\"/>"), "link `a`: mass value"),
            (TWO.replace("revolute", "spherical"), "joint `j1`: type"),
            (TWO.replace("<axis xyz=\"0 0 2\"/>", "<axis xyz=\"0 0 0\"/>"), "joint `j1`: axis xyz: is zero"),
            (TWO.replace("<limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"2\"/>", ""), "joint `j1`: limit: missing"),
            ("<robot name=\"x\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\"><xacro:macro name=\"m\"/></robot>".into(), "xacro"),
            ("<robot name=\"x\"><xacro:include filename=\"a.xacro\"/></robot>".into(), "xacro"),
            ("<robot><link".into(), "not XML"),
        ];
        for (xml, want) in cases {
            let e = Robot::parse(&xml).expect_err(want).to_string();
            assert!(e.contains(want), "`{e}` should contain `{want}`");
        }
    }
}
