//! The URDF of the two Omni-class arms in the paper's dimensions, published as
//! `/robot_description` so viewers draw the arms on the frames of [`crate::arm`]:
//! written from that chain ([`crate::arm::chain`]), so its link and joint names,
//! origins and axes are the chain's, and a URDF library's FK with the paper's joint
//! angles puts the tool where the kernels' FK does.

use crate::arm::{axis_index, name, Joint, Motion, Shape, Visual, ARMS, WORLD};
use std::fmt::Write as _;
use tactile_math::geometry::Geometry;

/// The URDF (XML) of robot `tactile`: the world, the master and the slave arm.
pub fn urdf(g: &Geometry) -> String {
    let mut s = urdf_open(g, &ARMS);
    s.push_str("</robot>\n");
    s
}

/// The URDF of the world and the Omni-class arms `arms` (of [`ARMS`]), without its
/// closing `</robot>`: another robot's links and joints can follow.
pub fn urdf_open(g: &Geometry, arms: &[&str]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<robot name=\"tactile\">\n\
         \x20 <material name=\"master\"><color rgba=\"0.2 0.45 0.85 1\"/></material>\n\
         \x20 <material name=\"slave\"><color rgba=\"0.9 0.5 0.15 1\"/></material>\n\
         \x20 <material name=\"tool\"><color rgba=\"0.1 0.1 0.1 1\"/></material>\n",
    );
    let _ = writeln!(s, "  <link name=\"{WORLD}\"/>");
    for arm in arms {
        arm_urdf(&mut s, g, arm);
    }
    s
}

/// The URDF element of a shape.
fn geometry(shape: Shape) -> String {
    match shape {
        Shape::Box([x, y, z]) => format!("<box size=\"{x} {y} {z}\"/>"),
        Shape::Cylinder(r, l) => format!("<cylinder radius=\"{r}\" length=\"{l}\"/>"),
        Shape::Sphere(r) => format!("<sphere radius=\"{r}\"/>"),
    }
}

fn link(s: &mut String, name: &str, visual: Option<Visual>, arm: &str) {
    let Some(v) = visual else {
        let _ = writeln!(s, "  <link name=\"{name}\"/>");
        return;
    };
    let [x, y, z] = v.at;
    let material = if v.tool { "tool" } else { arm };
    let _ = writeln!(
        s,
        "  <link name=\"{name}\">\n    <visual>\n      <origin xyz=\"{x} {y} {z}\" rpy=\"0 0 0\"/>\n      \
         <geometry>{}</geometry>\n      <material name=\"{material}\"/>\n    </visual>\n  </link>",
        geometry(v.shape)
    );
}

/// Every revolute joint's range and limits (the Omni turns no joint past half a turn).
const LIMIT: &str =
    "\n    <limit lower=\"-3.1416\" upper=\"3.1416\" effort=\"10\" velocity=\"20\"/>";

/// A joint's type, origin rpy and its axis, limit and mimic elements.
fn motion(j: &Joint, chain: &[Joint], arm: &str) -> (&'static str, [f64; 3], String) {
    match j.motion {
        Motion::Fixed { about, angle } => {
            let mut rpy = [0.0; 3];
            rpy[about] = angle;
            ("fixed", rpy, String::new())
        }
        Motion::Turns {
            axis,
            joint,
            multiplier,
            at_zero,
        } => {
            let mut rpy = [0.0; 3];
            rpy[axis_index(axis).0] = at_zero;
            let [x, y, z] = axis;
            let mut extra = format!("\n    <axis xyz=\"{x} {y} {z}\"/>{LIMIT}");
            if multiplier != 1.0 {
                let driver = chain.iter().find(|d| {
                    matches!(d.motion, Motion::Turns { joint: k, multiplier: m, .. } if k == joint && m == 1.0)
                });
                if let Some(d) = driver {
                    let _ = write!(
                        extra,
                        "\n    <mimic joint=\"{}\" multiplier=\"{multiplier}\" offset=\"0\"/>",
                        name(arm, d.name)
                    );
                }
            }
            ("revolute", rpy, extra)
        }
    }
}

/// Each joint of `arm`'s chain and the link it carries.
fn arm_urdf(s: &mut String, g: &Geometry, arm: &str) {
    let chain = crate::arm::chain(g, arm);
    for j in &chain {
        link(s, &name(arm, j.child), j.visual, arm);
        let parent = if j.parent == WORLD {
            WORLD.to_string()
        } else {
            name(arm, j.parent)
        };
        let (kind, rpy, extra) = motion(j, &chain, arm);
        let [x, y, z] = j.origin;
        let _ = writeln!(
            s,
            "  <joint name=\"{}\" type=\"{kind}\">\n    <parent link=\"{parent}\"/>\n    \
             <child link=\"{}\"/>\n    <origin xyz=\"{x} {y} {z}\" rpy=\"{} {} {}\"/>{extra}\n  </joint>",
            name(arm, j.name),
            name(arm, j.child),
            rpy[0],
            rpy[1],
            rpy[2]
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_frame_of_the_chain_is_a_link_and_every_joint_names_two() {
        let u = urdf(&Geometry::PAPER);
        for arm in ARMS {
            for (_, child, _, _) in crate::arm::links(&Geometry::PAPER, arm, [0.0; 3]) {
                assert!(u.contains(&format!("<link name=\"{child}\"")), "{child}");
            }
            assert!(u.contains(&format!("<mimic joint=\"{arm}_joint2\" multiplier=\"-1\"")));
        }
        assert_eq!(u.matches("<joint ").count(), 2 * 6);
        assert_eq!(u.matches("<link ").count(), 1 + 2 * 6);
    }
}
