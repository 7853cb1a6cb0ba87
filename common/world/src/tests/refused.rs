//! What the world refuses to build, each naming the field.

use super::*;
use crate::mesh::{self, Mesh};

fn scene(shape: &str, kind: &str) -> String {
    format!(
        r#"
[environment]
engine = "physics"

[[environment.bodies]]
name = "thing"
kind = "{kind}"
shape = {shape}
"#
    )
}

fn refused(text: &str, dir: &Path) -> String {
    match world_in(text, dir) {
        Ok(_) => panic!("built: {text}"),
        Err(e) => e,
    }
}

#[test]
fn bad_mesh_files_are_refused_naming_the_field() {
    let d = tempfile::tempdir().expect("temp dir");
    let cube = Mesh::cuboid([0.01; 3]);
    let mut open = cube.clone();
    open.triangles.pop();
    let mut truncated = mesh::to_stl_binary(&cube);
    truncated.truncate(200);
    let files: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty.stl", Vec::new(), "holds no triangle"),
        ("cut.stl", truncated, "truncated"),
        ("junk.obj", vec![0xff, 0x00, 0x13, 0x37, 0x80], "not text"),
        (
            "nan.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n".to_vec(),
            "vertex 2",
        ),
        (
            "huge.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1e300 0\nf 1 2 3\n".to_vec(),
            "vertex 2",
        ),
        ("open.obj", mesh::to_obj(&open).into_bytes(), "not closed"),
        (
            "big.obj",
            mesh::to_obj(&Mesh::cuboid([1e3; 3])).into_bytes(),
            "beyond 100 m",
        ),
    ];
    for (name, bytes, why) in &files {
        std::fs::write(d.path().join(name), bytes).expect("write");
        let text = scene(
            &format!("{{ type = \"mesh\", file = \"{name}\" }}"),
            "dynamic",
        );
        let e = refused(&text, d.path());
        assert!(
            e.contains("environment.bodies[0].shape.file") && e.contains(why),
            "{name}: {e}"
        );
    }
    // An open mesh is a surface a static body may have.
    let text = scene("{ type = \"mesh\", file = \"open.obj\" }", "static");
    world_in(&text, d.path()).expect("an open static mesh");
    let e = refused(
        &scene("{ type = \"mesh\", file = \"none.stl\" }", "static"),
        d.path(),
    );
    assert!(
        e.contains("environment.bodies[0].shape.file") && e.contains("cannot read"),
        "{e}"
    );
}

#[test]
fn bodies_overlapping_at_the_start_are_refused() {
    let text = r#"
[environment]
engine = "physics"

[[environment.bodies]]
name = "table"
shape = { type = "box", half_extents = [0.5, 0.5, 0.05] }
position = [0.0, 0.0, -0.05]

[[environment.bodies]]
name = "ball"
kind = "dynamic"
shape = { type = "sphere", radius = 0.02 }
position = [0.0, 0.0, 0.01]
"#;
    let e = refused(text, Path::new("."));
    assert!(
        e.contains("environment.bodies[1].position")
            && e.contains("`ball` overlaps `table`")
            && e.contains("10.000 mm"),
        "{e}"
    );
    // Resting exactly on it is not overlapping.
    world(&text.replace("0.0, 0.0, 0.01]", "0.0, 0.0, 0.02]"));
}

#[test]
fn a_joint_damping_too_stiff_for_the_substep_is_refused() {
    let text = r#"
[environment]
engine = "physics"
substeps = 1

[[environment.bodies]]
name = "slider"
kind = "dynamic"
shape = { type = "box", half_extents = [0.01, 0.01, 0.01] }
mass = 0.01

[[environment.joints]]
name = "rail"
kind = "prismatic"
body2 = "slider"
axis = [1.0, 0.0, 0.0]
damping = 100.0
"#;
    let e = refused(text, Path::new("."));
    assert!(
        e.contains("environment.joints[0].damping") && e.contains("b h / m = 10"),
        "{e}"
    );
}
