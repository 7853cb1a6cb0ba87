//! `--set KEY=VALUE` on `tactile run`, and `tactile sweep`.

use crate::util;

use util::Sandbox;

/// The paper scenario at 1 kHz, lockstep, `samples` samples.
fn scenario(samples: u64) -> String {
    util::paper_1khz(samples).replace("mode = \"realtime\"", "mode = \"lockstep\"")
}

#[test]
fn set_changes_the_scenario_as_run_and_is_checked_like_the_file() {
    let sb = Sandbox::new("set");
    let s = sb.write("s.toml", &scenario(400));
    let s = s.to_str().expect("utf-8");
    let o = sb.tactile(&[
        "run",
        s,
        "--in-process",
        "--out",
        "out",
        "--set",
        "network.forward.delay=[3, 3, 3]",
        "--set",
        "samples=300",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let sum = sb.json("out", "summary.json");
    assert_eq!(sum["samples_sent"], 300);
    let ran = std::fs::read_to_string(sb.path("out").join("scenario.toml")).expect("copy");
    assert!(ran.contains("delay = [3, 3, 3]"), "{ran}");
    // Bad sets: exit 2, one line naming the key, nothing written.
    // The needles are the scenario's own words, not the echo of the set.
    for (set, needle) in [
        (
            "network.forward.dealy=[1,1,1]",
            "unknown field `dealy`, expected one of `delay`",
        ),
        (
            "rate_hz=fast",
            "with --set rate_hz=fast: invalid type: string \"fast\", expected f64",
        ),
        ("samples=0", "field `samples`: 0 is outside"),
        ("samples", "expected KEY=VALUE"),
        ("network.forward.delay[7]=1", "delay has 3 entries"),
    ] {
        sb.assert_bad_set(s, set, needle);
    }
}

#[test]
fn a_sweep_runs_every_combination_and_tabulates_the_summaries() {
    let sb = Sandbox::new("sweep");
    let s = sb.write("s.toml", &scenario(2000));
    let o = sb.tactile(&[
        "sweep",
        s.to_str().expect("utf-8"),
        "--set",
        "network.forward.delay=[0,0,0],[10,10,10],[40,40,40]",
        "--set",
        "seed=1,2",
        "--out",
        "sw",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(sb.path("sw").join("sweep.csv")).expect("csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 6, "{csv}");
    assert!(lines[0].starts_with("run,network.forward.delay,seed,samples_sent"));
    // Each row is a view of its run's summary.
    for k in 0..6 {
        let sum = sb.json(&format!("sw/run-{k:04}"), "summary.json");
        let row: Vec<&str> = lines[1 + k].split("\",").collect();
        let cells: Vec<&str> = row[1].split(',').collect();
        assert_eq!(cells[1], sum["samples_sent"].to_string(), "row {k}");
        let rms = sum["tracking_rms_m"].as_f64().expect("rms");
        assert_eq!(cells[4].parse::<f64>().expect("rms"), rms, "row {k}");
        assert!(!sb.path(&format!("sw/run-{k:04}/trace.csv")).exists());
    }
    // The delay shows in the round trip: 0, 10 and 40 samples forward.
    let rt = |k: usize| {
        sb.json(&format!("sw/run-{k:04}"), "summary.json")["round_trip_ns"]["p50"].as_u64()
    };
    assert!(
        rt(0) < rt(2) && rt(2) < rt(4),
        "{:?} {:?} {:?}",
        rt(0),
        rt(2),
        rt(4)
    );
    for metric in ["tracking_rms_m", "round_trip_p50_ns"] {
        let svg = sb.path("sw").join(format!("sweep-{metric}.svg"));
        let text = std::fs::read_to_string(&svg).expect("plot");
        assert!(
            text.contains("seed=2"),
            "{metric}: one line per value of the second key"
        );
    }
}

#[test]
fn a_bad_value_anywhere_in_a_sweep_stops_it_before_any_run() {
    let sb = Sandbox::new("sweepbad");
    let s = sb.write("s.toml", &scenario(100));
    let o = sb.tactile(&[
        "sweep",
        s.to_str().expect("utf-8"),
        "--set",
        "rate_hz=1000.0,50.0",
        "--out",
        "sw",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("field `rate_hz`: 50 Hz is outside 100..=10000 Hz"),
        "{err}"
    );
    assert!(!sb.path("sw").exists(), "nothing ran");
}
