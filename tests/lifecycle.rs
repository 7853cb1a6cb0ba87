//! A node's and a run's life as documented: a node stopped by SIGINT (exit 130), a
//! master whose peers never come (exit 1), restarts exhausted, counters summed over a
//! restarted node's segments, and a sweep of process runs.

use crate::util;

use std::path::Path;
use std::time::Duration;
use tactile_records::slave::{SlaveSample, SlaveTotals};
use tactile_records::{Record, RecordReader};
use util::{finish, kill_once_recorded, start_node, wait_for, Sandbox};

#[test]
fn a_node_stopped_by_sigint_exits_130_with_its_record_closed() {
    let sb = Sandbox::new("node130");
    let scenario = sb.write("s.toml", &util::paper_1khz(1000));
    let slave = start_node(&sb, "slave", &scenario, "s", &[]);
    wait_for("the slave holds its lock", Duration::from_secs(10), || {
        tactile_runtime::lock::in_use(&sb.prefix).is_err()
    });
    let pid = rustix::process::Pid::from_raw(slave.id() as i32).expect("pid");
    let _ = rustix::process::kill_process(pid, rustix::process::Signal::INT);
    let (code, err) = finish(slave);
    assert_eq!(code, Some(130), "{err}");
    let log = std::fs::read_to_string(sb.path("s").join("slave.log")).expect("log");
    assert!(log.contains("stop: interrupted"), "{log}");
}

#[test]
fn a_master_whose_peers_never_come_exits_1_naming_them() {
    let sb = Sandbox::new("startup");
    let scenario = sb.write("s.toml", &util::paper_1khz(1000));
    let master = start_node(&sb, "master", &scenario, "m", &["--startup-timeout-s", "1"]);
    let (code, err) = finish(master);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("no answer from the emulator and slave within 1.0 s"),
        "{err}"
    );
}

/// `tactile run SCENARIO --out OUT --max-restarts 0` (and `extra`) under the sandbox's
/// prefix, its output captured.
fn run_without_restarts(
    sb: &Sandbox,
    scenario: &Path,
    out: &Path,
    extra: &[&str],
) -> std::process::Child {
    sb.spawn_run(scenario, out, &[&["--max-restarts", "0"], extra].concat())
}

#[test]
fn a_node_that_dies_past_its_restarts_ends_the_run_as_failed() {
    let sb = Sandbox::new("norestart");
    let scenario = sb.write("s.toml", &util::paper_1khz(20_000));
    let out = sb.path("run");
    let child = run_without_restarts(&sb, &scenario, &out, &[]);
    wait_for("the slave runs", Duration::from_secs(20), || {
        util::pid_of(&sb.prefix, "slave").is_some()
    });
    let slave = util::pid_of(&sb.prefix, "slave").expect("slave");
    util::wait_for_rows(&out.join("slave.rec"), 800, Duration::from_secs(20));
    let pid = rustix::process::Pid::from_raw(slave).expect("pid");
    let _ = rustix::process::kill_process(pid, rustix::process::Signal::KILL);
    let o = util::wait_within(child, util::LIMIT);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("no restarts left"), "{err}");
    let s = sb.json("run", "summary.json");
    assert_eq!(s["failed"], true);
    assert!(
        !s["events"].to_string().contains("restarted"),
        "{}",
        s["events"]
    );
    sb.assert_no_leftover_processes();
}

/// Each segment's last counters, read from the record itself.
fn segment_counters(rec: &Path) -> Vec<SlaveTotals> {
    let mut r = RecordReader::<Record<SlaveSample, SlaveTotals>>::open(rec).expect("record");
    let mut segments: Vec<Option<SlaveTotals>> = Vec::new();
    while let Some(x) = r.next_record().expect("readable") {
        match x {
            Record::Start(_) => segments.push(None),
            Record::Counters(t) => {
                if let Some(last) = segments.last_mut() {
                    *last = Some(t.counters);
                }
            }
            _ => {}
        }
    }
    segments.into_iter().flatten().collect()
}

#[test]
fn a_restarted_nodes_counters_are_summed_over_its_segments() {
    let sb = Sandbox::new("segments");
    let scenario = sb.write("s.toml", &util::paper_1khz(6000));
    let master = start_node(&sb, "master", &scenario, "m", &[]);
    let emulator = start_node(&sb, "emulator", &scenario, "e", &[]);
    let slave = start_node(&sb, "slave", &scenario, "s", &[]);
    let rec = sb.path("s").join("slave.rec");
    // Past a second of samples at 1 kHz, so the first segment has written its
    // counters (every second).
    kill_once_recorded(slave, &rec, 1_500);
    let slave = start_node(&sb, "slave", &scenario, "s", &["--append"]);
    for (role, child) in [("master", master), ("emulator", emulator), ("slave", slave)] {
        let (code, err) = finish(child);
        assert_eq!(code, Some(0), "{role}: {err}");
    }
    let o = sb.tactile(&["report", "m", "e", "s", "--out", "r"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let segments = segment_counters(&rec);
    assert_eq!(segments.len(), 2, "two segments with counters");
    let s = sb.json("r", "summary.json");
    let steps: u64 = segments.iter().map(|t| t.counters.steps).sum();
    let received: u64 = segments.iter().map(|t| t.v_in.received).sum();
    assert!(segments.iter().all(|t| t.counters.steps > 0));
    assert_eq!(
        util::num(&s["slave"]["counters"]["steps"]),
        steps as f64,
        "{}",
        s["slave"]
    );
    assert_eq!(util::num(&s["slave"]["v_in"]["received"]), received as f64);
    sb.assert_no_leftover_processes();
}

#[test]
fn a_sweep_of_process_runs_tabulates_each() {
    let sb = Sandbox::new("sweepproc");
    sb.write("s.toml", &util::paper_1khz(300));
    let o = sb.tactile(&[
        "sweep",
        "s.toml",
        "--set",
        "control.kind=none,tdpa",
        "--processes",
        "--out",
        "sw",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let table = std::fs::read_to_string(sb.path("sw").join("sweep.csv")).expect("sweep.csv");
    assert_eq!(table.lines().count(), 3, "{table}");
    for k in 0..2 {
        let run = sb.path("sw").join(format!("run-{k:04}"));
        for role in ["master", "emulator", "slave"] {
            assert!(run.join(format!("{role}.rec")).is_file(), "{k}: {role}");
        }
        let s = sb.json(&format!("sw/run-{k:04}"), "summary.json");
        assert_eq!(s["runner"], "processes", "{s}");
        assert_eq!(util::num(&s["samples_received"]), 300.0);
    }
}

/// Two runs into one --out: the second is refused (exit 2, naming the first) with
/// nothing of the first touched, so does a report into it meanwhile; the first ends
/// whole.
#[test]
fn an_output_folder_holds_one_run_at_a_time() {
    let sb = Sandbox::new("oneout");
    let scenario = sb.write("s.toml", &util::paper_1khz(3000));
    let out = sb.path("out");
    let first = sb.spawn_run(&scenario, &out, &[]);
    let rec = out.join("slave.rec");
    util::wait_for_rows(&rec, 150, Duration::from_secs(30));
    let before = tactile_records::rows_in(&rec);
    let second = sb.tactile(&[
        "run",
        scenario.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(second.status.code(), Some(2));
    let err = String::from_utf8_lossy(&second.stderr);
    assert!(
        err.contains("tactile run (pid") && err.contains("is writing into it"),
        "{err}"
    );
    let report = sb.tactile(&["report", out.to_str().expect("utf-8")]);
    assert_eq!(report.status.code(), Some(2), "{report:?}");
    assert!(
        tactile_records::rows_in(&rec) >= before,
        "the record is kept"
    );
    let done = util::wait_within(first, Duration::from_secs(60));
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let s = sb.json("out", "summary.json");
    assert_eq!(s["samples_sent"], 3000, "{s}");
    assert!(!out.join(".tactile.lock").exists());
    let names: Vec<String> = std::fs::read_dir(&out)
        .expect("folder")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect();
    assert!(names.is_empty(), "{names:?}");
}

/// `tactile run` into `run` (with `extra`), its slave stopped by SIGSTOP once its
/// record holds `samples`; the run's output.
fn freeze_the_slave(
    sb: &Sandbox,
    scenario: &Path,
    extra: &[&str],
    samples: u64,
) -> std::process::Output {
    let out = sb.path("run");
    let child = run_without_restarts(sb, scenario, &out, extra);
    util::wait_for_rows(&out.join("slave.rec"), samples, Duration::from_secs(20));
    let slave = util::pid_of(&sb.prefix, "slave").expect("slave");
    let pid = rustix::process::Pid::from_raw(slave).expect("pid");
    rustix::process::kill_process(pid, rustix::process::Signal::STOP).expect("SIGSTOP");
    util::wait_within(child, util::LIMIT)
}

/// A slave frozen by SIGSTOP: the launcher names it frozen after the stall limit, kills it, and the run is failed (exit 1), not a completed
/// run with most samples lost.
#[test]
fn a_frozen_node_fails_the_run_after_the_stall_limit() {
    let sb = Sandbox::new("frozen");
    let scenario = sb.write("s.toml", &util::paper_1khz(20_000));
    let o = freeze_the_slave(&sb, &scenario, &["--stall-s", "1.5"], 800);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let s = sb.json("run", "summary.json");
    assert_eq!(s["failed"], true);
    let events = s["events"].to_string();
    assert!(
        events.contains("slave made no progress for 1.5 s (the process is stopped (SIGSTOP"),
        "{events}"
    );
    assert!(
        util::num(&s["samples_sent"]) < 20_000.0,
        "stopped early: {s}"
    );
    sb.assert_no_leftover_processes();
}

/// A slave frozen by SIGSTOP in a run shorter than the stall limit (3 s of samples,
/// the default 5 s limit): still stopped when the master ends, it fails the run (exit
/// 1), named with the moment it stopped, not a completed run with most samples lost.
#[test]
fn a_node_still_frozen_when_the_run_ends_fails_it() {
    let sb = Sandbox::new("frozenend");
    let scenario = sb.write("s.toml", &util::paper_1khz(3000));
    let o = freeze_the_slave(&sb, &scenario, &[], 300);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("slave was still frozen when the run ended"),
        "{err}"
    );
    let s = sb.json("run", "summary.json");
    assert_eq!(s["failed"], true);
    let events = s["events"].to_string();
    assert!(
        events.contains("the process is stopped (SIGSTOP or a job-control stop) since"),
        "{events}"
    );
    sb.assert_no_leftover_processes();
}

/// `--append` into a file that is not a record: bad input (exit 2, as documented),
/// naming the file, the file left as it was; it exited 1, as if the run had failed.
#[test]
fn append_into_a_file_that_is_not_a_record_is_bad_input() {
    let sb = Sandbox::new("appendbad");
    let scenario = sb.write("s.toml", &util::paper_1khz(1000));
    std::fs::create_dir_all(sb.path("s")).expect("folder");
    let rec = sb.write("s/slave.rec", "these are notes, not a record\n");
    let slave = start_node(&sb, "slave", &scenario, "s", &["--append"]);
    let (code, err) = finish(slave);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("slave.rec") && err.contains("not a Tactile record"),
        "{err}"
    );
    let kept = std::fs::read_to_string(rec).expect("still there");
    assert_eq!(kept, "these are notes, not a record\n");
}
