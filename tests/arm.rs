//! Any arm from its URDF as the slave (`[slave.arm]`): the shipped Panda scenario
//! follows the master in free space within a millimetre and presses the wall, its
//! joints stay inside the URDF's limits, two runs give the same bytes, the node
//! programs load the arm as the in-process run does, and a bad arm is refused before
//! anything starts, naming the field.

use crate::util;

use std::path::{Path, PathBuf};
use util::{column, Sandbox};

/// The shipped Panda scenario.
fn panda() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/panda.toml")
}

/// The Panda's URDF, as the shipped scenario names it.
fn panda_urdf() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/panda.urdf")
}

/// The shipped Panda scenario's text, its URDF named by an absolute path (so a copy
/// runs from a sandbox).
fn panda_text() -> String {
    let text = std::fs::read_to_string(panda()).expect("scenario");
    text.replace(
        "../robots/panda.urdf",
        panda_urdf().to_str().expect("utf-8"),
    )
}

/// Rows of a CSV file, header first.
fn rows(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .expect("csv")
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn a_panda_follows_in_free_space_presses_the_wall_and_stays_in_its_limits() {
    let sb = Sandbox::new("armpanda");
    sb.simulate(&panda(), "a");
    let trace = sb.trace("a");
    let h3 = column(&trace, "h_3");
    assert_eq!(h3.len(), 4000);
    // In free space (no force) the hand is where the master's position puts it.
    let (worst, free) = util::free_space_error(&trace, 0);
    assert!(worst < 1e-3, "tool {worst} m from its target");
    assert!(free > 1000, "{free} samples in free space");
    // The wall at z = -0.08 pushes back up, as its stiffness says.
    let h_max = h3.iter().copied().fold(0.0, f64::max);
    assert!(h_max > 5.0, "largest wall force {h_max} N");

    // joints.csv: a row a sample, 7 references, 7 angles, 7 efforts, all in limits.
    let j = rows(&sb.path("a").join("joints.csv"));
    assert_eq!(j.len(), 4001);
    // Then h(n)'s torque, the orientation reference, the tool's and the master's, the
    // clutch's offsets, the angle between reference and tool, the clutch.
    assert_eq!(j[0].len(), 1 + 3 * 7 + 3 + 4 + 4 + 4 + 3 + 4 + 2);
    assert_eq!(j[0][1], "q_ref_1");
    assert_eq!(j[0][15], "tau_1");
    let chain = tactile_chain::Chain::from_urdf(
        &std::fs::read_to_string(panda_urdf()).expect("urdf"),
        "panda_link0",
        "panda_hand",
    )
    .expect("chain");
    for row in &j[1..] {
        let x: Vec<f64> = row[1..].iter().map(|c| c.parse().expect("float")).collect();
        for (i, d) in chain.dofs.iter().enumerate() {
            for q in [x[i], x[7 + i]] {
                assert!(q >= d.lower && q <= d.upper, "{}: {q}", d.name);
            }
            assert!(
                x[14 + i].abs() <= d.effort,
                "{}: effort {}",
                d.name,
                x[14 + i]
            );
        }
    }
    let s = sb.json("a", "summary.json");
    let c = &s["slave"]["counters"];
    assert_eq!(c["ik_clamped"], 0, "{c}");
    assert_eq!(c["rejected"], 0, "{c}");

    // The same scenario and seed give the same bytes.
    sb.simulate(&panda(), "b");
    for f in ["trace.csv", "joints.csv"] {
        let (a, b) = (sb.path("a").join(f), sb.path("b").join(f));
        let strip = |p: &Path| {
            let text = std::fs::read_to_string(p).expect("read");
            if f == "trace.csv" {
                tactile_report::trace::signal_columns(&text)
            } else {
                text
            }
        };
        assert!(strip(&a) == strip(&b), "{f} differs between two runs");
    }
}

#[test]
fn the_node_programs_load_the_arm_as_the_in_process_run_does() {
    let sb = Sandbox::new("armnodes");
    let scenario = sb.write(
        "panda.toml",
        &panda_text()
            .replace("mode = \"realtime\"", "mode = \"lockstep\"")
            .replace("samples = 4000", "samples = 300"),
    );
    sb.simulate(&scenario, "sim");
    sb.run(&scenario, "nodes");
    let out = sb.path("nodes");
    // The URDF travels with the run: bundled into the output folder's inputs.
    let bundled = out.join("inputs").join("panda.urdf");
    assert_eq!(
        std::fs::read(&bundled).expect("bundled urdf"),
        std::fs::read(panda_urdf()).expect("urdf")
    );
    let joints = rows(&out.join("joints.csv"));
    assert_eq!(joints.len(), 301);
    // The slave program's arm starts where the in-process one does.
    assert_eq!(joints[1], rows(&sb.path("sim").join("joints.csv"))[1]);
}

#[test]
fn a_bad_arm_is_named_and_nothing_starts() {
    let sb = Sandbox::new("armbad");
    let base = panda_text();
    let cases: [(&str, &str, &str); 7] = [
        (
            "home = [0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398]",
            "home = [0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796]",
            "field `slave.arm.home`: has 6 values; the chain from `panda_link0` to `panda_hand` has 7 joints",
        ),
        (
            "home = [0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398]",
            "home = [0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 9.0]",
            "field `slave.arm.home`: 9 for joint `panda_joint7` is outside its limits",
        ),
        ("tip = \"panda_hand\"", "tip = \"panda_nose\"", "chain from `panda_link0` to `panda_nose`"),
        (
            "kd = [50.0,",
            "kd = [-50.0,",
            "field `slave.arm.kd[0]`: -50 must be finite and non-negative",
        ),
        ("panda.urdf\"", "missing.urdf\"", "missing.urdf"),
        (
            "[slave.arm]",
            "[slave]\nbackend = \"ros2\"\n[slave.ros2]\njoints = [\"a\", \"b\", \"c\"]\n[slave.arm]",
            "field `slave.ros2.joints`: is for the paper's 3-DoF arm only; with [slave.arm] the arm's joints are its URDF's",
        ),
        (
            "[slave.arm]",
            "[slave.ros2]\ntrajectory_time_s = 2.0\n[slave.arm]",
            "field `slave.ros2.trajectory_time_s`: 2 s is outside (0, 1] s",
        ),
    ];
    for (k, (from, to, want)) in cases.iter().enumerate() {
        assert!(base.contains(from), "case {k}: {from}");
        sb.assert_refused(k, &base.replacen(from, to, 1), want);
    }
}

/// True if python3 has the readers tests/mcap_arm_check.py needs.
fn mcap_readers() -> bool {
    util::python_has("mcap, mcap_ros2, yourdfpy, numpy")
}

/// tests/mcap_arm_check.py on the report in `out`: its output.
fn mcap_arm_check(sb: &Sandbox, out: &str, base: &str, tip: &str) -> String {
    mcap_arm_check_with(sb, out, &["--base", base, "--tip", tip])
}

/// tests/mcap_arm_check.py on the report in `out` with `args`: its output.
fn mcap_arm_check_with(sb: &Sandbox, out: &str, args: &[&str]) -> String {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/mcap_arm_check.py");
    let mut c = std::process::Command::new("python3");
    c.arg(script).arg(sb.path(out)).args(args);
    let o = util::output_within(c, util::LIMIT);
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}");
    text
}

/// The recording draws the Panda where its joints put it: run.mcap read by independent
/// readers (mcap_ros2, yourdfpy's URDF parser and FK; tests/mcap_arm_check.py).
#[test]
fn the_recording_draws_the_arm_where_its_joints_put_it() {
    if !mcap_readers() {
        return util::cannot("python3 lacks mcap, mcap-ros2-support, yourdfpy or numpy");
    }
    let sb = Sandbox::new("armmcap");
    sb.simulate(&panda(), "a");
    let text = mcap_arm_check(&sb, "a", "panda_link0", "panda_hand");
    assert!(
        text.contains("4000 samples, 41 drawn and compared"),
        "{text}"
    );
}

/// A 6-DoF operator's recording (panda-pose.toml): the handle turns in run.mcap as the
/// operator turned it, read by the same independent readers.
#[test]
fn the_recording_turns_the_handle_as_the_operator_did() {
    if !mcap_readers() {
        return util::cannot("python3 lacks mcap, mcap-ros2-support, yourdfpy or numpy");
    }
    let sb = Sandbox::new("armmcappose");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/panda-pose.toml");
    sb.simulate(&scenario, "a");
    let args = [
        "--base",
        "panda_link0",
        "--tip",
        "panda_hand",
        "--handles-only",
    ];
    let text = mcap_arm_check_with(&sb, "a", &args);
    let turned: u64 = text
        .strip_prefix("mcap_arm_check: ")
        .and_then(|t| t.strip_suffix(" handles turned\n"))
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(turned > 5000, "{text}");
}

/// The shipped UR5 scenario: six joints, a URDF rooted in `world` (drawn where its
/// URDF puts it), the tool within a millimetre of its target in free space.
#[test]
fn a_ur5_follows_in_free_space_and_is_drawn_from_its_own_world() {
    let sb = Sandbox::new("armur5");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/ur5.toml");
    sb.simulate(&scenario, "a");
    let trace = sb.trace("a");
    let (worst, free) = util::free_space_error(&trace, 0);
    assert!(free > 1000, "{free}");
    assert!(worst < 1e-3, "free-space error {worst} m");
    let h = column(&trace, "h_3");
    assert!(h.iter().any(|f| *f > 5.0), "the wall pushed back");
    if !mcap_readers() {
        return util::cannot("python3 lacks mcap, mcap-ros2-support, yourdfpy or numpy");
    }
    let text = mcap_arm_check(&sb, "a", "base_link", "tool0");
    assert!(text.contains("4000 samples"), "{text}");
}

/// Records whose URDF is gone (moved without their inputs) still make a whole report:
/// the recording leaves the arm undrawn and the summary says why.
#[test]
fn a_report_whose_urdf_is_gone_says_so_and_loses_nothing_else() {
    let sb = Sandbox::new("armgone");
    sb.simulate(&panda(), "a");
    std::fs::remove_file(sb.path("a").join("inputs").join("panda.urdf")).expect("bundled urdf");
    let a = sb.path("a");
    let b = sb.path("b");
    let o = sb.tactile(&[
        "report",
        a.to_str().expect("utf-8"),
        "--out",
        b.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = sb.json("b", "summary.json");
    let events = s["events"].to_string();
    assert!(
        events.contains("the slave arm is not drawn") && events.contains("panda.urdf"),
        "{events}"
    );
    for f in ["trace.csv", "joints.csv", "run.mcap"] {
        assert!(sb.path("b").join(f).exists(), "{f}");
    }
    assert_eq!(
        std::fs::read_to_string(sb.path("a").join("joints.csv")).expect("a"),
        std::fs::read_to_string(sb.path("b").join("joints.csv")).expect("b")
    );
}

/// example-robot-data's folder of robots (tests/pin_reference.py finds it), or None
/// when Pinocchio's wheels are not installed.
fn example_robots() -> Option<PathBuf> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/pin_reference.py");
    let o = std::process::Command::new("python3")
        .arg(script)
        .arg("--robots-dir")
        .output()
        .ok()
        .filter(|o| o.status.success())?;
    Some(PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()))
}

/// Issue 51: Kinova's Jaco2 (example-robot-data's kinova.urdf, whose fixed joints
/// write `<axis xyz="0 0 0">`) was refused; it loads, and on the Panda's press it
/// follows the master in free space and feels the wall, within its limits.
#[test]
fn a_kinova_jaco2_from_example_robot_data_follows_and_presses_the_wall() {
    let Some(robots) = example_robots() else {
        return util::cannot(
            "python3 lacks pinocchio and example-robot-data (tests/requirements.txt)",
        );
    };
    let urdf = robots.join("kinova_description/robots/kinova.urdf");
    let sb = Sandbox::new("armjaco");
    let text = panda_text()
        .replace(
            panda_urdf().to_str().expect("utf-8"),
            urdf.to_str().expect("utf-8"),
        )
        .replace("base = \"panda_link0\"", "base = \"base\"")
        .replace("tip = \"panda_hand\"", "tip = \"j2s6s200_end_effector\"")
        .replace(
            "home = [0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398]",
            // Kinova's home pose of the Jaco2 (kinova-ros), radians.
            "home = [4.80, 2.92, 1.00, 4.19, 1.44, 1.31]",
        )
        .replace(
            "kp = [600.0, 600.0, 600.0, 600.0, 250.0, 150.0, 50.0]",
            "kp = [200.0, 300.0, 200.0, 50.0, 50.0, 50.0]",
        )
        .replace(
            "kd = [50.0, 50.0, 50.0, 50.0, 30.0, 25.0, 15.0]",
            "kd = [10.0, 15.0, 10.0, 2.0, 2.0, 2.0]",
        );
    let scenario = sb.write("jaco.toml", &text);
    sb.simulate(&scenario, "a");
    let trace = sb.trace("a");
    let (worst, free) = util::free_space_error(&trace, 0);
    assert!(worst < 1e-3, "tool {worst} m from its target");
    assert!(free > 1000, "{free} samples in free space");
    let h3 = column(&trace, "h_3");
    // Softer gains than the Panda's (the Jaco2's motors give 20 to 80 N m): the
    // wall's force comes back, 4.9 N here against the Panda's 6.7 N.
    let h_max = h3.iter().copied().fold(0.0, f64::max);
    assert!(h_max > 3.0, "largest wall force {h_max} N");
    eprintln!("jaco2: free space within {worst} m over {free} samples; the wall {h_max} N");
    let c = &sb.json("a", "summary.json")["slave"]["counters"];
    assert_eq!(c["ik_clamped"], 0, "{c}");
    assert_eq!(c["rejected"], 0, "{c}");
}

/// Issue 51: URDFs that mean nothing physical were taken, and the runs went on
/// (negative damping pushed the operator at the force limit; a cycle had no root;
/// an inertia of 1e300 froze the arm; a scale of 1e-300 sent 8e301 N). Each is
/// refused before anything starts, naming the element and the field.
#[test]
fn an_unphysical_urdf_or_scale_is_named_and_nothing_starts() {
    let sb = Sandbox::new("armunphys");
    let urdf = std::fs::read_to_string(panda_urdf()).expect("urdf");
    let cycle = "<joint name=\"back\" type=\"fixed\"><parent link=\"panda_hand\"/><child link=\"panda_link0\"/></joint></robot>";
    let cases: [(&str, &str, &str); 6] = [
        (
            "damping=\"0.003\"",
            "damping=\"-0.5\"",
            "joint `panda_joint1`: dynamics damping: -0.5 is negative",
        ),
        (
            "xyz=\"0 0 0.333\"",
            "xyz=\"0 0 1e308\"",
            "joint `panda_joint1`: origin xyz: 1e308 m is further than",
        ),
        (
            "<mass value=\"0.629769\"/>",
            "<mass value=\"1e300\"/>",
            "link `panda_link0`: mass value: 1e300 kg is outside",
        ),
        (
            "ixx=\"0.70337\"",
            "ixx=\"-0.70337\"",
            "link `panda_link1`: inertia: principal moments",
        ),
        (
            "effort=\"87.0\"",
            "effort=\"0\"",
            "joint `panda_joint1` has effort 0",
        ),
        ("</robot>", cycle, "its joints form a cycle"),
    ];
    for (k, (from, to, want)) in cases.iter().enumerate() {
        assert!(urdf.contains(from), "case {k}: {from}");
        let bad = sb.write(&format!("bad{k}.urdf"), &urdf.replacen(from, to, 1));
        let text = panda_text().replace(
            panda_urdf().to_str().expect("utf-8"),
            bad.to_str().expect("utf-8"),
        );
        sb.assert_refused(k, &text, want);
    }
    let scale = panda_text().replace("[slave.arm]", "[slave.arm]\nscale = 1e-300");
    sb.assert_refused(
        6,
        &scale,
        "field `slave.arm.scale`: 1e-300 is outside [0.001, 100]",
    );
}
