//! Real-time scheduling set by the nodes themselves: SCHED_FIFO where permitted, the
//! margins and CPUs recorded in the summary, a clean fallback where the kernel
//! refuses, and SCHED_OTHER for lockstep (whose loop never sleeps).

use crate::util;

use util::Sandbox;

fn is_root() -> bool {
    rustix::process::geteuid().is_root()
}

fn run_args<'a>(sb: &'a Sandbox, scenario: &'a str, out: &'a str) -> Vec<&'a str> {
    vec!["run", scenario, "--out", out, "--prefix", &sb.prefix, "-q"]
}

/// `tactile run` of the scenario `text` into the folder `out` with `extra` arguments;
/// it must succeed. Returns its stdout and the summary.
fn run(sb: &Sandbox, text: &str, extra: &[&str]) -> (String, serde_json::Value) {
    let s = sb.write("s.toml", text);
    let out = sb.path("out");
    let mut args = run_args(sb, s.to_str().expect("utf-8"), out.to_str().expect("utf-8"));
    args.extend(extra);
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        sb.json("out", "summary.json"),
    )
}

#[test]
fn realtime_nodes_run_sched_fifo_and_the_summary_says_how() {
    if !util::fifo_permitted() {
        util::cannot("SCHED_FIFO is not permitted here");
        return;
    }
    let sb = Sandbox::new("fifo");
    let (text, sum) = run(&sb, &util::paper_1khz(1500), &[]);
    assert_eq!(sum["samples_lost"], 0);
    for (role, cpu) in [("master", 0), ("emulator", 1), ("slave", 1)] {
        let s = &sum["nodes"][role]["sched"];
        assert_eq!(s["policy"], "SCHED_FIFO", "{role}: {s}");
        assert_eq!(s["priority"], 70, "{role}: {s}");
        assert_eq!(s["wake_early_us"], 200, "{role}: {s}");
        assert_eq!(s["poll_us"], 400, "{role}: {s}");
        assert_eq!(s["memory_locked"], true, "{role}: {s}");
        assert_eq!(s["idle_poll"], false, "{role}: {s}");
        assert!(s["note"].is_null(), "{role}: {s}");
        if tactile_launch::two_cpus() {
            assert_eq!(s["cpu"], cpu, "{role}: {s}");
        }
    }
    assert!(text.contains("SCHED_FIFO 70"), "{text}");
    assert!(!text.contains("kept awake"), "{text}");
    // The percentile plot is written beside the histograms.
    let svg = std::fs::read_to_string(sb.path("out").join("percentiles.svg")).expect("svg");
    assert!(svg.contains("99.9%"), "percentile axis");
    sb.assert_no_leftover_processes();
}

#[test]
fn where_sched_fifo_is_refused_the_nodes_run_sched_other_and_say_so() {
    // Root without CAP_SYS_NICE and CAP_IPC_LOCK (dropped from the bounding set, so
    // no program it starts gets them back) is refused SCHED_FIFO like any user.
    let setpriv = std::path::Path::new("/usr/bin/setpriv");
    if !is_root() || !setpriv.exists() {
        util::cannot("taking SCHED_FIFO away needs root and /usr/bin/setpriv");
        return;
    }
    let sb = Sandbox::new("nofifo");
    let s = sb.write("s.toml", &util::paper_1khz(1000));
    let out = sb.path("out");
    let mut c = std::process::Command::new(setpriv);
    c.args([
        "--bounding-set",
        "-sys_nice,-ipc_lock",
        "--inh-caps",
        "-sys_nice,-ipc_lock",
        env!("CARGO_BIN_EXE_tactile"),
    ])
    .args(run_args(
        &sb,
        s.to_str().expect("utf-8"),
        out.to_str().expect("utf-8"),
    ))
    .args(["--idle", "poll"])
    .current_dir(sb.dir.path())
    .env("TACTILE_NODE_DIR", util::node_dir());
    let o = c.output().expect("setpriv");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let sum = sb.json("out", "summary.json");
    assert_eq!(sum["samples_lost"], 0, "the run goes on without SCHED_FIFO");
    for role in ["master", "emulator", "slave"] {
        let s = &sum["nodes"][role]["sched"];
        assert_eq!(s["policy"], "SCHED_OTHER", "{role}: {s}");
        assert_eq!(s["priority"], 0, "{role}: {s}");
        // Asked for, but a SCHED_OTHER node that yields would hand its CPU to the
        // idle-poll thread: not started.
        assert_eq!(s["idle_poll"], false, "{role}: {s}");
        let note = s["note"].as_str().unwrap_or_default();
        assert!(note.contains("SCHED_FIFO not permitted"), "{role}: {s}");
    }
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("SCHED_FIFO not permitted"), "{text}");
    sb.assert_no_leftover_processes();
}

#[test]
fn lockstep_runs_sched_other_whatever_is_asked() {
    let sb = Sandbox::new("lockrt");
    let text = tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace("samples = 1200", "samples = 300");
    let (_, sum) = run(&sb, &text, &["--sched", "fifo", "--idle", "poll"]);
    for role in ["master", "emulator", "slave"] {
        let s = &sum["nodes"][role]["sched"];
        assert_eq!(s["policy"], "SCHED_OTHER", "{role}: {s}");
        assert_eq!(s["wake_early_us"], 0, "{role}: {s}");
        assert_eq!(s["priority"], 0, "{role}: {s}");
        assert_eq!(s["idle_poll"], false, "{role}: {s}");
    }
}

#[test]
fn idle_poll_keeps_the_cpus_awake_and_the_summary_says_so() {
    if !util::fifo_permitted() {
        util::cannot("SCHED_FIFO is not permitted here");
        return;
    }
    let sb = Sandbox::new("awake");
    let (text, sum) = run(&sb, &util::paper_1khz(1000), &["--idle", "poll"]);
    for role in ["master", "emulator", "slave"] {
        let s = &sum["nodes"][role]["sched"];
        assert_eq!(s["policy"], "SCHED_FIFO", "{role}: {s}");
        assert_eq!(s["idle_poll"], true, "{role}: {s}");
        assert!(s["note"].is_null(), "{role}: {s}");
    }
    assert!(text.contains("CPU kept awake"), "{text}");
    sb.assert_no_leftover_processes();
}
