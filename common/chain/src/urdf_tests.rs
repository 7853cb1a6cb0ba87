//! The URDF reader's tests (beside the module, which they would double).
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
fn a_fixed_joints_axis_and_limit_are_not_read() {
    // As Kinova's Jaco2 URDF writes them (example-robot-data's kinova.urdf).
    let xml = TWO.replace(
        "</robot>",
        r#"<link name="tool"/><joint name="mount" type="fixed"><parent link="a"/><child link="tool"/>
          <axis xyz="0 0 0"/><limit effort="0" lower="0" upper="0" velocity="0"/></joint></robot>"#,
    );
    let r = Robot::parse(&xml).expect("a fixed joint's zero axis is ignored");
    assert_eq!(
        (r.joints[1].kind, r.joints[1].limit),
        (JointType::Fixed, None)
    );
    // A moving joint's zero axis is still refused.
    let bad = xml.replace("<axis xyz=\"0 0 2\"/>", "<axis xyz=\"0 0 0\"/>");
    let e = Robot::parse(&bad).expect_err("zero axis").to_string();
    assert!(e.contains("joint `j1`: axis xyz: is zero"), "{e}");
}

#[test]
fn an_axis_of_huge_or_tiny_components_is_a_unit_vector() {
    for (a, want) in [
        ("0 0 1e200", Vector3::z()),
        ("1e308 1e308 0", Vector3::new(1.0, 1.0, 0.0).normalize()),
        ("0 -1e-5 0", -Vector3::y()),
    ] {
        let r = Robot::parse(&TWO.replace("0 0 2", a)).expect(a);
        let axis = r.joints[0].axis;
        assert!(axis.iter().all(|v| v.is_finite()), "{a}: {axis:?}");
        assert!((axis - want).norm() < 1e-15, "{a}: {axis:?}");
    }
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
        // Issue 51: numbers that overflow or mean nothing physical.
        (TWO.replace("xyz=\"0 0 0.2\"", "xyz=\"0 0 1e308\""), "joint `j1`: origin xyz: 1e308 m is further than"),
        (TWO.replace("xyz=\"0 0 0.1\"", "xyz=\"1e300 0 0\""), "link `a`: origin xyz"),
        (TWO.replace("damping=\"0.5\"", "damping=\"-0.5\""), "joint `j1`: dynamics damping: -0.5 is negative"),
        (TWO.replace("damping=\"0.5\"", "friction=\"-1\""), "joint `j1`: dynamics friction: -1 is negative"),
        (TWO.replace(" effort=\"10\"", ""), "joint `j1`: limit effort: missing: URDF requires it; write effort=\"...\""),
        (TWO.replace(" velocity=\"2\"", ""), "joint `j1`: limit velocity: missing"),
        (TWO.replace("1.5\"/>", "1e300\"/>"), "link `a`: mass value: 1e300 kg is outside"),
        (TWO.replace("ixx=\"0.01\"", "ixx=\"-0.01\""), "link `a`: inertia: principal moments"),
        (TWO.replace("izz=\"0.03\"", "izz=\"0.5\""), "the triangle inequality"),
        (TWO.replace("ixx=\"0.01\" iyy=\"0.02\" izz=\"0.03\"", "ixx=\"1e300\" iyy=\"1e300\" izz=\"1e300\""), "not within 0 to"),
        (TWO.replace("ixy=\"0\"", "ixy=\"0.05\""), "not positive semi-definite"),
    ];
    for (xml, want) in cases {
        let e = Robot::parse(&xml).expect_err(want).to_string();
        assert!(e.contains(want), "`{e}` should contain `{want}`");
    }
}

/// A flat body rounded to two digits by a CAD export is taken (refused with a 1e-6
/// tolerance); one that breaks the triangle inequality, or has a negative moment, is not.
#[test]
fn a_rounded_flat_bodys_inertia_is_taken() {
    let diag = |x: f64, y: f64, z: f64| Matrix3::from_diagonal(&Vector3::new(x, y, z));
    assert_eq!(physical(&diag(1.2e-5, 1.2e-5, 2.5e-5)), Ok(()));
    let e = physical(&diag(1.0, 1.0, 3.0)).err().unwrap_or_default();
    assert!(e.contains("triangle inequality"), "{e}");
    let e = physical(&diag(-1e-3, 1.0, 1.0)).err().unwrap_or_default();
    assert!(e.contains("negative"), "{e}");
}

#[test]
fn collisions_are_read_with_their_origins_and_bad_sizes_refused() {
    let xml = r#"<robot name="r"><link name="a">
        <collision><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><box size="0.1 0.2 0.3"/></geometry></collision>
        <collision><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision>
        <collision><geometry><sphere radius="0.02"/></geometry></collision>
        <collision><geometry><mesh filename="package://p/m.stl" scale="0.001 0.001 0.001"/></geometry></collision>
        <collision><geometry><capsule radius="1" length="2"/></geometry></collision>
        </link></robot>"#;
    let r = Robot::parse(xml).expect("collisions");
    let c = &r.links[0].collisions;
    assert_eq!(c.len(), 4, "the capsule (not URDF's) is left out");
    assert_eq!(
        c[0].geometry,
        Geometry::Box {
            size: [0.1, 0.2, 0.3]
        }
    );
    assert_eq!(c[0].origin.p.z, 0.1);
    assert_eq!(
        c[1].geometry,
        Geometry::Cylinder {
            radius: 0.05,
            length: 0.4
        }
    );
    assert_eq!(c[2].geometry, Geometry::Sphere { radius: 0.02 });
    assert_eq!(
        c[3].geometry,
        Geometry::Mesh {
            filename: "package://p/m.stl".into(),
            scale: [0.001; 3]
        }
    );
    let bad = xml.replace("radius=\"0.02\"", "radius=\"-1\"");
    let e = Robot::parse(&bad)
        .expect_err("a negative radius")
        .to_string();
    assert!(
        e.contains("link `a`") && e.contains("collision sphere radius"),
        "{e}"
    );
}
