//! What the summary says, checked against what the run did: a lockstep run's round
//! trip in samples with the overhead n/a; the emulator's losses in the text.

use crate::util::{self, Sandbox};

#[test]
fn lockstep_reports_its_round_trip_in_samples_and_no_overhead() {
    let sb = Sandbox::new("lockstep-rt");
    // 25 samples each way at 1 kHz: 50 samples, 50 ms nominal.
    let s = sb.write(
        "s.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 400"),
    );
    let o = sb.tactile(&["run", s.to_str().expect("utf-8"), "--out", "out"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    assert!(
        text.contains("round trip (lockstep): 50 samples p50 (50.0 ms nominal)"),
        "{text}"
    );
    assert!(text.contains("system overhead: n/a (lockstep"), "{text}");
    assert!(
        !text.contains("\nround trip   "),
        "no wall-clock round trip row: {text}"
    );
    let j = sb.json("out", "summary.json");
    assert_eq!(j["round_trip_samples"]["p50"], 50);
    assert_eq!(j["round_trip_ms_nominal"], 50.0);
    assert!(j["overhead_ns"].is_null());
    assert!(j["overhead_na"]
        .as_str()
        .is_some_and(|w| w.starts_with("lockstep")));
    // In real time the overhead stays, and no nominal round trip is claimed.
    let rt = sb.write("rt.toml", &util::paper_1khz(300));
    let o = sb.tactile(&["run", rt.to_str().expect("utf-8"), "--out", "rt", "-q"]);
    assert!(o.status.success());
    let j = sb.json("rt", "summary.json");
    assert!(j["overhead_ns"]["p50"].is_u64());
    assert!(j["overhead_na"].is_null() && j["round_trip_ms_nominal"].is_null());
}

#[test]
fn the_text_says_what_the_network_lost() {
    let sb = Sandbox::new("replay-lost");
    // A replayed network that loses every third packet of 1200.
    let (s, _) = replayed(&sb, 1200, |k| (2, k % 3 == 0));
    let o = sb.tactile(&["run", s.to_str().expect("utf-8"), "--out", "out"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}");
    let j = sb.json("out", "summary.json");
    let lost = j["emulator"]["counters"]["forward_packets_lost"]
        .as_u64()
        .expect("count");
    assert_eq!(lost, 400, "every third of 1200");
    assert!(out.contains("network forward: 400 packets lost"), "{out}");
    assert!(out.contains("network backward: 0 packets lost"), "{out}");
}

#[test]
fn an_output_folder_holds_its_inputs_and_reruns_from_them() {
    let sb = Sandbox::new("bundle");
    let (s, csv) = replayed(&sb, 600, |k| (3 + k % 4, k % 11 == 0));
    let s = s.to_str().expect("utf-8");
    for (out, how) in [("proc", None), ("sim", Some("--in-process"))] {
        let mut args = vec!["run", s, "--out", out, "-q"];
        args.extend(how);
        let o = sb.tactile(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let copy = sb.path(out).join("inputs").join("net.csv");
        assert_eq!(std::fs::read_to_string(&copy).expect("copy"), csv, "{out}");
        let ran = std::fs::read_to_string(sb.path(out).join("scenario.toml")).expect("toml");
        assert!(ran.contains("path = \"inputs/net.csv\""), "{out}: {ran}");
    }
    // The original edited, the folder's scenario reruns what ran.
    sb.write("net.csv", "delay,lost\n9,0\n");
    let again = sb.path("sim").join("scenario.toml");
    let o = sb.tactile(&[
        "run",
        again.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        "again",
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let signals = |d: &str| tactile_report::trace::signal_columns(&sb.trace(d));
    assert_eq!(
        signals("again"),
        signals("sim"),
        "the rerun reads the copies"
    );
    // A folder's scenario never runs into that same folder (it would overwrite it).
    let into_itself = sb.path("again").join("scenario.toml");
    let o = sb.tactile(&[
        "run",
        into_itself.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        "again",
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn check_prints_the_scenario_as_it_would_run_and_what_it_writes() {
    let sb = Sandbox::new("check");
    let s = sb.write("s.toml", &util::wall_delay());
    let s = s.to_str().expect("utf-8");
    let o = sb.tactile(&["check", s, "--set", "samples=4000"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resolved = String::from_utf8(o.stdout).expect("utf-8");
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(
        said.contains("runs 4000 samples at 1000 Hz in lockstep: 4.0 s of simulated time"),
        "{said}"
    );
    assert!(
        said.contains("master.rec 248 kB") && said.contains("trace.csv 4.5 MB"),
        "{said}"
    );
    assert!(!said.contains("warning"), "{said}");
    // What it prints is the scenario, every default filled in: it runs as it is.
    let copy = sb.write("resolved.toml", &resolved);
    assert!(resolved.contains("samples = 4000") && resolved.contains("[slave.controller]"));
    let o = sb.tactile(&[
        "run",
        copy.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        "r",
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(sb.json("r", "summary.json")["samples_sent"], 4000);
    // A long run is warned about; a bad one is bad input and prints nothing.
    let o = sb.tactile(&["check", s, "--set", "samples=2000000"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("warning: the run writes about 3.84 GB"));
    let o = sb.tactile(&["check", s, "--set", "rate_hz=5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    assert!(String::from_utf8_lossy(&o.stderr).contains("rate_hz"));
}

/// The paper scenario in lockstep, `samples` long, its forward network replayed from
/// `net.csv` (delay and loss of packet k from `net`); returns the scenario and the CSV.
fn replayed(
    sb: &Sandbox,
    samples: u64,
    net: impl Fn(u64) -> (u64, bool),
) -> (std::path::PathBuf, String) {
    let mut csv = String::from("delay,lost\n");
    for k in 0..samples {
        let (delay, lost) = net(k);
        csv.push_str(&format!("{delay},{}\n", u8::from(lost)));
    }
    sb.write("net.csv", &csv);
    let text = util::paper_1khz(samples).replace("mode = \"realtime\"", "mode = \"lockstep\"")
        + "\n[network.forward.replay]\npath = \"net.csv\"\n";
    (sb.write("s.toml", &text), csv)
}

/// Issue 51: `--resume` kept a run whose folder held another run's `summary.json`
/// beside its own right `scenario.toml`. A summary is kept only with the record it
/// reports (the master's record's length and CRC-32).
#[test]
fn resume_keeps_a_summary_only_with_the_records_it_reports() {
    let sb = Sandbox::new("resume-own");
    let s = sb.write(
        "s.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 300"),
    );
    let sweep = |extra: &[&str]| {
        let mut args = vec!["sweep", s.to_str().expect("utf-8"), "--set", "seed=1,2"];
        args.extend_from_slice(&["--out", "sw"]);
        args.extend_from_slice(extra);
        let o = sb.tactile(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    sweep(&[]);
    let (own, other) = (
        sb.path("sw").join("run-0000"),
        sb.path("sw").join("run-0001"),
    );
    std::fs::copy(other.join("summary.json"), own.join("summary.json")).expect("copy");
    let err = sweep(&["--resume"]);
    assert!(err.contains("1 runs kept from before"), "{err}");
    let after = sb.json("sw/run-0000", "summary.json");
    let theirs = sb.json("sw/run-0001", "summary.json");
    let digest = |j: &serde_json::Value| j["nodes"]["master"]["digest"].clone();
    assert_ne!(digest(&after), digest(&theirs), "run-0000 was run again");
    assert_ne!(after["master"], theirs["master"], "its own figures");
}
