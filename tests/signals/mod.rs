//! Stopping when asked: SIGINT to an in-process run, to a sweep and to the whole
//! process group of a launcher (the terminal's Ctrl-C) ends each with exit 130 and the
//! report of what ran; a closed stdout ends a command quietly.

mod commands;
mod hdl;

use crate::util;

use std::os::unix::process::CommandExt;
use std::process::Stdio;
use std::time::{Duration, Instant};
use util::{finish, wait_for, Sandbox};

fn signal(pid: i32, sig: rustix::process::Signal) {
    let pid = rustix::process::Pid::from_raw(pid).expect("pid");
    let _ = rustix::process::kill_process(pid, sig);
}

/// A million samples in-process, stopped by SIGINT once the records are growing: it
/// ends with 130 soon after (the issue asks for a second; the bound here leaves room
/// for a loaded CI machine), its records say `interrupted`, and the report of what
/// ran is written.
#[test]
fn sigint_stops_an_in_process_run_with_a_report_of_what_ran() {
    let sb = Sandbox::new("siginproc");
    let text = util::wall_delay().replace("samples = 8000", "samples = 1000000");
    let scenario = sb.write("s.toml", &text);
    let child = sb
        .command(&["run", "s.toml", "--in-process", "--out", "run"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start");
    let rec = sb.path("run").join("master.rec");
    util::wait_for_rows(&rec, util::MASTER_ROWS * 15_000, Duration::from_secs(30));
    let asked = Instant::now();
    signal(child.id() as i32, rustix::process::Signal::INT);
    let (code, err) = finish(child);
    let took = asked.elapsed();
    assert_eq!(code, Some(130), "{err}");
    assert!(
        took < Duration::from_secs(3),
        "stopped {took:?} after SIGINT"
    );
    let s = sb.json("run", "summary.json");
    assert_eq!(s["interrupted"], true, "{s}");
    assert_eq!(s["failed"], false, "{s}");
    let mut ended = s["nodes"]["master"]["ended"]
        .as_str()
        .expect("ended")
        .to_string();
    if ended.starts_with("not read to its end") {
        // The interrupted report had its 700 ms and a loaded machine: the records are
        // whole, and the report of all of them says how the master ended.
        let out = sb.command(&["report", "run"]).output().expect("report");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        let whole = sb.json("run", "summary.json");
        ended = whole["nodes"]["master"]["ended"]
            .as_str()
            .expect("ended")
            .into();
    }
    assert!(ended.starts_with("interrupted"), "{ended}");
    assert!(s["samples_sent"].as_u64().is_some_and(|n| n > 0), "{s}");
    drop(scenario);
}

/// Starts a sweep of six runs of the wall scenario, `samples` samples each, `jobs` at
/// once, into `sw`.
fn six_run_sweep(sb: &Sandbox, samples: u64, jobs: &str) -> std::process::Child {
    let text = util::wall_delay().replace("samples = 8000", &format!("samples = {samples}"));
    sb.write("s.toml", &text);
    sb.command(&[
        "sweep",
        "s.toml",
        "--set",
        "control.kind=none,tdpa,wave",
        // Six runs (a value given twice would be refused: the same run twice).
        "--set",
        "seed=1,2",
        "--jobs",
        jobs,
        "--out",
        "sw",
    ])
    .stdout(Stdio::piped())
    .stderr(Stdio::piped())
    .spawn()
    .expect("start")
}

/// A sweep stopped by SIGINT after its first run (one run at a time): exit 130,
/// `sweep.csv` holds the runs that finished (and no partial one), no panic.
#[test]
fn sigint_stops_a_sweep_keeping_its_finished_rows() {
    let sb = Sandbox::new("sigsweep");
    let child = six_run_sweep(&sb, 200_000, "1");
    let second = sb.path("sw").join("run-0001").join("master.rec");
    wait_for("the second run starts", Duration::from_secs(60), || {
        second.exists()
    });
    signal(child.id() as i32, rustix::process::Signal::INT);
    let (code, err) = finish(child);
    assert_eq!(code, Some(130), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("stopped by a signal after 1 of 6 runs"),
        "{err}"
    );
    let table = std::fs::read_to_string(sb.path("sw").join("sweep.csv")).expect("sweep.csv");
    assert_eq!(
        table.lines().count(),
        2,
        "header and the finished run:\n{table}"
    );
}

/// A sweep stopped by SIGINT while its first two runs (two at a time) are under way:
/// neither is counted as ended ("1/6 runs"), each is said as stopped, and the closing
/// line says none of the 6 ended.
#[test]
fn a_sweep_stopped_mid_run_counts_no_run_as_ended() {
    let sb = Sandbox::new("sigsweep2");
    let child = six_run_sweep(&sb, 2_000_000, "2");
    let rec = |k: usize| sb.path("sw").join(format!("run-{k:04}")).join("master.rec");
    wait_for("both runs start", Duration::from_secs(60), || {
        rec(0).exists() && rec(1).exists()
    });
    signal(child.id() as i32, rustix::process::Signal::INT);
    let (code, err) = finish(child);
    assert_eq!(code, Some(130), "{err}");
    assert!(!err.contains("/6 runs,"), "no run ended:\n{err}");
    for k in 0..2 {
        let said = format!("run-{k:04} stopped before it ended");
        assert!(err.contains(&said), "{said}:\n{err}");
    }
    assert!(err.contains("after 0 of 6 runs"), "{err}");
}

/// The terminal's Ctrl-C reaches the launcher and its nodes at once: exit 130, the
/// run `interrupted`, not `failed`, and no node restarted.
#[test]
fn ctrl_c_to_the_process_group_is_a_stop_not_a_failure() {
    let sb = Sandbox::new("sigpgrp");
    let scenario = sb.write("s.toml", &util::paper_1khz(20_000));
    let child = sb
        .command(&["run", scenario.to_str().expect("utf-8"), "--out", "run"])
        .args(["--prefix", &sb.prefix, "-q"])
        .process_group(0)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start");
    let rec = sb.path("run").join("slave.rec");
    util::wait_for_rows(&rec, 1_500, Duration::from_secs(20));
    let group = rustix::process::Pid::from_raw(child.id() as i32).expect("pid");
    let _ = rustix::process::kill_process_group(group, rustix::process::Signal::INT);
    let (code, err) = finish(child);
    assert_eq!(code, Some(130), "{err}");
    sb.assert_no_leftover_processes();
    let s = sb.json("run", "summary.json");
    assert_eq!(s["interrupted"], true, "{s}");
    assert_eq!(s["failed"], false, "{s}");
    let events = s["events"].to_string();
    assert!(!events.contains("restart"), "{events}");
}

/// `tactile sweep ... | head -1`: the reader goes away; the sweep ends quietly.
#[test]
fn a_closed_stdout_ends_quietly() {
    let sb = Sandbox::new("sigpipe");
    sb.write("s.toml", &util::wall_delay());
    let mut child = sb
        .command(&[
            "sweep",
            "s.toml",
            "--set",
            "control.kind=none,tdpa",
            "--out",
            "sw",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start");
    drop(child.stdout.take());
    let (code, err) = finish(child);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let mut kernels = sb
        .command(&["kernels", "fk"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start");
    drop(kernels.stdout.take());
    let rows = "theta1,theta2,theta3\n".to_string() + &"0.1,0.2,0.3\n".repeat(200_000);
    if let Some(mut stdin) = kernels.stdin.take() {
        let _ = std::io::Write::write_all(&mut stdin, rows.as_bytes());
    }
    let (code, err) = finish(kernels);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.is_empty(), "{err}");
}

/// SIGTERM to any one node, master included, is a stop from outside, the same for
/// each: the launcher ends with 130, the run `interrupted`, not `failed` (the master's
/// was "failed", exit 1, the others' 130).
#[test]
fn sigterm_to_any_node_is_the_same_stop() {
    for role in ["master", "emulator", "slave"] {
        let sb = Sandbox::new(&format!("sigterm{role}"));
        let scenario = sb.write("s.toml", &util::paper_1khz(20_000));
        let child = sb.spawn_run(&scenario, "run", &[]);
        let rec = sb.path("run").join("slave.rec");
        util::wait_for_rows(&rec, 1_500, Duration::from_secs(20));
        let pid = util::pid_of(&sb.prefix, role).unwrap_or_else(|| panic!("no {role}"));
        signal(pid, rustix::process::Signal::TERM);
        let (code, err) = finish(child);
        assert_eq!(code, Some(130), "{role}: {err}");
        sb.assert_no_leftover_processes();
        let s = sb.json("run", "summary.json");
        assert_eq!(
            (&s["interrupted"], &s["failed"]),
            (&serde_json::json!(true), &serde_json::json!(false)),
            "{role}: {}",
            s["events"]
        );
    }
}
