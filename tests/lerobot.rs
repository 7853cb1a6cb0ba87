//! `tactile export lerobot`: runs and sweeps as a LeRobot v3.0 dataset, read by
//! independent readers (pyarrow and pandas, tests/lerobot_check.py; the Rerun SDK's
//! LeRobot importer, tests/lerobot_rerun.py), its `info.json` keyed as a LeRobot
//! recorder's (tests/fixtures/lerobot), each frame's values the trace's at the sample
//! at or before it; bad input refused with exit 2 and nothing left behind; a damaged
//! record exported up to its damage, said; a stop request (SIGINT) ends an export with
//! exit 130 and nothing written.

use crate::formats::check;
use crate::util::{self, cannot, Sandbox};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::Path;

/// True if python3 has Arrow, pandas and the Rerun SDK.
fn python_ready() -> bool {
    util::python_has("pyarrow, pandas, rerun")
}

/// `tactile run SCENARIO --in-process` with `sets`, into `out`.
fn run(sb: &Sandbox, scenario: &str, sets: &[&str], out: &str) {
    let path = format!("{}/scenarios/{scenario}", env!("CARGO_MANIFEST_DIR"));
    let mut args = vec!["run", &path, "--in-process", "-q", "--out", out];
    for s in sets {
        args.extend(["--set", s]);
    }
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `tactile export lerobot ARGS...`, its exit code and its stdout and stderr.
fn export(sb: &Sandbox, args: &[&str]) -> (Option<i32>, String) {
    let mut all = vec!["export", "lerobot"];
    all.extend(args);
    let o = sb.tactile(&all);
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    (o.status.code(), text)
}

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).expect("read json");
    serde_json::from_str(&text).expect("json")
}

fn keys(v: &Value) -> BTreeSet<String> {
    v.as_object()
        .map(|o| o.keys().cloned().collect())
        .unwrap_or_default()
}

/// The dataset's `info.json` has a LeRobot recorder's keys, its features the keys a
/// recorder's features have, and the default columns exactly a recorder's.
fn assert_keyed_as_a_recorder(info: &Value) {
    let fixture = json(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/fixtures/lerobot/so101-record-test-info.json"
    )));
    assert_eq!(keys(info), keys(&fixture));
    assert_eq!(info["codebase_version"], "v3.0");
    let theirs: BTreeSet<String> = fixture["features"]
        .as_object()
        .expect("features")
        .values()
        .flat_map(keys)
        .collect();
    for (name, ft) in info["features"].as_object().expect("features") {
        assert!(keys(ft).is_subset(&theirs), "{name}: {:?}", keys(ft));
        if let Some(same) = fixture["features"].get(name.as_str()) {
            if [
                "timestamp",
                "frame_index",
                "episode_index",
                "index",
                "task_index",
            ]
            .contains(&name.as_str())
            {
                assert_eq!(ft, same, "{name}");
            }
        }
    }
}

/// The line `episodes: [...]` lerobot_check.py prints: each episode's run and metadata.
fn episodes_said(text: &str) -> Vec<Value> {
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("episodes: "))
        .expect("episodes line");
    let v: Value = serde_json::from_str(line).expect("episodes json");
    v.as_array().cloned().expect("array")
}

#[test]
fn a_sweep_and_a_task_run_export_as_one_dataset_that_pyarrow_and_rerun_read() {
    if !python_ready() {
        return cannot("python3 lacks pyarrow, pandas or rerun-sdk");
    }
    let sb = Sandbox::new("lerobot");
    let paper = format!("{}/scenarios/paper.toml", env!("CARGO_MANIFEST_DIR"));
    // Two runs: no delay and no loss; 20 ms forward with 20 % of the positions and 30 %
    // of the answers lost (the slave does not step on a lost position: the frames hold
    // its last values).
    let o = sb.tactile(&[
        "sweep",
        &paper,
        "--set",
        "samples=200",
        "--set",
        "network.forward.delay_ms=0,20",
        "--set",
        "+network.backward.loss=0,0.3",
        "--set",
        "+network.forward.loss=0,0.2",
        "--trace",
        "-q",
        "--out",
        "sw",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    run(&sb, "push-box.toml", &[], "push");
    let (code, text) = export(&sb, &["sw", "push", "--out", "ds", "--fps", "50"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("3 episodes"), "{text}");
    let info = json(&sb.path("ds/meta/info.json"));
    assert_keyed_as_a_recorder(&info);
    assert_eq!(info["fps"], 50);
    let ds = sb.path("ds");
    let ds = ds.to_str().expect("utf-8");
    let runs = ["sw/run-0000", "sw/run-0001", "push"].map(|r| sb.path(r));
    let mut args = vec![ds, "50"];
    args.extend(runs.iter().map(|r| r.to_str().expect("utf-8")));
    let said = check("lerobot_check.py", &args, "lerobot ok: 3 episodes");
    let eps = episodes_said(&said);
    // The sweep's values per episode, the task's outcome where the run had one.
    assert_eq!(eps[0]["swept"]["network.forward.delay_ms"], "0");
    assert_eq!(eps[1]["swept"]["network.forward.delay_ms"], "20");
    assert_eq!(eps[1]["swept"]["network.backward.loss"], "0.3");
    assert_eq!(eps[1]["delay_forward_ms"], 20.0);
    assert_eq!(eps[1]["loss_backward"], 0.3);
    assert_eq!(eps[1]["swept"]["network.forward.loss"], "0.2");
    assert_eq!(eps[0]["task_success"], Value::Null);
    assert_eq!(eps[2]["task_success"], true);
    assert!(
        eps[2]["completion_s"].as_f64().is_some_and(|t| t > 0.0),
        "{eps:?}"
    );
    assert_eq!(eps[2]["tasks"], serde_json::json!(["push-box"]));
    let rrd = sb.path("ds.rrd");
    check(
        "lerobot_rerun.py",
        &[ds, rrd.to_str().expect("utf-8")],
        "rerun ok: 3 episodes",
    );
}

#[test]
fn a_urdf_arm_exports_its_joints_by_their_names() {
    if !python_ready() {
        return cannot("python3 lacks pyarrow, pandas or rerun-sdk");
    }
    let sb = Sandbox::new("lerobot-arm");
    run(&sb, "panda.toml", &["samples=400"], "panda");
    let (code, text) = export(
        &sb,
        &["panda", "--out", "ds", "--fps", "100", "--task", "press"],
    );
    assert_eq!(code, Some(0), "{text}");
    let info = json(&sb.path("ds/meta/info.json"));
    assert_keyed_as_a_recorder(&info);
    let names = &info["features"]["action"]["names"];
    let want: Vec<String> = (1..=7).map(|k| format!("panda_joint{k}")).collect();
    assert_eq!(names, &serde_json::json!(want));
    assert_eq!(
        info["features"]["observation.state"]["shape"],
        serde_json::json!([14])
    );
    let (ds, run) = (sb.path("ds"), sb.path("panda"));
    let said = check(
        "lerobot_check.py",
        &[
            ds.to_str().expect("utf-8"),
            "100",
            run.to_str().expect("utf-8"),
        ],
        "lerobot ok: 1 episodes, 40 frames",
    );
    assert_eq!(
        episodes_said(&said)[0]["tasks"],
        serde_json::json!(["press"])
    );
}

/// Nothing of a refused export is left: no `out`, no hidden partial folder.
fn assert_nothing_left(sb: &Sandbox, out: &str) {
    assert!(!sb.path(out).exists(), "{out} left");
    assert!(
        !sb.path(&format!(".{out}.partial")).exists(),
        "partial left"
    );
}

#[test]
fn bad_input_exits_2_with_the_reason_and_leaves_nothing() {
    let sb = Sandbox::new("lerobot-bad");
    let paper = format!("{}/scenarios/paper.toml", env!("CARGO_MANIFEST_DIR"));
    let o = sb.tactile(&[
        "run",
        &paper,
        "--in-process",
        "-q",
        "--set",
        "samples=50",
        "--out",
        "r",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::create_dir(sb.path("empty")).expect("mkdir");
    for (args, why) in [
        (vec!["empty", "--out", "ds"], "no master.rec"),
        (vec!["nowhere", "--out", "ds"], "not a folder"),
        (vec!["r", "--out", "ds", "--fps", "0"], "--fps 0"),
        (vec!["r", "--out", "ds", "--fps", "101"], "above"),
    ] {
        let (code, text) = export(&sb, &args);
        assert_eq!(code, Some(2), "{args:?}: {text}");
        assert!(text.contains(why), "{args:?}: {text}");
        assert_nothing_left(&sb, "ds");
    }
    // An --out that holds a file is refused and left as it was.
    std::fs::create_dir(sb.path("full")).expect("mkdir");
    sb.write("full/keep.txt", "mine");
    let (code, text) = export(&sb, &["r", "--out", "full"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("not empty"), "{text}");
    let kept: Vec<_> = std::fs::read_dir(sb.path("full")).expect("dir").collect();
    assert_eq!(kept.len(), 1);
    assert!(!sb.path(".full.partial").exists());
    // An empty --out is taken.
    std::fs::create_dir(sb.path("new")).expect("mkdir");
    let (code, text) = export(&sb, &["r", "--out", "new"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(sb.path("new/meta/info.json").is_file());
}

#[test]
fn a_damaged_record_is_exported_up_to_its_damage_and_said() {
    if !python_ready() {
        return cannot("python3 lacks pyarrow, pandas or rerun-sdk");
    }
    let sb = Sandbox::new("lerobot-damage");
    run(&sb, "paper.toml", &["samples=200"], "r");
    for (file, cut) in [("master.rec", false), ("slave.rec", true)] {
        let copy = format!("d-{file}");
        std::fs::create_dir(sb.path(&copy)).expect("mkdir");
        for e in std::fs::read_dir(sb.path("r")).expect("dir").flatten() {
            if e.path().is_file() {
                std::fs::copy(e.path(), sb.path(&copy).join(e.file_name())).expect("copy");
            }
        }
        // A stretch in the middle overwritten, or the tail torn off.
        let rec = sb.path(&copy).join(file);
        let mut bytes = std::fs::read(&rec).expect("read");
        let half = bytes.len() / 2;
        if cut {
            bytes.truncate(half);
        } else {
            bytes[half..half + 64].fill(0xff);
        }
        std::fs::write(&rec, bytes).expect("write");
        let out = format!("ds-{file}");
        let (code, text) = export(&sb, &[&copy, "--out", &out, "--fps", "50"]);
        assert_eq!(code, Some(0), "{text}");
        assert!(text.contains("damaged at sample"), "{file}: {text}");
        let info = json(&sb.path(&format!("{out}/meta/info.json")));
        let frames = info["total_frames"].as_u64().expect("frames");
        assert!(frames > 0 && frames < 100, "{file}: {frames} of 100 frames");
        let (ds, dir) = (sb.path(&out), sb.path(&copy));
        let said = check(
            "lerobot_check.py",
            &[
                ds.to_str().expect("utf-8"),
                "50",
                dir.to_str().expect("utf-8"),
            ],
            "lerobot ok: 1 episodes",
        );
        let at = episodes_said(&said)[0]["damaged_at_sample"]
            .as_u64()
            .expect("damaged_at_sample");
        // The frames are those of the samples before the damage (100 Hz, 50 fps).
        assert_eq!(frames, at.div_ceil(2), "{file}: damaged at {at}");
    }
}

#[test]
fn a_stop_request_ends_an_export_with_nothing_written() {
    let sb = Sandbox::new("lerobot-stop");
    let lockstep = format!("{}/scenarios/lockstep-1e6.toml", env!("CARGO_MANIFEST_DIR"));
    // Long enough that the export is still joining when the request comes.
    let o = sb.tactile(&[
        "run",
        &lockstep,
        "--in-process",
        "--no-trace",
        "-q",
        "--set",
        "samples=200000",
        "--out",
        "long",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let child = sb
        .command(&["export", "lerobot", "long", "--out", "ds", "--fps", "1000"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spawn");
    let (pid, raw) = (rustix::process::Pid::from_child(&child), child.id());
    let limit = std::time::Duration::from_secs(60);
    // Once it answers SIGINT and has begun writing (its hidden folder made).
    util::wait_for("the export writing", limit, || {
        util::catches(raw, rustix::process::Signal::INT) && sb.path(".ds.partial").exists()
    });
    rustix::process::kill_process(pid, rustix::process::Signal::INT).expect("SIGINT");
    let o = util::wait_within(child, limit);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("stop request"), "{err}");
    assert_nothing_left(&sb, "ds");
}
