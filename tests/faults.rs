//! Faults done for real: processes killed with SIGKILL mid-run, a stop signal to the
//! launcher, a crashed run followed by a new one, a full subscriber buffer, corrupted
//! and dropped samples, forces past the device's limit.

use crate::util;

use std::time::Duration;
use tactile_messages::samples::{Flags, Forward};
use tactile_report::trace::signal_columns;
use tactile_transport::ipc::{self, IpcPublisher, IpcSubscriber};
use tactile_transport::{Publish, Subscribe};
use util::{cannot, column, finish, pid_of, Sandbox};

/// Sends `signal`; a process already gone is fine (nodes stop by themselves when their
/// launcher dies).
fn kill(pid: i32, signal: rustix::process::Signal) {
    let pid = rustix::process::Pid::from_raw(pid).expect("pid");
    let _ = rustix::process::kill_process(pid, signal);
}

/// Waits until the master of the run into `out` has recorded `samples`, then kills
/// `role` with SIGKILL.
fn kill_mid_run(sb: &Sandbox, out: &str, role: &str, samples: u64) {
    let rec = sb.path(out).join("master.rec");
    util::wait_for_rows(&rec, util::MASTER_ROWS * samples, Duration::from_secs(30));
    let pid = pid_of(&sb.prefix, role).unwrap_or_else(|| panic!("no {role} running"));
    kill(pid, rustix::process::Signal::KILL);
}

/// Kills `role` mid-run; the launcher restarts it and the loop must break, command
/// zero torque, and resume.
fn peer_dies_and_the_loop_resumes(role: &str) {
    let sb = Sandbox::new(role);
    let scenario = sb.write("s.toml", &util::paper_1khz(4000));
    let child = sb.spawn_run(&scenario, "run", &[]);
    kill_mid_run(&sb, "run", role, 1_500);
    let (code, stderr) = finish(child);
    sb.assert_no_leftover_processes();
    assert_eq!(code, Some(1), "a run with a dead process fails\n{stderr}");
    assert!(
        stderr.contains(&format!("{role} was killed by signal 9")),
        "{stderr}"
    );
    let s = sb.json("run", "summary.json");
    assert_eq!(s["failed"], true);
    let events: Vec<String> = s["events"]
        .as_array()
        .expect("events")
        .iter()
        .map(|e| e.as_str().expect("text").to_string())
        .collect();
    let joined = events.join("\n");
    assert!(
        joined.contains(&format!("{role} was killed by signal 9")),
        "{joined}"
    );
    assert!(joined.contains(&format!("{role} restarted")), "{joined}");
    assert!(joined.contains("loop broken"), "{joined}");
    assert!(joined.contains("loop resumed"), "{joined}");
    let m = &s["master"]["counters"];
    assert!(util::num(&m["peer_lost_samples"]) > 0.0, "{m}");
    assert!(util::num(&m["loop_breaks"]) >= 1.0);
    assert!(util::num(&m["resumes"]) >= 1.0);
    // Every sample past the timeout is marked and commands zero torque.
    let trace = sb.trace("run");
    let flags = column(&trace, "flags_m");
    let taus: Vec<Vec<f64>> = (1..=3)
        .map(|j| column(&trace, &format!("tau_{j}")))
        .collect();
    let lost: Vec<usize> = (0..flags.len())
        .filter(|&n| Flags::from_bits(flags[n] as u32).intersects(Flags::PEER_LOST))
        .collect();
    assert!(!lost.is_empty());
    for &n in &lost {
        assert!(taus.iter().all(|t| t[n] == 0.0), "sample {n} has torque");
    }
    // The loop broke exactly at the timeout: the first lost sample is the tenth
    // unanswered one in a row after an answered one.
    let received = column(&trace, "received");
    let first = lost[0];
    assert_eq!(
        received[first - 10],
        1.0,
        "sample {} was answered",
        first - 10
    );
    assert!(
        received[first - 9..=first].iter().all(|r| *r == 0.0),
        "ten unanswered samples before the break"
    );
    // And it resumed: answers again after the lost stretch.
    let last_lost = *lost.last().expect("lost");
    assert!(
        received[last_lost + 1..]
            .iter()
            .filter(|r| **r == 1.0)
            .count()
            > 100
    );
}

/// Lockstep has no clock, so neither a drop nor a stall may change what it computes:
/// with 5 % of the samples dropped each way and the emulator, then the master,
/// stopped for 300 ms mid-run (a loaded machine's worst), the three processes give the
/// in-process run's signals exactly. Before the emulator's drop notice, each drop cost
/// the master a 100 ms timeout, and a stall past it held a sample the in-process run
/// did not.
#[test]
fn lockstep_drops_and_stalls_change_nothing() {
    let sb = Sandbox::new("lockstall");
    let text = util::paper_1khz(20_000)
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace("[network.forward]\n", "[network.forward]\nloss = 0.05\n")
        .replace("[network.backward]\n", "[network.backward]\nloss = 0.05\n");
    let scenario = sb.write("s.toml", &text);
    let child = sb.spawn_run(&scenario, "run", &[]);
    let rec = sb.path("run").join("master.rec");
    for (role, samples) in [("emulator", 1_000), ("master", 4_000)] {
        util::wait_for_rows(&rec, util::MASTER_ROWS * samples, Duration::from_secs(30));
        let pid = pid_of(&sb.prefix, role).unwrap_or_else(|| panic!("no {role} running"));
        kill(pid, rustix::process::Signal::STOP);
        std::thread::sleep(Duration::from_millis(300));
        kill(pid, rustix::process::Signal::CONT);
    }
    let (code, stderr) = finish(child);
    assert_eq!(code, Some(0), "{stderr}");
    sb.assert_no_leftover_processes();
    sb.simulate(&scenario, "sim");
    let (run, sim) = (sb.trace("run"), sb.trace("sim"));
    assert_eq!(signal_columns(&run), signal_columns(&sim));
    let s = sb.json("run", "summary.json");
    let held = util::num(&s["master"]["counters"]["held_samples"]);
    assert!(
        held > 1000.0,
        "{held} samples dropped of 20,000 at 5 % each way"
    );
}

#[test]
fn slave_killed_the_master_zeroes_torque_and_resumes_after_restart() {
    peer_dies_and_the_loop_resumes("slave");
}

#[test]
fn emulator_killed_the_master_zeroes_torque_and_resumes_after_restart() {
    peer_dies_and_the_loop_resumes("emulator");
}

#[test]
fn master_killed_the_slave_holds_and_the_launcher_fails_cleanly() {
    let sb = Sandbox::new("master");
    let scenario = sb.write("s.toml", &util::paper_1khz(5000));
    let child = sb.spawn_run(&scenario, "run", &[]);
    kill_mid_run(&sb, "run", "master", 1_500);
    let (code, stderr) = finish(child);
    sb.assert_no_leftover_processes();
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("master was killed by signal 9"), "{stderr}");
    // The report is written from the records even though the master died.
    let s = sb.json("run", "summary.json");
    assert!(s["nodes"]["master"]["ended"]
        .as_str()
        .is_some_and(|e| e.contains("killed")));
    let c = &s["slave"]["counters"];
    assert!(util::num(&c["holds"]) >= 1.0, "{c}");
    assert!(util::num(&c["held_steps"]) > 10.0, "{c}");
    // Holding means staying put: under a millimetre of drift.
    assert!(util::num(&c["hold_drift_max_m"]) < 0.001, "{c}");
}

#[test]
fn sigterm_to_the_launcher_stops_everything_and_writes_the_report() {
    let sb = Sandbox::new("sigterm");
    let scenario = sb.write("s.toml", &util::paper_1khz(20_000));
    let child = sb.spawn_run(&scenario, "run", &[]);
    // Once the loop has run for a while (its slave has recorded a second).
    let rec = sb.path("run").join("slave.rec");
    util::wait_for_rows(&rec, 1_000, Duration::from_secs(20));
    kill(child.id() as i32, rustix::process::Signal::TERM);
    let (code, stderr) = finish(child);
    sb.assert_no_leftover_processes();
    assert_eq!(code, Some(130), "{stderr}");
    let s = sb.json("run", "summary.json");
    assert_eq!(s["interrupted"], true);
    let sent = s["samples_sent"].as_u64().expect("sent");
    assert!(sent > 100 && sent < 20_000, "sent {sent}");
    assert!(util::num(&s["round_trip_ns"]["count"]) > 100.0);
    assert!(sb.path("run").join("trace.csv").exists());
}

#[test]
fn a_new_run_after_a_crash_starts_cleanly() {
    let sb = Sandbox::new("crash");
    let scenario = sb.write("s.toml", &util::paper_1khz(20_000));
    let child = sb.spawn_run(&scenario, "first", &[]);
    kill_mid_run(&sb, "first", "master", 500);
    // Kill the launcher first, so nobody cleans up, then every process of the run.
    let launcher = child.id() as i32;
    let (m, e, s) = (
        pid_of(&sb.prefix, "master"),
        pid_of(&sb.prefix, "emulator"),
        pid_of(&sb.prefix, "slave"),
    );
    kill(launcher, rustix::process::Signal::KILL);
    for pid in [m, e, s].into_iter().flatten() {
        kill(pid, rustix::process::Signal::KILL);
    }
    let _ = finish(child);
    util::wait_for("the killed nodes are gone", Duration::from_secs(10), || {
        ["master", "emulator", "slave"]
            .iter()
            .all(|r| pid_of(&sb.prefix, r).is_none())
    });
    sb.assert_no_leftover_processes();
    // Stale shared memory of the crashed run is still there; the same prefix must work.
    let again = sb.write("again.toml", &util::paper_1khz(500));
    sb.run(&again, "second");
    let s = sb.json("second", "summary.json");
    assert_eq!(s["samples_received"], 500);
    assert_eq!(s["failed"], false);
}

#[test]
fn a_full_subscriber_buffer_loses_exactly_the_overwritten_samples() {
    let sb = Sandbox::new("overflow");
    let _lock = tactile_runtime::lock::take(&sb.prefix, "run", "this test").expect("lock");
    let node = std::rc::Rc::new(ipc::node(&sb.prefix, "test").expect("node"));
    let mut out = IpcPublisher::<Forward>::open(&node, "overflow", "nobody").expect("outbox");
    let mut inbox = IpcSubscriber::<Forward>::open(&node, "overflow").expect("inbox");
    let total = 200u64;
    for n in 0..total {
        let f = Forward {
            seq: n,
            ..Forward::default()
        };
        out.publish(&f, false).expect("send");
    }
    // Every publish reached the one subscriber.
    assert_eq!(out.stats().no_receiver, 0);
    let mut got = Vec::new();
    while let Some(f) = inbox.try_recv().expect("recv") {
        got.push(f.seq);
    }
    let buffer = ipc::SUBSCRIBER_BUFFER as u64;
    // Safe overflow keeps the newest samples.
    assert_eq!(got, (total - buffer..total).collect::<Vec<_>>());
    let st = inbox.stats();
    assert_eq!(st.received, buffer);
    // The first sample taken has nothing before it to compare with; from there on
    // every gap is counted.
    assert_eq!(st.overwritten, 0);
    // Now a second burst with the receiver established: every overwrite is counted.
    for n in total..total + 100 {
        let f = Forward {
            seq: n,
            ..Forward::default()
        };
        out.publish(&f, false).expect("send");
    }
    while inbox.try_recv().expect("recv").is_some() {}
    let st = inbox.stats();
    assert_eq!(st.received, 2 * buffer);
    assert_eq!(st.overwritten, 100 - buffer);
    assert_eq!(out.stats().published, total + 100);
    assert_eq!(out.stats().no_receiver, 0);
}

#[test]
fn corrupted_samples_never_reach_a_torque() {
    let sb = Sandbox::new("corrupt");
    let text = tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace("[network.forward]\n", "[network.forward]\ncorrupt = 0.05\n")
        .replace(
            "[network.backward]\n",
            "[network.backward]\ncorrupt = 0.05\n",
        );
    let scenario = sb.write("s.toml", &text);
    sb.run(&scenario, "run");
    let s = sb.json("run", "summary.json");
    let e = &s["emulator"]["counters"];
    let f_bad = e["forward_corrupted"].as_u64().expect("count");
    let b_bad = e["backward_corrupted"].as_u64().expect("count");
    assert!(f_bad > 20 && b_bad > 20, "{e}");
    assert_eq!(s["slave"]["counters"]["rejected"].as_u64(), Some(f_bad));
    assert_eq!(s["master"]["counters"]["rejected"].as_u64(), Some(b_bad));
    let trace = sb.trace("run");
    for col in [
        "tau_1",
        "tau_2",
        "tau_3",
        "u_1",
        "u_2",
        "u_3",
        "felt_1",
        "theta_sd_1",
    ] {
        assert!(column(&trace, col).iter().all(|v| v.is_finite()), "{col}");
    }
}

#[test]
fn dropped_samples_are_counted_and_every_stream_reconciles() {
    let sb = Sandbox::new("loss");
    let text = util::paper_1khz(3000)
        .replace("[network.forward]\n", "[network.forward]\nloss = 0.03\n")
        .replace("[network.backward]\n", "[network.backward]\nloss = 0.02\n");
    let scenario = sb.write("s.toml", &text);
    sb.run(&scenario, "run");
    let s = sb.json("run", "summary.json");
    let e = &s["emulator"]["counters"];
    let channels = &s["channels"];
    assert_eq!(channels["v"]["lost_dropped"], e["forward_dropped"]);
    assert_eq!(channels["q"]["lost_dropped"], e["backward_dropped"]);
    assert!(util::num(&e["forward_dropped"]) > 30.0);
    for stream in ["c", "v", "h", "q"] {
        let c = &channels[stream];
        let get = |k: &str| c[k].as_u64().expect("count");
        assert_eq!(
            get("offered"),
            get("received") + get("lost"),
            "{stream}: {c}"
        );
        assert_eq!(
            get("lost"),
            get("lost_dropped") + get("lost_overwritten") + get("lost_dead_peer"),
            "{stream}: {c}"
        );
        assert_eq!(get("lost_dead_peer"), 0, "{stream}: {c}");
        assert_eq!(get("lost_overwritten"), 0, "{stream}: {c}");
    }
    // End to end: a sample lost on either stream never comes back.
    let dropped =
        e["forward_dropped"].as_u64().expect("n") + e["backward_dropped"].as_u64().expect("n");
    assert_eq!(s["samples_lost"].as_u64(), Some(dropped));
}

#[test]
fn forces_and_torques_are_clamped_to_the_device_limits() {
    let sb = Sandbox::new("clamp");
    // A stiff wall (above the Omni's nominal 700 N/m: loads with a warning) that the
    // tool is driven deep into.
    let text = tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace(
            "stiffness = [300.0, 300.0, 300.0]",
            "stiffness = [3000.0, 3000.0, 3000.0]",
        )
        .replace("point = [0.0, 0.0, -0.16]", "point = [0.0, 0.0, -0.14]")
        .replace(
            "[slave.controller]\nkp = [6.0, 6.0, 6.0]",
            "[slave.controller]\nkp = [40.0, 40.0, 40.0]",
        );
    let scenario = sb.write("s.toml", &text);
    let o = sb.run(&scenario, "run");
    assert!(String::from_utf8_lossy(&o.stderr).contains("warning"));
    let s = sb.json("run", "summary.json");
    assert!(
        util::num(&s["master"]["motion"]["force_max_n"]) > 3.3,
        "{}",
        s["master"]["motion"]
    );
    assert!(util::num(&s["master"]["counters"]["force_clamps"]) > 0.0);
    let trace = sb.trace("run");
    for j in 1..=3 {
        assert!(column(&trace, &format!("felt_{j}"))
            .iter()
            .all(|f| f.abs() <= 3.3));
        assert!(column(&trace, &format!("tau_{j}"))
            .iter()
            .all(|t| t.abs() <= 0.45));
        assert!(column(&trace, &format!("u_{j}"))
            .iter()
            .all(|t| t.abs() <= 0.45));
    }
}

/// Unmounts a test's file system when the test ends, however it ends.
struct Unmount(std::path::PathBuf);

impl Drop for Unmount {
    fn drop(&mut self) {
        let _ = std::process::Command::new("umount")
            .arg("-l")
            .arg(&self.0)
            .status();
    }
}

/// Disk full in processes mode: the nodes died writing their records, and the
/// launcher said only "writing trace.csv: No space left on device". It names each
/// node's failure (how it ended, its log's last words) before its own error.
#[test]
fn a_full_disk_names_the_nodes_that_died_of_it() {
    if !rustix::process::geteuid().is_root() {
        cannot("a small tmpfs for the run's folder needs root");
        return;
    }
    let sb = Sandbox::new("diskfull");
    let scenario = sb.write("s.toml", &util::paper_1khz(20_000));
    let disk = sb.path("disk");
    std::fs::create_dir_all(&disk).expect("folder");
    let mounted = std::process::Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=600k", "tmpfs"])
        .arg(&disk)
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        cannot("mount -t tmpfs was refused");
        return;
    }
    let _unmount = Unmount(disk.clone());
    let child = sb.spawn_run(&scenario, disk.join("run"), &["--max-restarts", "0"]);
    let (code, err) = finish(child);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("No space left on device"), "{err}");
    assert!(
        err.contains(" exited with status 1 after ") && err.contains("its last words"),
        "each node's failure is named: {err}"
    );
    sb.assert_no_leftover_processes();
}
