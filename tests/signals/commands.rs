//! The commands that are not a run stop on SIGINT and SIGTERM within a second, with
//! exit 130, leaving no process and no temporary file (issue 65): `fuzz`, `kernels`
//! (input that never comes, or never ends), `report` over a damaged record, `bench`,
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

/// Issue 65's record: the slave's record holds 16 MB of sync words each claiming a
/// megabyte, then a hole of 64 GiB (a sparse file: no disk used), more than any
/// machine reads in a second. `report` stops on SIGINT within a second, with no
/// report (it was reading the records' starts), where it was 80 s past the signal.
#[test]
fn report_stops_on_sigint_inside_a_damaged_record() {
    let sb = Sandbox::new("sigreport");
    sb.write(
        "s.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 500"),
    );
    let o = sb.tactile(&["run", "s.toml", "--in-process", "-q", "--out", "run"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut bytes = tactile_records::MAGIC.to_vec();
    let mut header = tactile_records::frames::SYNC.to_vec();
    header.extend_from_slice(&(1u32 << 20).to_le_bytes());
    header.extend_from_slice(&0u32.to_le_bytes());
    while bytes.len() < 16 << 20 {
        bytes.extend_from_slice(&header);
    }
    let slave = sb.path("run").join("slave.rec");
    std::fs::write(&slave, &bytes).expect("write");
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(&slave)
        .expect("open");
    f.set_len(bytes.len() as u64 + (64 << 30))
        .expect("a sparse hole");
    drop(f);
    let child = procs::spawn(&mut sb.command(&["report", "run", "--out", "rep"]));
    procs::wait_until_it_catches(child.id());
    // Into the damage: reading its starts.
    std::thread::sleep(std::time::Duration::from_millis(300));
    let err = procs::stopped(child, Signal::INT);
    assert!(err.contains("stop request"), "{err}");
    assert!(!sb.path("rep").join("summary.json").exists());
}

/// `bench` stopped by SIGINT in its bare iceoryx2 hop (6 s of pings, after two loops
/// of 6 s), which took no notice of a stop: exit 130 within a second, the echo process
/// ended too, no node left running.
#[test]
fn bench_stops_on_sigint_inside_its_bare_hop() {
    let sb = Sandbox::new("sigbench");
    let out = sb.path("bench");
    let child = procs::spawn(&mut sb.command(&[
        "bench",
        "--samples",
        "24000",
        "--rates",
        "4000",
        "--probe-s",
        "0",
        "--out",
        out.to_str().expect("utf-8"),
        "--prefix",
        &sb.prefix,
    ]));
    let mut echo = Vec::new();
    util::wait_for("the bare hop's echo runs", util::LIMIT, || {
        echo = procs::children_running(child.id() as i32, "bench-echo");
        !echo.is_empty()
    });
    let err = procs::stopped(child, Signal::INT);
    assert!(
        echo.iter().all(|&p| !procs::alive(p)),
        "the echo runs on: {err}"
    );
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

/// A run stopped before its master began its record (a Ctrl-C at once: here node
/// programs that never start recording) is a stop, exit 130, not "the run failed, no
/// record from the master", exit 1; no node is left running.
#[test]
fn a_run_stopped_before_the_master_records_is_a_stop() {
    let sb = Sandbox::new("sigearly");
    let (nodes, log) = (sb.path("nodes"), sb.path("log"));
    std::fs::create_dir_all(&log).expect("log");
    for role in ["master", "emulator", "slave"] {
        procs::script(&nodes, &format!("tactile-{role}"), &procs::busy(&log, role));
    }
    sb.write("s.toml", &util::wall_delay());
    let child = procs::spawn(
        sb.command(&["run", "s.toml", "--out", "run", "--prefix", &sb.prefix])
            .env("TACTILE_NODE_DIR", &nodes),
    );
    // The master runs.
    procs::pid_in(&log.join("master.pid"));
    let err = procs::stopped(child, Signal::INT);
    assert!(err.contains("before the master began its record"), "{err}");
    for role in ["master", "emulator", "slave"] {
        let pid = procs::pid_in(&log.join(format!("{role}.pid")));
        assert!(!procs::alive(pid), "{role} runs on: {err}");
    }
}
