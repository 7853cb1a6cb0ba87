//! The slave in a physics world (docs/16): the shipped push-box task succeeds, the
//! same scenario gives the same bits in-process and as processes, a world that goes
//! wrong is named and its force ramped, and a world that cannot be built is refused
//! before anything starts.

use crate::util::{self, Sandbox};
use std::path::{Path, PathBuf};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../deploy/scenarios")
        .join(name)
}

#[test]
fn the_box_is_pushed_to_its_target_and_the_bits_repeat_in_process_and_as_processes() {
    let sb = Sandbox::new("pushbox");
    let scenario = shipped("push-box.toml");
    sb.simulate(&scenario, "a");
    sb.simulate(&scenario, "b");
    sb.run(&scenario, "procs");
    let a = util::signals(&sb.trace("a"));
    assert_eq!(a, util::signals(&sb.trace("b")), "in-process twice");
    assert_eq!(
        a,
        util::signals(&sb.trace("procs")),
        "processes against in-process"
    );
    let s = sb.json("a", "summary.json");
    let task = &s["task"];
    assert_eq!(task["success"], true, "{task}");
    let done = util::num(&task["completion_s"]);
    // The push ends at 5 s; the box must then be held within 1 cm for 0.5 s.
    assert!((2.5..6.0).contains(&done), "completed at {done} s");
    assert!(util::num(&task["path_length_m"]) > 0.15, "{task}");
    // A 0.2 kg box at mu 0.3 slides at 0.59 N: the push felt is about that.
    let peak = util::num(&task["peak_force_n"]);
    assert!((0.5..2.0).contains(&peak), "peak force {peak} N");
    assert_eq!(s["slave"]["world"]["physics"], true);
    assert!(util::num(&s["master"]["motion"]["contact_samples"]) > 1000.0);
    assert_eq!(s["warnings"].as_array().map(Vec::len), Some(0), "{s}");
}

#[test]
fn without_the_push_the_task_fails_and_says_how_close_it_came() {
    let sb = Sandbox::new("nopush");
    let text = std::fs::read_to_string(shipped("push-box.toml"))
        .expect("push-box")
        .replace("path = \"push-box.csv\"", "path = \"hover.csv\"");
    std::fs::write(
        sb.path("hover.csv"),
        "t,x,y,z\n0,0,-0.11,-0.035\n7,0,-0.11,-0.035\n",
    )
    .expect("write");
    let scenario = sb.write("hover.toml", &text);
    sb.simulate(&scenario, "run");
    let task = &sb.json("run", "summary.json")["task"];
    assert_eq!(task["success"], false, "{task}");
    assert!(task["completion_s"].is_null());
    // The box stays where it was put: 5 cm from its target.
    let d = util::num(&task["closest_distance"]);
    assert!((d - 0.05).abs() < 1e-3, "closest {d} m");
}

#[test]
fn a_body_that_leaves_the_world_is_named_and_the_force_ramps_down() {
    let sb = Sandbox::new("leaves");
    let text = std::fs::read_to_string(shipped("push-box.toml"))
        .expect("push-box")
        .replace(
            "path = \"push-box.csv\"",
            &format!("path = {:?}", shipped("push-box.csv")),
        )
        .replace(
            "engine = \"physics\"",
            "engine = \"physics\"\nbounds = { min = [-1.0, -1.0, -0.5], max = [1.0, 1.0, 1.0] }",
        )
        .replace(
            "position = [0.0, -0.11, -0.07]",
            "position = [0.5, -0.11, -0.07]",
        );
    let scenario = sb.write("leaves.toml", &text);
    sb.simulate(&scenario, "run");
    let s = sb.json("run", "summary.json");
    assert_eq!(
        s["slave"]["world"]["left_bounds"], 1,
        "{}",
        s["slave"]["world"]
    );
    let ramped = util::num(&s["slave"]["world"]["ramped_steps"]);
    assert!(ramped >= 500.0, "ramped over {ramped} samples");
    let warned = s["warnings"].to_string();
    assert!(warned.contains("1 bodies left its bounds"), "{warned}");
    let events = s["events"].to_string();
    assert!(
        events.contains("body `box` left the world's bounds"),
        "{events}"
    );
}

#[test]
fn a_world_that_cannot_be_built_is_refused_before_anything_starts() {
    let sb = Sandbox::new("badworld");
    let base = std::fs::read_to_string(shipped("push-box.toml"))
        .expect("push-box")
        .replace(
            "path = \"push-box.csv\"",
            &format!("path = {:?}", shipped("push-box.csv")),
        );
    std::fs::write(sb.path("junk.stl"), [0xffu8; 300]).expect("write");
    let cases = [
        (
            base.replace(
                "shape = { type = \"box\", half_extents = [0.02, 0.02, 0.02] }",
                "shape = { type = \"mesh\", file = \"junk.stl\" }\nkind = \"static\"",
            )
            .replace("kind = \"dynamic\"\n", "")
            .replace("mass = 0.2\n", ""),
            "environment.bodies[1].shape.file",
        ),
        (
            base.replace(
                "position = [0.0, -0.11, -0.07]",
                "position = [0.0, -0.11, -0.095]",
            ),
            "overlap",
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let s = sb.write(&format!("c{k}.toml"), text);
        let o = sb.tactile(&["check", s.to_str().expect("utf-8")]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "case {k}: {err}");
        assert!(err.contains(want), "case {k}: want {want:?} in {err}");
        sb.assert_refused(10 + k, text, want);
    }
}

#[test]
fn every_shipped_task_succeeds_at_zero_delay_and_a_misaligned_peg_does_not() {
    let sb = Sandbox::new("tasks");
    for name in ["drawer.toml", "peg-in-hole.toml", "panda-push-box.toml"] {
        let out = name.trim_end_matches(".toml");
        sb.simulate(&shipped(name), out);
        let task = &sb.json(out, "summary.json")["task"];
        assert_eq!(task["success"], true, "{name}: {task}");
    }
    // The hole 3 mm off the peg's path: the peg lands on the block's top and the
    // operator's press is held there (the mesh is solid, not a picture).
    let o = sb.tactile(&[
        "run",
        shipped("peg-in-hole.toml").to_str().expect("utf-8"),
        "--in-process",
        "-q",
        "--out",
        sb.path("off").to_str().expect("utf-8"),
        "--set",
        "environment.bodies[0].position=[0.003,-0.11,-0.09]",
        "--set",
        "task.mouth=[0.003,-0.11,-0.07]",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let task = &sb.json("off", "summary.json")["task"];
    assert_eq!(task["success"], false, "{task}");
    // Its centre 1.5 cm over the mouth: 2.5 cm from going 1 cm in.
    let d = util::num(&task["closest_distance"]);
    assert!((d - 0.025).abs() < 5e-4, "closest {d} m");
    assert!(util::num(&task["peak_force_n"]) > 2.0, "{task}");
}

#[test]
fn the_physics_wall_is_felt_as_stiff_as_its_coupling() {
    let sb = Sandbox::new("pwall");
    sb.simulate(&shipped("physics-wall.toml"), "run");
    let s = sb.json("run", "summary.json");
    assert!(s.get("task").is_none(), "no task, no task figures");
    let k = util::num(&s["transparency"]["environment_stiffness_n_per_m"]);
    // The contact is rigid: the 600 N/m coupling is the wall's stiffness.
    assert!((k - 600.0).abs() < 0.25 * 600.0, "{k} N/m");
}

#[test]
fn a_physics_sweep_on_two_jobs_equals_one_job() {
    let sb = Sandbox::new("pjobs");
    let scenario = shipped("push-box.toml");
    let sweep = |jobs: &str, out: &str| {
        let o = sb.tactile(&[
            "sweep",
            scenario.to_str().expect("utf-8"),
            "--set",
            "control.kind=none,wave",
            "--set",
            "network.forward.delay=[0,0,0],[25,25,25]",
            "--jobs",
            jobs,
            "-q",
            "--out",
            sb.path(out).to_str().expect("utf-8"),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(sb.path(out).join("sweep.csv")).expect("sweep.csv")
    };
    let one = sweep("1", "one");
    assert_eq!(one, sweep("2", "two"));
    assert!(one
        .lines()
        .next()
        .is_some_and(|h| h.contains("task_success")));
    assert_eq!(one.lines().count(), 5);
}
