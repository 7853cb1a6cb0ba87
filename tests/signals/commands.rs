//! The commands that are not a run stop on SIGINT and SIGTERM within a second, with
//! exit 130, leaving no process and no temporary file (issue 65): `fuzz`, `kernels`
//! (input that never comes, or never ends), `bench`,
//! and the node programs' build a `run` starts on a fresh clone.

use crate::util::procs;
use crate::util::{self, Sandbox};
use rustix::process::Signal;
use std::io::Write;

/// `fuzz` for a minute, stopped by each signal: it ends at the input in hand, prints
/// the target's row and says what it stopped, and its scratch folder is gone.
#[test]
fn fuzz_stops_on_either_signal_and_removes_its_scratch_folder() {
    for sig in [Signal::INT, Signal::TERM] {
        let sb = Sandbox::new("sigfuzz");
        let tmp = procs::tmp(&sb);
        let child = procs::spawn(
            sb.command(&["fuzz", "--target", "records", "--seconds", "60"])
                .env("TMPDIR", &tmp),
        );
        procs::wait_until_it_catches(child.id());
        let err = procs::stopped(child, sig);
        assert!(err.contains("records stopped before its time"), "{err}");
        procs::assert_empty(&tmp);
    }
}

/// `kernels fk` reading a pipe that gives nothing (a FIFO nobody writes to) and one
/// that never ends: each stops on a signal with nothing written to stdout.
#[test]
fn kernels_stops_on_either_signal_however_its_input_comes() {
    for (sig, endless) in [
        (Signal::INT, false),
        (Signal::TERM, true),
        (Signal::INT, true),
    ] {
        let sb = Sandbox::new("sigkern");
        let mut child = procs::spawn(&mut sb.command(&["kernels", "fk"]));
        let mut stdin = child.stdin.take().expect("stdin");
        let writer = std::thread::spawn(move || {
            let _ = stdin.write_all(b"theta1,theta2,theta3\n");
            let row = b"0.1,0.2,0.3\n".repeat(1000);
            // Until the command is gone (the pipe breaks), or held open silent.
            while endless && stdin.write_all(&row).is_ok() {}
            if !endless {
                std::thread::sleep(std::time::Duration::from_secs(30));
            }
        });
        procs::wait_until_it_catches(child.id());
        let err = procs::stopped(child, sig);
        assert!(err.contains("nothing written to stdout"), "{err}");
        if endless {
            writer.join().expect("writer");
        }
    }
}

/// `bench` stopped by SIGINT while its first loop runs: exit 130 within a second, no
/// node left running.
#[test]
fn bench_stops_on_sigint_with_no_process_left() {
    let sb = Sandbox::new("sigbench");
    let out = sb.path("bench");
    let child = procs::spawn(&mut sb.command(&[
        "bench",
        "--samples",
        "200000",
        "--rates",
        "1000",
        "--probe-s",
        "0",
        "--out",
        out.to_str().expect("utf-8"),
        "--prefix",
        &sb.prefix,
    ]));
    util::wait_for_rows(
        &out.join("iceoryx2-1000").join("slave.rec"),
        500,
        util::LIMIT,
    );
    procs::stopped(child, Signal::INT);
    sb.assert_no_leftover_processes();
}

/// `run` on a fresh clone first builds the node programs (minutes): SIGTERM then ends
/// the build (a stand-in for Cargo that waits on a child of its own) and the run,
/// exit 130 within a second, no build left running, nothing written.
#[test]
fn run_stops_the_node_programs_build_on_sigterm() {
    let sb = Sandbox::new("sigbuild");
    let log = sb.path("log");
    let cargo = procs::script(&sb.path("bin"), "cargo", &procs::busy(&log, "cargo"));
    std::fs::create_dir_all(&log).expect("log");
    sb.write("s.toml", &util::wall_delay());
    let child = procs::spawn(
        sb.command(&["run", "s.toml", "--out", "run", "--prefix", &sb.prefix])
            .env_remove("TACTILE_NODE_DIR")
            .env("CARGO", &cargo),
    );
    let (build, helper) = (
        procs::pid_in(&log.join("cargo.pid")),
        procs::pid_in(&log.join("cargo.child")),
    );
    let err = procs::stopped(child, Signal::TERM);
    assert!(err.contains("build stopped"), "{err}");
    assert!(
        !procs::alive(build) && !procs::alive(helper),
        "the build runs on"
    );
    assert!(!sb.path("run").exists(), "nothing written");
}
