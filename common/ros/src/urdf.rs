//! The URDF of the two Omni-class arms in the paper's dimensions, published as
//! `/robot_description` so viewers draw the arms on the frames of [`crate::arm`]:
//! link and joint names, origins and axes are that chain's, so a URDF library's FK
//! with the paper's joint angles puts the tool where the kernels' FK does.

use crate::arm::{name, ARMS, WORLD};
use std::fmt::Write as _;
use tactile_math::geometry::Geometry;

/// The URDF (XML) of robot `tactile`: the world, the master and the slave arm.
pub fn urdf(g: &Geometry) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<robot name=\"tactile\">\n\
         \x20 <material name=\"master\"><color rgba=\"0.2 0.45 0.85 1\"/></material>\n\
         \x20 <material name=\"slave\"><color rgba=\"0.9 0.5 0.15 1\"/></material>\n\
         \x20 <material name=\"tool\"><color rgba=\"0.1 0.1 0.1 1\"/></material>\n",
    );
    let _ = writeln!(s, "  <link name=\"{WORLD}\"/>");
    for arm in ARMS {
        arm_urdf(&mut s, g, arm);
    }
    s.push_str("</robot>\n");
    s
}

fn link(s: &mut String, name: &str, visual: Option<(&str, [f64; 3], &str)>) {
    match visual {
        None => {
            let _ = writeln!(s, "  <link name=\"{name}\"/>");
        }
        Some((geometry, [x, y, z], material)) => {
            let _ = writeln!(
                s,
                "  <link name=\"{name}\">\n    <visual>\n      <origin xyz=\"{x} {y} {z}\" rpy=\"0 0 0\"/>\n      \
                 <geometry>{geometry}</geometry>\n      <material name=\"{material}\"/>\n    </visual>\n  </link>"
            );
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn joint(
    s: &mut String,
    name: &str,
    kind: &str,
    parent: &str,
    child: &str,
    xyz: [f64; 3],
    rpy: [f64; 3],
    extra: &str,
) {
    let _ = writeln!(
        s,
        "  <joint name=\"{name}\" type=\"{kind}\">\n    <parent link=\"{parent}\"/>\n    \
         <child link=\"{child}\"/>\n    <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>{extra}\n  </joint>",
        xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]
    );
}

fn arm_urdf(s: &mut String, g: &Geometry, arm: &str) {
    let n = |p: &str| name(arm, p);
    let l4 = g.l1 + g.a;
    let rod = |len: f64| format!("<cylinder radius=\"0.005\" length=\"{len}\"/>");
    let limit = "\n    <limit lower=\"-3.1416\" upper=\"3.1416\" effort=\"10\" velocity=\"20\"/>";
    let axis_x = format!("\n    <axis xyz=\"-1 0 0\"/>{limit}");
    let base = crate::arm::base_in_world(arm);
    let rpy = [std::f64::consts::FRAC_PI_2, 0.0, 0.0];
    link(
        s,
        &n("base"),
        Some(("<box size=\"0.06 0.01 0.06\"/>", [0.0, -0.005, 0.0], arm)),
    );
    joint(
        s,
        &n("base_joint"),
        "fixed",
        WORLD,
        &n("base"),
        base.2,
        rpy,
        "",
    );
    link(
        s,
        &n("link1"),
        Some((
            "<cylinder radius=\"0.012\" length=\"0.02\"/>",
            [0.0; 3],
            arm,
        )),
    );
    joint(
        s,
        &n("joint1"),
        "revolute",
        &n("base"),
        &n("link1"),
        [0.0, g.l3, -l4],
        [0.0; 3],
        &format!("\n    <axis xyz=\"0 -1 0\"/>{limit}"),
    );
    link(
        s,
        &n("upper_arm"),
        Some((&rod(g.l1), [0.0, 0.0, g.l1 / 2.0], arm)),
    );
    joint(
        s,
        &n("joint2"),
        "revolute",
        &n("link1"),
        &n("upper_arm"),
        [0.0; 3],
        [0.0; 3],
        &axis_x,
    );
    link(s, &n("elbow"), None);
    let mimic = format!(
        "{axis_x}\n    <mimic joint=\"{}\" multiplier=\"-1\" offset=\"0\"/>",
        n("joint2")
    );
    joint(
        s,
        &n("elbow_joint"),
        "revolute",
        &n("upper_arm"),
        &n("elbow"),
        [0.0, 0.0, g.l1],
        [0.0; 3],
        &mimic,
    );
    link(
        s,
        &n("forearm"),
        Some((&rod(g.l2), [0.0, 0.0, g.l2 / 2.0], arm)),
    );
    joint(
        s,
        &n("joint3"),
        "revolute",
        &n("elbow"),
        &n("forearm"),
        [0.0; 3],
        rpy,
        &axis_x,
    );
    link(
        s,
        &n("tool"),
        Some(("<sphere radius=\"0.006\"/>", [0.0; 3], "tool")),
    );
    joint(
        s,
        &n("tool_joint"),
        "fixed",
        &n("forearm"),
        &n("tool"),
        [0.0, 0.0, g.l2],
        [0.0; 3],
        "",
    );
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
