//! The whole robot's transforms (what a viewer draws) agree with the chain's FK, for
//! the Panda, the UR5 and the paper's arm with its mimic joint.

use proptest::prelude::*;
use tactile_chain::{Chain, Robot, Tree};
use tactile_math::geometry::Geometry;

const PANDA: &str = include_str!("../../../deploy/robots/panda.urdf");
const UR5: &str = include_str!("../../../deploy/robots/ur5_robot.urdf");

/// Root-to-tip through the tree equals the chain's FK, joints given by name.
fn agree(xml: &str, base: &str, tip: &str, q: &[f64]) {
    let robot = Robot::parse(xml).expect("urdf");
    let tree = Tree::new(&robot).expect("tree");
    let chain = Chain::new(&robot, base, tip).expect("chain");
    let value = |name: &str| chain.dofs.iter().position(|d| d.name == name).map(|k| q[k]);
    let base_in_root = tree.pose(base, &value).expect("base");
    let tip_in_root = tree.pose(tip, &value).expect("tip");
    let tip_in_base = base_in_root.inverse().then(&tip_in_root);
    let fk = chain.fk(q);
    assert!(
        (tip_in_base.p - fk.p).norm() < 1e-12,
        "{tip_in_base:?} {fk:?}"
    );
    assert!((tip_in_base.r - fk.r).norm() < 1e-12);
}

proptest! {
    #[test]
    fn the_panda_drawn_puts_its_hand_where_the_chain_does(q in prop::collection::vec(-1.5f64..1.5, 7)) {
        agree(PANDA, "panda_link0", "panda_hand", &q);
    }

    #[test]
    fn the_ur5_drawn_puts_its_tool_where_the_chain_does(q in prop::collection::vec(-3.0f64..3.0, 6)) {
        agree(UR5, "base_link", "tool0", &q);
    }

    #[test]
    fn the_papers_arm_drawn_follows_its_mimic(q in prop::collection::vec(-1.0f64..1.0, 3)) {
        let xml = tactile_ros::urdf::urdf(&Geometry::PAPER);
        agree(&xml, "slave_base", "slave_tool", &q);
    }
}

#[test]
fn every_link_has_one_transform_and_fingers_rest_in_their_limits() {
    let robot = Robot::parse(PANDA).expect("urdf");
    let tree = Tree::new(&robot).expect("tree");
    let none = |_: &str| None;
    let mut children: Vec<&str> = tree
        .fixed()
        .chain(tree.moving(&none))
        .map(|(_, c, _)| c)
        .collect();
    children.push(&tree.root);
    children.sort_unstable();
    let mut links: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
    links.sort_unstable();
    assert_eq!(children, links);
    assert_eq!(tree.root, "panda_link0");
    // The fingers (prismatic, 0..0.04 m) are drawn closed, the second mimicking the first.
    let fingers = tree.pose("panda_rightfinger", &none).expect("finger");
    let hand = tree.pose("panda_hand", &none).expect("hand");
    assert!((hand.inverse().then(&fingers).p.z - 0.0584).abs() < 1e-12);
    assert!(tree.moving_names().any(|n| n == "panda_finger_joint1"));
}

#[test]
fn a_robot_of_two_roots_is_refused() {
    let xml = r#"<robot name="two"><link name="a"/><link name="b"/></robot>"#;
    let e = Tree::new(&Robot::parse(xml).expect("urdf")).expect_err("two roots");
    assert!(
        e.to_string()
            .contains("2 links are no joint's child (a, b)"),
        "{e}"
    );
}

#[test]
fn elements_are_copied_as_written() {
    let xml = "<robot name=\"r\">\n  <link name=\"a\"/>\n  <!-- c -->\n  <joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>\n  <link name=\"b\"/><gazebo/></robot>";
    let got = tactile_chain::urdf::elements(xml, &["link", "joint"]).expect("xml");
    assert_eq!(
        got,
        [
            "<link name=\"a\"/>",
            "<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>",
            "<link name=\"b\"/>"
        ]
    );
}
