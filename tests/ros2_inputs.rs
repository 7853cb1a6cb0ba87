//! What a ROS 2 device may and may not bring into a run: its gimbal's URDF read from
//! the scenario's folder and kept in the run's `inputs/`; messages of the wrong type
//! hash, without rmw_zenoh's attachment, or with a joint named twice dropped and
//! counted, against the independent stand-in of tests/ros2_standin.py.
#![cfg(feature = "zenoh")]

use crate::ros2::{listening, python_ready, report};
use crate::util::{self, cannot, free_port, num, Sandbox};

/// A Touch with its gimbal (`gimbal` the URDF's path as written) over ROS 2 on
/// `port` in `domain`, driving the Panda simulated (`root`: the deploy folder).
fn touch_on_panda(root: &str, domain: u32, port: u16, gimbal: &str, samples: u64) -> String {
    let text = std::fs::read_to_string(format!("{root}/scenarios/panda.toml")).expect("panda");
    let text = text
        .replace("../robots/panda.urdf", &format!("{root}/robots/panda.urdf"))
        .replace("samples = 4000", &format!("samples = {samples}"));
    format!(
        r#"{text}
[ros]
domain_id = {domain}
connect = ["tcp/127.0.0.1:{port}"]

[master]
backend = "ros2"

[master.ros2]
joint_states = "/phantom/joint_states"
joints = ["waist", "shoulder", "elbow"]
force_topic = "/phantom/force_feedback"
gimbal = {{ urdf = "{gimbal}", base = "base", tip = "stylus", frame = {{ rpy_deg = [-90.0, 0.0, 0.0] }} }}

[master.ros2.watch]
timeout_ms = 300.0
"#
    )
}

/// A relative gimbal URDF is the scenario folder's file, checked and run alike: the
/// run (its output folder elsewhere) reads it from there, not from `--out/..`, and
/// copies it into `inputs/` with the scenario pointing at the copy.
#[test]
fn a_relative_gimbal_urdf_is_read_from_the_scenarios_folder_and_kept() {
    let sb = Sandbox::new("ros2-gimbal");
    let root = env!("CARGO_MANIFEST_DIR");
    std::fs::create_dir_all(sb.path("scen")).expect("mkdir");
    std::fs::create_dir_all(sb.path("devices")).expect("mkdir");
    std::fs::create_dir_all(sb.path("runs/devices")).expect("mkdir");
    let urdf = std::fs::read_to_string(format!("{root}/devices/phantom_omni.urdf")).expect("urdf");
    sb.write("devices/omni.urdf", &urdf);
    // Where `--out runs/out` would wrongly resolve it: another file, not a URDF.
    sb.write("runs/devices/omni.urdf", "not the gimbal");
    let text = touch_on_panda(root, 40, free_port(), "../devices/omni.urdf", 500);
    let scenario = sb.write("scen/t.toml", &text);
    let o = sb.tactile(&["check", scenario.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = sb.path("runs/out");
    // No device: the master waits for it until its start-up timeout, then fails.
    let o = sb.try_run(&scenario, "runs/out");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !err.contains("URDF") && !err.contains("gimbal"),
        "the gimbal was read from elsewhere: {err}"
    );
    assert!(err.contains("the ROS 2 session reached none"), "{err}");
    let copy = std::fs::read_to_string(out.join("inputs/omni.urdf")).expect("the copy");
    assert_eq!(copy, urdf);
    sb.assert_no_leftover_processes();
}

/// A 3-DoF device over ROS 2 (joints in rad, the default map) driving the simulated
/// paper arm, `samples` at 100 Hz.
fn device_only(domain: u32, port: u16, samples: u64) -> String {
    format!(
        "name = \"forged\"\nmode = \"realtime\"\nrate_hz = 100.0\nsamples = {samples}\n\
         device = \"paper\"\nseed = 1\n\n[ros]\ndomain_id = {domain}\n\
         connect = [\"tcp/127.0.0.1:{port}\"]\n\n[master]\nbackend = \"ros2\"\n\n\
         [master.ros2]\njoint_states = \"/phantom/joint_states\"\n\
         joints = [\"waist\", \"shoulder\", \"elbow\"]\nforce_topic = \"/phantom/force_feedback\"\n"
    )
}

/// A device publishing on Humble's key (`TypeHashNotSupported`) drives the run; among
/// its messages, samples on another type hash's key, without rmw_zenoh's attachment or
/// with a short one, and a `JointState` naming a joint twice, each with the waist 0.5
/// rad off: every one dropped and counted, none reaching the loop, each reason in the
/// master's log (issue 51: a wrong hash moved the handle 5 cm, "0 dropped").
#[test]
fn samples_of_another_type_without_an_attachment_or_with_a_joint_twice_are_dropped() {
    if !python_ready() {
        return cannot("python3 lacks eclipse-zenoh or rosbags");
    }
    let _serial = crate::ros2::one_at_a_time();
    let sb = Sandbox::new("ros2-forged");
    sb.write(
        "device.csv",
        "t,waist,shoulder,elbow\n0,0.1,0.2,0.3\n60,0.1,0.2,0.3\n",
    );
    let port = free_port();
    let device = crate::ros2::device_standin(
        &sb,
        41,
        port,
        &[
            "--humble",
            "--forge-at",
            "0.5",
            "--forge-each",
            "3",
            "--end-after",
            "7.0",
        ],
    );
    let scenario = sb.write("f.toml", &device_only(41, port, 600));
    listening(port);
    sb.run(&scenario, "out");
    let d = report(&sb, device, "device.json");
    assert_eq!(
        d["forged"],
        serde_json::json!({"hash": 3, "noattach": 3, "short": 3, "dup": 3}),
        "{d}"
    );
    let s = sb.json("out", "summary.json");
    let md = &s["master"]["device"];
    assert_eq!(num(&md["rejected"]), 12.0, "{md}");
    assert!(num(&md["fresh"]) > 500.0, "{md}");
    let trace = sb.trace("out");
    let waist = util::column(&trace, "theta_md_1");
    assert_eq!(waist.len(), 600);
    assert!(
        waist.iter().all(|w| (w - 0.1).abs() < 1e-12),
        "a forged waist reached the loop: {:?}",
        waist.iter().find(|w| (**w - 0.1).abs() >= 1e-12)
    );
    let log = std::fs::read_to_string(sb.path("out").join("master.log")).expect("log");
    for why in [
        "type hash RIHS01_0000",
        "rmw_zenoh's attachment: none",
        "rmw_zenoh's attachment: 20 bytes",
        "joint \"waist\" is named twice",
    ] {
        assert!(log.contains(why), "{why}: {log}");
    }
}
