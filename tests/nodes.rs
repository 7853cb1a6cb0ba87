//! The node programs as a user runs them: started by hand in any order, each writing
//! its own record, joined by `tactile report`; killed mid-run; long runs in bounded
//! memory; and what a launcher does when it dies.

use crate::util;

use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};
use tactile_report::trace::signal_columns;
use util::{column, finish, kill_once_recorded, pid_of, start_node, Sandbox};

/// The paper scenario in lockstep with a noisy, delayed network.
fn lockstep(samples: u64) -> String {
    tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace("samples = 1200", &format!("samples = {samples}"))
        .replace(
            "[network.forward]\ndelay = [0, 0, 0]\nnoise_std = [0.0, 0.0, 0.0]",
            "[network.forward]\ndelay = [2, 3, 1]\nnoise_std = [0.0005, 0.001, 0.0]",
        )
}

fn report(sb: &Sandbox, dirs: &[&str], out: &str) -> std::process::Output {
    let out = sb.path(out);
    let mut args = vec!["report"];
    args.extend_from_slice(dirs);
    args.extend(["--out", out.to_str().expect("utf-8")]);
    sb.tactile(&args)
}

#[test]
fn hand_started_nodes_in_any_order_match_tactile_run_and_the_simulation() {
    let sb = Sandbox::new("byhand");
    let scenario = sb.write("s.toml", &lockstep(1200));
    // Slave first, then the master (which waits for its peers), then the emulator.
    let waits = |role: &str, what: &str| {
        let log = sb.path(&format!("h-{role}")).join(format!("{role}.log"));
        let what = what.to_string();
        util::wait_for(
            &format!("the {role} waits"),
            Duration::from_secs(20),
            move || std::fs::read_to_string(&log).is_ok_and(|l| l.contains(&what)),
        );
    };
    let slave = start_node(&sb, "slave", &scenario, "h-slave", &[]);
    waits("slave", "waiting for the master");
    let master = start_node(&sb, "master", &scenario, "h-master", &[]);
    waits("master", "waiting for the emulator and slave");
    let emulator = start_node(&sb, "emulator", &scenario, "h-emulator", &[]);
    for (name, child) in [("master", master), ("emulator", emulator), ("slave", slave)] {
        let (code, err) = finish(child);
        assert_eq!(code, Some(0), "{name}: {err}");
    }
    // The last node to end removed the run's shared memory and iceoryx2 files.
    let shm = format!("{}.", sb.prefix);
    let left: Vec<String> = std::fs::read_dir("/dev/shm")
        .expect("/dev/shm")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&shm))
        .collect();
    assert!(left.is_empty(), "left in /dev/shm: {left:?}");
    let iox = std::path::Path::new(tactile_transport::ipc::ROOT).join(&sb.prefix);
    assert!(!iox.exists(), "{} left", iox.display());
    // Each node wrote its own record and log into its own folder.
    for role in ["master", "emulator", "slave"] {
        let dir = sb.path(&format!("h-{role}"));
        assert!(dir.join(format!("{role}.rec")).is_file(), "{role}");
        let log = std::fs::read_to_string(dir.join(format!("{role}.log"))).expect("log");
        assert!(
            log.contains("start:") && log.contains("stop: completed"),
            "{role}:\n{log}"
        );
    }
    let o = report(&sb, &["h-master", "h-emulator", "h-slave"], "joined");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    sb.run(&scenario, "launched");
    sb.simulate(&scenario, "sim");
    let joined = signal_columns(&sb.trace("joined"));
    assert_eq!(joined.lines().count(), 1201);
    assert_eq!(
        joined,
        signal_columns(&sb.trace("launched")),
        "by hand vs tactile run"
    );
    assert_eq!(
        joined,
        signal_columns(&sb.trace("sim")),
        "by hand vs in-process"
    );
    // The same summary: counts, accounting and motion (latencies differ run to run).
    let a = sb.json("joined", "summary.json");
    let b = sb.json("launched", "summary.json");
    for key in [
        "samples_sent",
        "samples_received",
        "samples_lost",
        "tracking_rms_m",
        "channels",
    ] {
        assert_eq!(a[key], b[key], "{key}");
    }
    assert_eq!(a["master"]["motion"], b["master"]["motion"]);
    assert_eq!(a["slave"]["counters"], b["slave"]["counters"]);
    assert_eq!(a["emulator"]["counters"], b["emulator"]["counters"]);
    for role in ["master", "emulator", "slave"] {
        let n = &a["nodes"][role];
        assert!(
            n["ended"].as_str().expect("ended").starts_with("completed"),
            "{n}"
        );
        assert!(util::num(&n["peak_rss_kb"]) > 0.0, "{n}");
    }
    sb.assert_no_leftover_processes();
}

#[test]
fn a_killed_slave_leaves_every_sample_it_took_in_its_record() {
    let sb = Sandbox::new("slavekill");
    let scenario = sb.write("s.toml", &util::paper_1khz(3000));
    let master = start_node(&sb, "master", &scenario, "m", &[]);
    let emulator = start_node(&sb, "emulator", &scenario, "e", &[]);
    let slave = start_node(&sb, "slave", &scenario, "s", &[]);
    // Kill the slave (SIGKILL: no chance to flush anything) once it is well under way.
    kill_once_recorded(slave, &sb.path("s").join("slave.rec"), 300);
    // The master breaks, runs to its end with zero torque; the emulator follows it.
    let (code, err) = finish(master);
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = finish(emulator);
    assert_eq!(code, Some(0), "{err}");
    let o = report(&sb, &["m", "e", "s"], "report");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = sb.json("report", "summary.json");
    let node = &s["nodes"]["slave"];
    let last = node["last_sample"]
        .as_u64()
        .expect("the slave recorded samples");
    let ended = node["ended"].as_str().expect("ended");
    assert!(
        ended.contains(&format!("after sample {last}")) && ended.contains("killed"),
        "{ended}"
    );
    // Every sample up to the last block the slave wrote is in its record (v(n)
    // recorded: the paper path's z is never 0), none after it; the master got answers
    // for at most a block's steps more (50 samples, 50 ms at 1 kHz: the block the kill
    // took with it).
    let trace = sb.trace("report");
    let v3 = column(&trace, "v_3");
    let received = column(&trace, "received");
    let last = usize::try_from(last).expect("index");
    assert!(last > 50 && last < 2900, "killed at {last}");
    assert!(
        v3[..=last].iter().all(|v| *v != 0.0),
        "a gap in the slave's record"
    );
    assert!(v3[last + 1..].iter().all(|v| *v == 0.0));
    let unrecorded = received[last + 1..].iter().filter(|r| **r != 0.0).count();
    assert!(unrecorded <= 50, "{unrecorded} answered steps not recorded");
    assert_eq!(node["unjoined"], 0);
    assert!(util::num(&s["master"]["counters"]["loop_breaks"]) >= 1.0);
    sb.assert_no_leftover_processes();
}

#[test]
fn a_long_run_keeps_every_node_in_bounded_memory() {
    // The same run at 2,000 and 50,000 samples: a node that kept even 100 bytes per
    // sample would grow by 4.8 MB between them, a trace row per sample (the old
    // master) by about 45 MB. Each node's peak at 50,000 may exceed its peak at 2,000
    // by 2 MB (allocator slack), and stays under 24 MB in absolute terms. (10^4 and
    // 10^5 took 131 s of CI's suite.)
    let sb = Sandbox::new("longrun");
    let peaks = |samples: u64, name: &str| -> Vec<u64> {
        let scenario = sb.write(&format!("{name}.toml"), &lockstep(samples));
        let out = sb.path(name);
        let o = sb.tactile(&[
            "run",
            scenario.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
            "--prefix",
            &sb.prefix,
            "--no-trace",
            "-q",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let s = sb.json(name, "summary.json");
        assert_eq!(util::num(&s["samples_received"]), samples as f64);
        assert!(!out.join("trace.csv").exists());
        ["master", "emulator", "slave"]
            .map(|role| s["nodes"][role]["peak_rss_kb"].as_u64().expect("rss"))
            .to_vec()
    };
    let short = peaks(2_000, "short");
    let long = peaks(50_000, "long");
    for (k, role) in ["master", "emulator", "slave"].iter().enumerate() {
        let (a, b) = (short[k], long[k]);
        assert!(b > 1000 && b < 24 * 1024, "{role}: peak RSS {b} kB");
        assert!(
            b <= a + 2048,
            "{role}: peak RSS {a} kB at 2,000 samples, {b} kB at 50,000"
        );
    }
    // The plots are thinned to the pixel width: small whatever the length.
    for plot in ["positions.svg", "forces.svg"] {
        let size = std::fs::metadata(sb.path("long").join(plot))
            .expect("plot")
            .len();
        assert!(size < 600_000, "{plot}: {size} bytes");
    }
    sb.assert_no_leftover_processes();
}

#[test]
fn nodes_stop_within_a_second_when_the_launcher_is_killed() {
    let sb = Sandbox::new("orphans");
    let scenario = sb.write("s.toml", &util::paper_1khz(60_000));
    let mut launcher = sb.spawn_run(&scenario, "run", &[]);
    // The loop runs (its samples reach the slave's record), so every node is past its
    // start-up when the launcher dies.
    util::wait_for_rows(
        &sb.path("run").join("slave.rec"),
        200,
        Duration::from_secs(20),
    );
    launcher.kill().expect("SIGKILL the launcher");
    let _ = launcher.wait();
    let killed = Instant::now();
    while ["master", "emulator", "slave"]
        .iter()
        .any(|r| pid_of(&sb.prefix, r).is_some())
    {
        assert!(
            killed.elapsed() < Duration::from_secs(1),
            "nodes still running {:?} after the launcher died",
            killed.elapsed()
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    // They stopped cleanly: each record ends with a stop, readable by the report.
    let o = report(&sb, &["run"], "report");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = sb.json("report", "summary.json");
    for role in ["master", "emulator", "slave"] {
        let ended = s["nodes"][role]["ended"]
            .as_str()
            .expect("ended")
            .to_string();
        assert!(ended.starts_with("interrupted"), "{role}: {ended}");
    }
}

#[test]
fn a_prefix_in_use_is_refused_and_names_its_holder() {
    let sb = Sandbox::new("prefix");
    let scenario = sb.write("s.toml", &util::paper_1khz(1000));
    // A slave started by hand holds the prefix.
    let slave = start_node(&sb, "slave", &scenario, "hand", &[]);
    util::wait_for(
        "the hand slave holds its lock",
        Duration::from_secs(10),
        || tactile_runtime::lock::in_use(&sb.prefix).is_err(),
    );
    // A second slave by hand is refused before it starts.
    let o = sb
        .node(
            "tactile-slave",
            &[
                "--scenario",
                "s.toml",
                "--out",
                "second",
                "--prefix",
                &sb.prefix,
            ],
        )
        .output()
        .expect("start");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("in use") && err.contains(&format!("pid {}", slave.id())),
        "{err}"
    );
    assert!(!sb.path("second").join("slave.rec").exists());
    // A launcher on the same prefix is refused before it starts or writes anything,
    // and the hand run it would have disturbed completes.
    let master = start_node(&sb, "master", &scenario, "hand-m", &[]);
    let emulator = start_node(&sb, "emulator", &scenario, "hand-e", &[]);
    let o = sb.tactile(&[
        "run", "s.toml", "--out", "run", "--prefix", &sb.prefix, "-q",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("in use") && err.contains("pid"), "{err}");
    assert!(
        !sb.path("run").exists(),
        "the refused launcher wrote nothing"
    );
    for (role, child) in [("master", master), ("emulator", emulator), ("slave", slave)] {
        let (code, err) = finish(child);
        assert_eq!(code, Some(0), "the hand {role} completes: {err}");
    }
    sb.assert_no_leftover_processes();
    // Two launchers: the second refuses and names the first.
    let mut first = sb
        .command(&[
            "run", "s.toml", "--out", "first", "--prefix", &sb.prefix, "-q",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start");
    util::wait_for("the first run's master", Duration::from_secs(20), || {
        pid_of(&sb.prefix, "master").is_some()
    });
    let o = sb.tactile(&[
        "run",
        "s.toml",
        "--out",
        "second-run",
        "--prefix",
        &sb.prefix,
        "-q",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("tactile run (pid {},", first.id())),
        "{err}"
    );
    assert!(first.wait().expect("wait").success());
    sb.assert_no_leftover_processes();
}

#[test]
fn bad_prefixes_are_refused_before_anything_starts() {
    let sb = Sandbox::new("badprefix");
    let scenario = sb.write("s.toml", &util::paper_1khz(100));
    let long = "p".repeat(25);
    for bad in ["a/b", "../x", "-x", "a b", long.as_str()] {
        let prefix = format!("--prefix={bad}");
        let o = sb.tactile(&[
            "run",
            scenario.to_str().expect("utf-8"),
            "--out",
            "out",
            &prefix,
            "-q",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--prefix"), "{bad}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!sb.path("out").join("scenario.toml").exists(), "{bad}");
    }
}

#[test]
fn the_longest_prefix_allowed_runs_over_iceoryx2() {
    // Iceoryx2's event sockets hold the prefix twice in a path of at most 108 bytes:
    // the longest prefix accepted must still open them.
    let sb = Sandbox::new("longpfx");
    let scenario = sb.write("s.toml", &lockstep(50));
    let prefix = format!("{}{}", sb.prefix, "x".repeat(24 - sb.prefix.len()));
    let o = sb.tactile(&[
        "run",
        scenario.to_str().expect("utf-8"),
        "--out",
        "run",
        "--prefix",
        &prefix,
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(sb.json("run", "summary.json")["samples_received"], 50);
    tactile_transport::ipc::remove_run_files(&prefix);
}

#[test]
fn relative_paths_and_the_copied_scenario_work_in_every_mode() {
    let sb = Sandbox::new("paths");
    std::fs::create_dir(sb.path("sub")).expect("mkdir");
    sb.write(
        "sub/traj.csv",
        "x,y,z\n0.05,0.02,-0.12\n0.06,0.02,-0.12\n0.07,0.03,-0.11\n",
    );
    let text = lockstep(300).replace(
        "[operator]\nkind = \"paper\"",
        "[operator]\nkind = \"csv\"\npath = \"traj.csv\"",
    );
    let scenario = sb.write("sub/s.toml", &text);
    // From the sandbox, the scenario one folder down: processes and in-process.
    sb.run(&scenario, "a");
    sb.simulate(&scenario, "b");
    assert_eq!(
        signal_columns(&sb.trace("a")),
        signal_columns(&sb.trace("b"))
    );
    // The copy in the output folder runs again as it is, from another folder.
    let copy = sb.path("a").join("scenario.toml");
    std::fs::create_dir(sb.path("elsewhere")).expect("mkdir");
    let o = sb
        .command(&[
            "run",
            copy.to_str().expect("utf-8"),
            "--out",
            "again",
            "--prefix",
            &sb.prefix,
            "-q",
        ])
        .current_dir(sb.path("elsewhere"))
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let again = std::fs::read_to_string(sb.path("elsewhere/again/trace.csv")).expect("trace");
    assert_eq!(signal_columns(&again), signal_columns(&sb.trace("a")));
}

#[test]
fn a_run_never_overwrites_its_input_nor_mixes_two_runs_in_a_folder() {
    let sb = Sandbox::new("inputs");
    let scenario = sb.write("s.toml", &lockstep(200));
    sb.run(&scenario, "out");
    // Running the copy in the output folder into the same folder would overwrite it.
    let copy = sb.path("out").join("scenario.toml");
    let before = std::fs::read(&copy).expect("read");
    let o = sb.tactile(&["run", copy.to_str().expect("utf-8"), "--out", "out", "-q"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("overwrite"), "{err}");
    assert_eq!(std::fs::read(&copy).expect("read"), before);
    // A second run in the same folder leaves none of the first run's files: the
    // in-process run writes no logs, so the first run's logs must be gone.
    assert!(sb.path("out").join("master.log").exists());
    sb.simulate(&scenario, "out");
    for role in ["master", "emulator", "slave"] {
        assert!(
            !sb.path("out").join(format!("{role}.log")).exists(),
            "{role}.log"
        );
    }
    // Records of two runs are never joined.
    sb.run(&scenario, "other");
    let o = report(&sb, &["out", "other"], "mixed");
    assert_eq!(o.status.code(), Some(2));
    std::fs::remove_file(sb.path("other").join("master.rec")).expect("rm");
    let o = report(&sb, &["out", "other"], "mixed");
    assert_eq!(o.status.code(), Some(2), "two slave records");
    std::fs::create_dir(sb.path("x")).expect("mkdir");
    std::fs::rename(
        sb.path("other").join("slave.rec"),
        sb.path("x").join("slave.rec"),
    )
    .expect("mv");
    std::fs::remove_file(sb.path("out").join("slave.rec")).expect("rm");
    let o = report(&sb, &["out", "x"], "mixed");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("not one run"), "{err}");
}

#[test]
fn statistics_say_na_when_nothing_came_back() {
    let sb = Sandbox::new("nothing");
    let text =
        util::paper_1khz(300).replace("[network.backward]\n", "[network.backward]\nloss = 1.0\n");
    let scenario = sb.write("s.toml", &text);
    let o = sb.tactile(&[
        "run",
        scenario.to_str().expect("utf-8"),
        "--out",
        "run",
        "--prefix",
        &sb.prefix,
        "-q",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = sb.json("run", "summary.json");
    assert_eq!(s["samples_received"], 0);
    assert!(
        s["round_trip_ns"].is_null() && s["overhead_ns"].is_null(),
        "{s}"
    );
    assert!(s["master"]["motion"]["felt_rms_n"].is_null());
    let line = stdout
        .lines()
        .find(|l| l.starts_with("round trip"))
        .expect("line");
    assert!(line.contains("n/a"), "{line}");
    // The slave did follow: its tracking is measured against what it was sent.
    assert!(
        s["tracking_rms_m"].as_f64().is_some_and(|t| t < 0.01),
        "{}",
        s["tracking_rms_m"]
    );
}

#[test]
fn unreadable_and_absurd_input_files_are_refused() {
    let sb = Sandbox::new("files");
    std::fs::create_dir(sb.path("folder.toml")).expect("mkdir");
    let big = sb.path("big.toml");
    let f = std::fs::File::create(&big).expect("create");
    f.set_len(2 << 20).expect("grow");
    for (scenario, want) in [
        ("folder.toml", "is a folder"),
        ("/dev/zero", "not a regular file"),
        ("big.toml", "more than"),
    ] {
        let o = sb.tactile(&["run", scenario, "--out", "out", "-q"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{scenario}: {err}");
        assert!(
            err.contains(want) && err.lines().count() == 1,
            "{scenario}: {err}"
        );
        assert!(!sb.path("out").exists());
    }
    // A trajectory that is a device or absurdly large.
    let csv = sb.path("huge.csv");
    std::fs::File::create(&csv)
        .expect("create")
        .set_len(200 << 20)
        .expect("grow");
    for path in ["/dev/zero", "huge.csv"] {
        let text = lockstep(10).replace(
            "[operator]\nkind = \"paper\"",
            &format!("[operator]\nkind = \"csv\"\npath = \"{path}\""),
        );
        let s = sb.write("t.toml", &text);
        let o = sb.tactile(&["run", s.to_str().expect("utf-8"), "--out", "out", "-q"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{path}: {err}");
        assert!(
            err.contains(path) && err.lines().count() == 1,
            "{path}: {err}"
        );
    }
    // A device file for the kernels that is not a regular file.
    let o = sb.tactile(&["kernels", "fk", "--device", "/dev/zero"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("not a regular file"), "{err}");
}

#[test]
fn a_run_leaves_nothing_behind_and_cleans_only_dead_runs() {
    let sb = Sandbox::new("leftover");
    let scenario = sb.write("s.toml", &lockstep(300));
    let root = Path::new(tactile_transport::ipc::ROOT);
    // A dead run's leftovers (a lock nobody holds, its iceoryx2 folder) and a live
    // run's (its lock held by this test).
    let dead = format!("{}d", sb.prefix);
    let live = format!("{}l", sb.prefix);
    for p in [&dead, &live] {
        std::fs::create_dir_all(root.join(p)).expect("folder");
        std::fs::write(root.join(p).join("node"), "x").expect("file");
    }
    let locks = tactile_runtime::lock::lock_dir();
    std::fs::create_dir_all(&locks).expect("locks");
    let dead_lock = locks.join(format!("{dead}.slave.lock"));
    std::fs::write(&dead_lock, "a killed slave").expect("lock");
    let held = tactile_runtime::lock::take(&live, "slave", "a live slave").expect("take");
    sb.run(&scenario, "out");
    let mine: Vec<String> = std::fs::read_dir(&locks)
        .expect("locks")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&format!("{}.", sb.prefix)))
        .collect();
    assert!(mine.is_empty(), "the run's locks are gone: {mine:?}");
    assert!(
        !root.join(&sb.prefix).exists(),
        "the run's iceoryx2 folder is gone"
    );
    let shm = std::fs::read_dir("/dev/shm")
        .expect("/dev/shm")
        .flatten()
        .any(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(&format!("{}.", sb.prefix))
        });
    assert!(!shm, "the run's shared memory is gone");
    assert!(
        !root.join(&dead).exists() && !dead_lock.exists(),
        "a dead run's are cleaned"
    );
    assert!(
        root.join(&live).join("node").exists(),
        "a live run's are kept"
    );
    assert!(held.path.exists());
    drop(held);
    tactile_transport::ipc::remove_run_files(&live);
}

/// `program` by hand into `out` with `link` options and the TLS files `[ca, cert, key]`.
fn with_tls(
    sb: &Sandbox,
    program: &str,
    scenario: &std::path::Path,
    link: &[&str],
    [ca, cert, key]: [&str; 3],
) -> std::process::Output {
    let mut args = vec!["--scenario", scenario.to_str().expect("utf-8")];
    args.extend(["--out", "out", "--prefix", &sb.prefix]);
    args.extend_from_slice(link);
    args.extend(["--tls-ca", ca, "--tls-cert", cert, "--tls-key", key]);
    util::output_within(sb.node(program, &args), util::LIMIT)
}

/// TLS options on a node whose link cannot carry them: refused (exit 2, nothing
/// written), never a run in clear that looks encrypted.
#[test]
fn tls_on_a_link_without_tls_is_refused() {
    let sb = Sandbox::new("tlsclear");
    let scenario = sb.write("s.toml", &util::paper_1khz(100));
    for f in ["ca.pem", "n.pem", "n.key"] {
        sb.write(
            f,
            "-----BEGIN CERTIFICATE-----\n-----END CERTIFICATE-----\n",
        );
    }
    for link in ["udp", "iceoryx2"] {
        let o = with_tls(
            &sb,
            "tactile-slave",
            &scenario,
            &["--link", link],
            ["ca.pem", "n.pem", "n.key"],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{link}: {err}");
        assert!(err.contains("would run in clear"), "{link}: {err}");
        assert!(!sb.path("out").join("slave.rec").exists(), "{link}");
    }
}

/// A node's own TLS files, each wrong in its own way: refused before anything starts
/// (exit 2), the message naming the file and the fault, never a wait with nothing said.
#[test]
fn a_nodes_own_bad_tls_files_are_named_and_refused() {
    let sb = Sandbox::new("tlsown");
    let ips = vec!["127.0.0.1".to_string()];
    let (run, other) = match (
        tactile_launch::pki::make(&sb.path("run"), "run", &ips),
        tactile_launch::pki::make(&sb.path("other"), "other", &ips),
    ) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => return util::cannot(&e.to_string()),
    };
    let garbled = sb.write(
        "garbled.pem",
        "-----BEGIN CERTIFICATE-----\nAAAA\n-----END CERTIFICATE-----\n",
    );
    let scenario = sb.write("s.toml", &util::paper_1khz(100));
    let path = |p: &std::path::Path| p.to_str().expect("utf-8").to_string();
    let cases = [
        ([path(&run[0]), path(&garbled), path(&run[2])], "--tls-cert"),
        (
            [path(&run[0]), path(&run[1]), path(&other[2])],
            "is not the key of --tls-cert",
        ),
        (
            [path(&run[0]), path(&other[1]), path(&other[2])],
            "is not valid under --tls-ca",
        ),
        ([path(&run[0]), path(&run[1]), path(&run[0])], "--tls-key"),
    ];
    for ([ca, cert, key], needle) in &cases {
        let zenoh = ["--link", "zenoh", "--listen", "tls/127.0.0.1:0"];
        let files = [ca.as_str(), cert.as_str(), key.as_str()];
        let o = with_tls(&sb, "tactile-master", &scenario, &zenoh, files);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{needle}: {err}");
        assert!(err.contains(needle), "{needle}: {err}");
        assert!(!sb.path("out").join("master.rec").exists(), "{needle}");
    }
}
