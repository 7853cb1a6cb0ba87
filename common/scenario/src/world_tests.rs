//! The physics world's keys: defaults, round trips, and each bad value refused by name.

use crate::world::*;
use crate::{Scenario, ScenarioError, TaskConfig};

/// A small physics scene: a table, a box on it, a drawer on a prismatic joint.
pub(crate) const SCENE: &str = r#"
[environment]
engine = "physics"
substeps = 4

[[environment.bodies]]
name = "table"
shape = { type = "box", half_extents = [0.5, 0.5, 0.02] }
position = [0.0, 0.0, -0.02]

[[environment.bodies]]
name = "box"
kind = "dynamic"
shape = { type = "box", half_extents = [0.02, 0.02, 0.02] }
position = [0.1, 0.0, 0.02]
mass = 0.2
friction = 0.4

[[environment.bodies]]
name = "drawer"
kind = "dynamic"
shape = { type = "box", half_extents = [0.05, 0.05, 0.02] }
position = [-0.2, 0.0, 0.03]
density = 500.0

[[environment.joints]]
name = "slide"
kind = "prismatic"
body2 = "drawer"
anchor = [-0.2, 0.0, 0.03]
axis = [1.0, 0.0, 0.0]
limits = [0.0, 0.3]
damping = 2.0
friction = 0.5

[task]
kind = "pose"
body = "box"
position = [0.2, 0.0, 0.02]
tolerance = 0.01
"#;

fn err(text: &str) -> (String, String) {
    match Scenario::from_toml_str(text) {
        Err(ScenarioError::Invalid { field, problem }) => (field, problem),
        other => panic!("expected a field refused, got {other:?}"),
    }
}

/// SCENE with `from` replaced by `to` (which must be there).
fn with(from: &str, to: &str) -> String {
    assert!(SCENE.contains(from), "{from}");
    SCENE.replacen(from, to, 1)
}

#[test]
fn a_physics_scene_loads_with_its_defaults_and_round_trips() {
    let s = Scenario::from_toml_str(SCENE).expect("the scene");
    let e = &s.environment;
    assert_eq!(e.engine, Engine::Physics);
    assert_eq!(e.gravity, [0.0, 0.0, -9.81]);
    assert_eq!(e.bodies.len(), 3);
    assert_eq!(e.bodies[0].kind, BodyKind::Static);
    assert_eq!(e.bodies[0].friction, 0.5);
    assert_eq!(e.bodies[0].rotation, [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(e.joints[0].limits, Some([0.0, 0.3]));
    assert_eq!(e.tool, ToolConfig::default());
    assert!(matches!(s.task, Some(TaskConfig::Pose { hold_s, .. }) if hold_s == 0.5));
    let again = Scenario::from_toml_str(&s.to_toml()).expect("written back");
    assert_eq!(again, s);
    assert_eq!(again.to_toml(), s.to_toml());
}

/// An analytic scenario (every shipped one) writes no key of the physics world: their
/// `scenario.toml` is what it was before the world existed.
#[test]
fn an_analytic_scenario_writes_no_physics_key() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../deploy/scenarios");
    let mut seen = 0;
    for f in std::fs::read_dir(&dir).expect("deploy/scenarios") {
        let p = f.expect("entry").path();
        if p.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&p).expect("read");
        let Ok(s) = Scenario::from_toml_str(&text) else {
            continue;
        };
        if s.environment.engine == Engine::Physics {
            continue;
        }
        let out: toml::Value = s.to_toml().parse().expect("toml");
        assert!(out.get("task").is_none(), "{}", p.display());
        if let Some(env) = out.get("environment").and_then(|e| e.as_table()) {
            let keys: Vec<&String> = env.keys().collect();
            assert!(
                keys.iter().all(|k| *k == "objects" || *k == "changes"),
                "{}: {keys:?}",
                p.display()
            );
        }
        seen += 1;
    }
    assert!(seen >= 5, "{seen} scenarios");
    let paper = Scenario::paper().to_toml();
    assert!(
        !paper.contains("engine") && !paper.contains("gravity"),
        "{paper}"
    );
}

#[test]
fn mesh_and_hull_files_are_inputs_of_the_scenario() {
    let text = with(
        "shape = { type = \"box\", half_extents = [0.5, 0.5, 0.02] }",
        "shape = { type = \"mesh\", file = \"meshes/table.stl\", scale = 0.001 }",
    );
    let text = text.replacen(
        "shape = { type = \"box\", half_extents = [0.02, 0.02, 0.02] }",
        "shape = { type = \"convex_hull\", file = \"meshes/box.obj\" }",
        1,
    );
    let s = Scenario::from_toml_str(&text).expect("meshes");
    assert_eq!(s.input_paths(), ["meshes/table.stl", "meshes/box.obj"]);
    let r = s.resolved(std::path::Path::new("/data"));
    assert_eq!(
        r.input_paths(),
        ["/data/meshes/table.stl", "/data/meshes/box.obj"]
    );
    assert_eq!(
        r.relative_to(std::path::Path::new("/data")).input_paths(),
        s.input_paths()
    );
}

#[test]
fn bad_bodies_are_refused_naming_the_field() {
    let cases: &[(&str, &str, &str)] = &[
        ("mass = 0.2", "mass = 0.0", "environment.bodies[1].mass"),
        ("mass = 0.2", "mass = -1.0", "environment.bodies[1].mass"),
        ("mass = 0.2", "mass = nan", "environment.bodies[1].mass"),
        (
            "density = 500.0",
            "density = 0.0",
            "environment.bodies[2].density",
        ),
        (
            "density = 500.0",
            "density = -3.0",
            "environment.bodies[2].density",
        ),
        (
            "density = 500.0",
            "density = nan",
            "environment.bodies[2].density",
        ),
        (
            "friction = 0.4",
            "friction = 0.0",
            "environment.bodies[1].friction",
        ),
        (
            "friction = 0.4",
            "friction = -0.1",
            "environment.bodies[1].friction",
        ),
        (
            "friction = 0.4",
            "friction = nan",
            "environment.bodies[1].friction",
        ),
        (
            "mass = 0.2",
            "mass = 0.2\ndensity = 3.0",
            "environment.bodies[1].density",
        ),
        (
            "name = \"drawer\"",
            "name = \"box\"",
            "environment.bodies[2].name",
        ),
        (
            "name = \"drawer\"",
            "name = \"tool\"",
            "environment.bodies[2].name",
        ),
        (
            "position = [0.1, 0.0, 0.02]",
            "position = [1e300, 0.0, 0.02]",
            "environment.bodies[1].position[0]",
        ),
        (
            "half_extents = [0.02, 0.02, 0.02]",
            "half_extents = [0.02, 0.0, 0.02]",
            "environment.bodies[1].shape.half_extents[1]",
        ),
        (
            "position = [0.1, 0.0, 0.02]",
            "position = [0.1, 0.0, 0.02]\nrotation = [0.0, 0.0, 0.0, 0.0]",
            "environment.bodies[1].rotation",
        ),
        (
            "name = \"table\"",
            "name = \"table\"\nmass = 3.0",
            "environment.bodies[0].mass",
        ),
        (
            "friction = 0.4",
            "friction = 0.4\nrestitution = 1.5",
            "environment.bodies[1].restitution",
        ),
    ];
    for (from, to, field) in cases {
        let (f, problem) = err(&with(from, to));
        assert_eq!(&f, field, "{to}: {problem}");
    }
}

#[test]
fn bad_joints_and_tasks_are_refused_naming_the_field() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "limits = [0.0, 0.3]",
            "limits = [0.3, 0.0]",
            "environment.joints[0].limits",
        ),
        (
            "limits = [0.0, 0.3]",
            "limits = [0.1, 0.3]",
            "environment.joints[0].limits",
        ),
        (
            "body2 = \"drawer\"",
            "body2 = \"drawr\"",
            "environment.joints[0].body2",
        ),
        (
            "body2 = \"drawer\"",
            "body2 = \"table\"",
            "environment.joints[0].body2",
        ),
        (
            "body2 = \"drawer\"",
            "body1 = \"drawer\"\nbody2 = \"drawer\"",
            "environment.joints[0].body1",
        ),
        (
            "axis = [1.0, 0.0, 0.0]",
            "axis = [0.0, 0.0, 0.0]",
            "environment.joints[0].axis",
        ),
        (
            "damping = 2.0",
            "damping = -2.0",
            "environment.joints[0].damping",
        ),
        // A fixed joint moves nothing: its limits (first), damping and friction are
        // refused.
        (
            "kind = \"prismatic\"",
            "kind = \"fixed\"",
            "environment.joints[0].limits",
        ),
        (
            "kind = \"prismatic\"\nbody2 = \"drawer\"\nanchor = [-0.2, 0.0, 0.03]\naxis = [1.0, 0.0, 0.0]\nlimits = [0.0, 0.3]",
            "kind = \"fixed\"\nbody2 = \"drawer\"\nanchor = [-0.2, 0.0, 0.03]\naxis = [1.0, 0.0, 0.0]",
            "environment.joints[0].damping",
        ),
        ("body = \"box\"", "body = \"crate\"", "task.body"),
        ("tolerance = 0.01", "tolerance = 0.0", "task.tolerance"),
    ];
    for (from, to, field) in cases {
        let (f, problem) = err(&with(from, to));
        assert_eq!(&f, field, "{to}: {problem}");
    }
    let joint_task = with(
        "kind = \"pose\"\nbody = \"box\"\nposition = [0.2, 0.0, 0.02]\ntolerance = 0.01",
        "kind = \"joint\"\njoint = \"door\"\nposition = 0.2",
    );
    assert_eq!(err(&joint_task).0, "task.joint");
}

#[test]
fn physics_keys_need_the_physics_engine_and_it_takes_no_analytic_object() {
    let analytic = with("engine = \"physics\"", "engine = \"analytic\"");
    assert_eq!(err(&analytic).0, "environment.bodies");
    let task_only = "[task]\nkind = \"joint\"\njoint = \"j\"\nposition = 1.0\n";
    assert_eq!(err(task_only).0, "task");
    let mixed = format!(
        "{SCENE}\n[[environment.objects]]\nkind = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nstiffness = [1.0, 1.0, 1.0]\n"
    );
    assert_eq!(err(&mixed).0, "environment.objects");
}

#[test]
fn bad_world_settings_and_tool_are_refused_naming_the_field() {
    let cases: &[(&str, &str)] = &[
        ("substeps = 4", "environment.substeps"),
        (
            "bounds = { min = [0.0, 0.0, 0.0], max = [1.0, 0.0, 1.0] }",
            "environment.bounds.max[1]",
        ),
        ("gravity = [0.0, 0.0, nan]", "environment.gravity[2]"),
        (
            "solver = { iterations = 0 }",
            "environment.solver.iterations",
        ),
        ("tool = { mass = 0.0 }", "environment.tool.mass"),
        ("tool = { stiffness = -1.0 }", "environment.tool.stiffness"),
        ("tool = { friction = 0.0 }", "environment.tool.friction"),
        (
            "tool = { shape = { type = \"sphere\", radius = 0.0 } }",
            "environment.tool.shape.radius",
        ),
    ];
    for (line, field) in cases {
        let text = if line.starts_with("substeps") {
            with("substeps = 4", "substeps = 0")
        } else {
            with("substeps = 4", line)
        };
        assert_eq!(&err(&text).0, field, "{line}");
    }
    let hull = with(
        "shape = { type = \"box\", half_extents = [0.02, 0.02, 0.02] }",
        "shape = { type = \"convex_hull\", points = [[0.0, 0.0, 0.0]] }",
    );
    assert_eq!(err(&hull).0, "environment.bodies[1].shape.points");
    let neither = with(
        "shape = { type = \"box\", half_extents = [0.02, 0.02, 0.02] }",
        "shape = { type = \"convex_hull\" }",
    );
    assert_eq!(err(&neither).0, "environment.bodies[1].shape");
}
