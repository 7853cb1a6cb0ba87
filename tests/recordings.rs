//! `run.mcap` read by independent implementations: the Python packages `mcap` with
//! `mcap-ros2-support` and `rosbags` decode every message, the values equal the
//! trace, the URDF's FK (yourdfpy) equals the kernels' (tests/mcap_check.py). The
//! recording follows the seed byte for byte, converts old records, and refuses bad
//! ones as `tactile report` does.

use crate::util::{self, cannot, Sandbox};
use std::io::Write as _;
use std::process::{Command, Stdio};

/// True if python3 has the readers the check needs.
fn python_ready() -> bool {
    util::python_has("mcap, mcap_ros2, rosbags, yourdfpy")
}

/// The kernels' FK (f64) at three poses, as the checker's `--fk` JSON.
fn kernel_fk(sb: &Sandbox, device: &str) -> String {
    let poses = [[0.1, 0.2, 0.3], [-0.7, 0.45, -0.2], [1.2, -0.3, 0.8]];
    let mut input = String::from("theta1,theta2,theta3\n");
    for p in poses {
        input.push_str(&format!("{},{},{}\n", p[0], p[1], p[2]));
    }
    let mut child = sb
        .command(&["kernels", "fk", "--arith", "f64", "--device", device])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("tactile kernels");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(input.as_bytes())
        .expect("write");
    let out = child.wait_with_output().expect("kernels output");
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let rows: Vec<String> = text
        .lines()
        .skip(1)
        .zip(poses)
        .map(|(l, p)| format!("{{\"theta\":[{},{},{}],\"xyz\":[{l}]}}", p[0], p[1], p[2]))
        .collect();
    assert_eq!(rows.len(), 3, "{text}");
    format!("[{}]", rows.join(","))
}

fn check(sb: &Sandbox, out: &str, fk: &str) {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/mcap_check.py");
    let o = util::output_within(
        {
            let mut c = Command::new("python3");
            c.arg(script).arg(sb.path(out)).args(["--fk", fk]);
            c
        },
        util::LIMIT,
    );
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}");
    assert!(text.contains("values equal the trace"), "{text}");
}

#[test]
fn a_recording_reads_with_independent_readers_and_equals_the_trace() {
    if !python_ready() {
        return cannot("python3 lacks mcap, mcap-ros2-support, rosbags or yourdfpy");
    }
    let sb = Sandbox::new("mcap-read");
    // The stiff wall through 50 ms: contact, forces, TDPA observers, delays.
    let scenario = sb.write(
        "wall.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 3000"),
    );
    sb.run(&scenario, "out");
    check(&sb, "out", &kernel_fk(&sb, "omni"));
    // The paper's geometry, run by the in-process simulation.
    let paper = sb.write("paper.toml", &util::paper_1khz(1500));
    sb.simulate(&paper, "sim");
    check(&sb, "sim", &kernel_fk(&sb, "paper"));
}

#[test]
fn the_recording_follows_the_seed_and_converts_old_records() {
    let sb = Sandbox::new("mcap-seed");
    let paper = sb.write("paper.toml", &util::paper_1khz(800));
    sb.simulate(&paper, "a");
    sb.simulate(&paper, "b");
    let read = |d: &str| std::fs::read(sb.path(d).join("run.mcap")).expect("run.mcap");
    let a = read("a");
    assert!(a.starts_with(b"\x89MCAP0\r\n") && a.ends_with(b"\x89MCAP0\r\n"));
    assert!(a == read("b"), "same scenario and seed, same bytes");
    // --mcap-only from the records gives the same file, and nothing else.
    let conv = sb.path("conv");
    let o = sb.tactile(&[
        "report",
        "a",
        "--mcap-only",
        "--out",
        conv.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(read("conv") == a, "converted records, same recording");
    let files: Vec<_> = std::fs::read_dir(&conv).expect("dir").flatten().collect();
    assert_eq!(files.len(), 1, "only run.mcap");
    // --no-trace writes no recording.
    let o = sb.tactile(&["report", "a", "--no-trace", "--out", "plain"]);
    assert!(o.status.success());
    assert!(!sb.path("plain").join("run.mcap").exists());
}

#[test]
fn bad_records_are_refused_as_the_report_refuses_them() {
    let sb = Sandbox::new("mcap-bad");
    let scenario = sb.write(
        "s.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 300"),
    );
    sb.run(&scenario, "one");
    sb.run(&scenario, "two");
    // The slave's record of another run beside this run's master and emulator.
    std::fs::create_dir(sb.path("mixed")).expect("mkdir");
    for (dir, role) in [("one", "master"), ("one", "emulator"), ("two", "slave")] {
        let f = format!("{role}.rec");
        std::fs::copy(sb.path(dir).join(&f), sb.path("mixed").join(&f)).expect("copy");
    }
    std::fs::create_dir(sb.path("empty")).expect("mkdir");
    for dir in ["mixed", "empty"] {
        let report = sb.tactile(&["report", dir, "--out", "r"]);
        let mcap = sb.tactile(&["report", dir, "--mcap-only", "--out", "m"]);
        assert_eq!(report.status.code(), Some(2), "{dir}");
        assert_eq!(mcap.status.code(), Some(2), "{dir}");
        assert_eq!(report.stderr, mcap.stderr, "{dir}: the same error");
        assert!(!sb.path("m").join("run.mcap").exists(), "{dir}");
        assert!(!sb.path("m").join("run.mcap.partial").exists(), "{dir}");
    }
    // A truncated master record: the whole frames are converted, as reported.
    let rec = sb.path("one").join("master.rec");
    let len = std::fs::metadata(&rec).expect("meta").len();
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(&rec)
        .expect("open");
    f.set_len(len * 2 / 3 + 7).expect("truncate");
    let report = sb.tactile(&["report", "one", "--out", "r2"]);
    let mcap = sb.tactile(&["report", "one", "--mcap-only", "--out", "m2"]);
    assert_eq!(report.status.code(), mcap.status.code());
    let rows = std::fs::read_to_string(sb.path("r2").join("trace.csv"))
        .expect("trace")
        .lines()
        .count()
        - 1;
    let said = String::from_utf8_lossy(&mcap.stdout);
    assert!(
        said.contains(&format!(": {rows} samples")),
        "{said} vs {rows} rows"
    );
}

#[test]
fn a_sweep_with_trace_writes_one_recording_per_run() {
    let sb = Sandbox::new("mcap-sweep");
    let scenario = sb.write(
        "s.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 200"),
    );
    let o = sb.tactile(&[
        "sweep",
        scenario.to_str().expect("utf-8"),
        "--set",
        "control.kind=none,tdpa",
        "--trace",
        "--out",
        "sw",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut recordings = 0;
    for entry in std::fs::read_dir(sb.path("sw"))
        .expect("sweep dir")
        .flatten()
    {
        if entry.path().join("summary.json").exists() {
            assert!(
                entry.path().join("run.mcap").exists(),
                "{}",
                entry.path().display()
            );
            recordings += 1;
        }
    }
    assert_eq!(recordings, 2);
}
