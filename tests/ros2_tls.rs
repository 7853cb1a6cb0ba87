//! The ROS 2 session over mutual TLS (`[ros.tls]`), against an independent Zenoh peer:
//! the stand-in device of tests/ros2_standin.py (eclipse-zenoh's own TLS settings)
//! listening on a `tls/` endpoint, with certificates made by openssl as the loop's
//! tests make them (`tactile_launch::pki`); and the files refused, named, when bad.
#![cfg(feature = "zenoh")]

use crate::ros2::{device_standin_on, listening, python_ready, report};
use crate::util::{cannot, free_port, num, Sandbox};
use std::path::PathBuf;

/// A CA and a node certificate for 127.0.0.1 in `sb/dir`, or None without openssl.
fn pki(sb: &Sandbox, dir: &str) -> Option<[PathBuf; 3]> {
    let ips = ["127.0.0.1".to_string()];
    match tactile_launch::pki::make(&sb.path(dir), dir, &ips) {
        Ok(f) => Some(f),
        Err(e @ tactile_launch::pki::PkiError::Start(_)) => {
            cannot(&format!("openssl makes the test certificates ({e})"));
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// A 3-DoF device over ROS 2 on `tls/127.0.0.1:port`, `[ros.tls]` the files of `dir`
/// (relative to the scenario's folder), the simulated paper arm, `samples` at 100 Hz.
fn over_tls(domain: u32, port: u16, dir: &str, samples: u64) -> String {
    format!(
        "name = \"tls\"\nmode = \"realtime\"\nrate_hz = 100.0\nsamples = {samples}\n\
         device = \"paper\"\nseed = 1\n\n[ros]\ndomain_id = {domain}\n\
         connect = [\"tls/127.0.0.1:{port}\"]\n\n\
         [ros.tls]\nca = \"{dir}/ca.pem\"\ncert = \"{dir}/node.pem\"\nkey = \"{dir}/node.key\"\n\n\
         [master]\nbackend = \"ros2\"\n\n[master.ros2]\njoint_states = \"/phantom/joint_states\"\n\
         joints = [\"waist\", \"shoulder\", \"elbow\"]\nforce_topic = \"/phantom/force_feedback\"\n"
    )
}

/// The device's driver over mutual TLS: a master whose certificate another CA signed
/// is refused at the handshake (its session reaches no one, and says so); one with a
/// certificate of the device's CA runs, every force reaching the driver, no warning of
/// a session in clear.
#[test]
fn a_ros2_session_over_mutual_tls_runs_and_a_stranger_is_refused() {
    if !python_ready() {
        return cannot("python3 lacks eclipse-zenoh or rosbags");
    }
    let sb = Sandbox::new("ros2-tls");
    let (Some(run), Some(_)) = (pki(&sb, "run"), pki(&sb, "rogue")) else {
        return;
    };
    sb.write(
        "device.csv",
        "t,waist,shoulder,elbow\n0,0.1,0.2,0.3\n60,0.1,0.2,0.3\n",
    );
    let port = free_port();
    let files: Vec<String> = run.iter().map(|p| p.display().to_string()).collect();
    let tls = files.join(",");
    let listen = format!("tls/127.0.0.1:{port}");
    let args = ["--tls", &tls, "--end-after", "3.0"];
    let device = device_standin_on(&sb, 42, &listen, &args);
    listening(port);
    let rogue = sb.write("rogue.toml", &over_tls(42, port, "rogue", 200));
    let o = sb.try_run(&rogue, "rogue-out");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("the ROS 2 session reached none"), "{err}");
    let good = sb.write("good.toml", &over_tls(42, port, "run", 200));
    let o = sb.run(&good, "out");
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(!said.contains("in clear"), "{said}");
    let d = report(&sb, device, "device.json");
    assert_eq!(d["bad_attachments"], serde_json::json!([]), "{d}");
    let forces = d["forces"].as_array().map_or(0, Vec::len);
    assert!(forces >= 150, "{forces} forces reached the driver");
    let md = &sb.json("out", "summary.json")["master"]["device"];
    assert!(
        num(&md["fresh"]) > 150.0 && num(&md["rejected"]) == 0.0,
        "{md}"
    );
}

/// Each `[ros.tls]` file is checked before anything starts (exit 2, the field and the
/// file named): missing, a folder, not PEM, a key that is not the certificate's, a
/// certificate of another CA; and the endpoints go with it.
#[test]
fn bad_ros_tls_files_are_refused_and_named() {
    let sb = Sandbox::new("ros2-tls-bad");
    let (Some(_), Some(_)) = (pki(&sb, "run"), pki(&sb, "rogue")) else {
        return;
    };
    std::fs::create_dir_all(sb.path("bad")).expect("mkdir");
    let base = over_tls(43, 7447, "run", 100);
    let check = |k: usize, text: String, want: &[&str]| {
        let s = sb.write(&format!("b{k}.toml"), &text);
        let o = sb.tactile(&["check", s.to_str().expect("utf-8")]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{k}: {err}");
        for w in want {
            assert!(err.contains(w), "{k}: {w}: {err}");
        }
    };
    let o = sb.tactile(&["check", sb.write("ok.toml", &base).to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    check(
        1,
        base.replace("run/ca.pem", "run/none.pem"),
        &["ros.tls.ca", "none.pem", "No such file"],
    );
    check(
        2,
        base.replace("run/ca.pem", "bad"),
        &["ros.tls.ca", "not a regular file"],
    );
    sb.write("bad/garbage.pem", "not a certificate\n");
    check(
        3,
        base.replace("run/node.pem", "bad/garbage.pem"),
        &["ros.tls.cert", "no certificate"],
    );
    check(
        4,
        base.replace("run/node.key", "run/node.pem"),
        &["ros.tls.key", "no private key"],
    );
    check(
        5,
        base.replace("run/node.key", "rogue/node.key"),
        &["ros.tls.key", "is not the key of ros.tls.cert"],
    );
    check(
        6,
        base.replace("\"run/node.", "\"rogue/node."),
        &["ros.tls.cert", "is not valid under ros.tls.ca"],
    );
    check(
        7,
        base.replace("tls/127.0.0.1", "tcp/127.0.0.1"),
        &["ros.connect[0]", "every endpoint is tls/"],
    );
    let in_clear: Vec<&str> = base
        .lines()
        .filter(|l| {
            !["[ros.tls]", "ca =", "cert =", "key ="]
                .iter()
                .any(|p| l.starts_with(p))
        })
        .collect();
    check(
        8,
        in_clear.join("\n"),
        &["ros.connect[0]", "needs [ros.tls]"],
    );
}
