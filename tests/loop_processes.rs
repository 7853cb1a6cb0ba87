//! The loop as three real processes over real iceoryx2 shared memory.

use crate::util;

use tactile_report::trace::signal_columns;
use util::{column, std_dev, Sandbox};

/// The paper scenario with a delayed, noisy network, in the given mode.
fn paper_with_network(mode: &str, rate: f64, samples: u64) -> String {
    let base = tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", &format!("mode = \"{mode}\""))
        .replace("rate_hz = 100.0", &format!("rate_hz = {rate:?}"))
        .replace("samples = 1200", &format!("samples = {samples}"));
    base.replace(
        "[network.forward]\ndelay = [0, 0, 0]\nnoise_std = [0.0, 0.0, 0.0]",
        "[network.forward]\ndelay = [2, 3, 1]\nnoise_std = [0.0005, 0.001, 0.0]",
    )
    .replace(
        "[network.backward]\ndelay = [0, 0, 0]\nnoise_std = [0.0, 0.0, 0.0]",
        "[network.backward]\ndelay = [1, 1, 4]\nnoise_std = [0.05, 0.0, 0.02]",
    )
}

#[test]
fn lockstep_trio_equals_the_in_process_simulation_bit_for_bit() {
    let sb = Sandbox::new("lockstep");
    let scenario = sb.write("s.toml", &paper_with_network("lockstep", 100.0, 1200));
    sb.run(&scenario, "trio");
    sb.simulate(&scenario, "sim");
    let trio = signal_columns(&sb.trace("trio"));
    let sim = signal_columns(&sb.trace("sim"));
    assert_eq!(trio.lines().count(), 1201);
    for (k, (a, b)) in trio.lines().zip(sim.lines()).enumerate() {
        assert_eq!(a, b, "trace line {} differs", k + 1);
    }
    // The run exercised what it should: contact forces and injected noise.
    let s = sb.json("trio", "summary.json");
    assert!(util::num(&s["master"]["motion"]["contact_samples"]) > 100.0);
    assert_eq!(s["samples_lost"], 0);
    assert_eq!(s["deadline_misses"], 0);
}

#[test]
fn same_scenario_and_seed_give_identical_traces() {
    let sb = Sandbox::new("determinism");
    let scenario = sb.write("s.toml", &paper_with_network("lockstep", 1000.0, 800));
    sb.run(&scenario, "a");
    sb.run(&scenario, "b");
    assert_eq!(
        signal_columns(&sb.trace("a")),
        signal_columns(&sb.trace("b"))
    );
    let other_seed = std::fs::read_to_string(&scenario)
        .expect("read")
        .replace("seed = 1", "seed = 2");
    let scenario2 = sb.write("s2.toml", &other_seed);
    sb.run(&scenario2, "c");
    assert_ne!(
        signal_columns(&sb.trace("a")),
        signal_columns(&sb.trace("c"))
    );
}

#[test]
fn injected_noise_has_the_configured_spread() {
    let sb = Sandbox::new("noise");
    let text = paper_with_network("lockstep", 1000.0, 3000);
    let scenario = sb.write("s.toml", &text);
    sb.run(&scenario, "run");
    let trace = sb.trace("run");
    // Forward noise as recorded, and as seen in the received signal: v - c(n - d).
    for (axis, want, d) in [(1, 0.0005, 2usize), (2, 0.001, 3)] {
        let recorded = column(&trace, &format!("noise_f_{axis}"));
        let sd = std_dev(&recorded);
        // Standard error of a standard deviation over 3000 samples is ~1.3 %.
        assert!((sd - want).abs() < 0.08 * want, "forward {axis}: sd {sd}");
        let c = column(&trace, &format!("c_{axis}"));
        let v = column(&trace, &format!("v_{axis}"));
        let seen: Vec<f64> = (d..v.len()).map(|n| v[n] - c[n - d]).collect();
        let sd_seen = std_dev(&seen);
        assert!(
            (sd_seen - want).abs() < 0.08 * want,
            "received {axis}: sd {sd_seen}"
        );
    }
    assert!(column(&trace, "noise_f_3").iter().all(|r| *r == 0.0));
    let back = std_dev(&column(&trace, "noise_b_1"));
    assert!((back - 0.05).abs() < 0.004, "backward sd {back}");
}

#[test]
fn injected_delay_shows_in_the_round_trip() {
    let sb = Sandbox::new("delay");
    // 1 kHz, forward delay 3 samples, backward 2: 5 ms on top of the overhead.
    let text = tactile_launch::PAPER_SCENARIO
        .replace("rate_hz = 100.0", "rate_hz = 1000.0")
        .replace("samples = 1200", "samples = 1500")
        .replace(
            "[network.forward]\ndelay = [0, 0, 0]",
            "[network.forward]\ndelay = [3, 3, 3]",
        )
        .replace(
            "[network.backward]\ndelay = [0, 0, 0]",
            "[network.backward]\ndelay = [2, 2, 2]",
        );
    let scenario = sb.write("s.toml", &text);
    sb.run(&scenario, "run");
    let trace = sb.trace("run");
    let rtt = column(&trace, "round_trip_ns");
    let over = column(&trace, "overhead_ns");
    let delays: Vec<f64> = column(&trace, "delay_b_1");
    let mut checked = 0;
    for n in 10..rtt.len() {
        if rtt[n] == 0.0 {
            continue;
        }
        assert_eq!(delays[n], 5.0, "sample {n}: injected delay");
        assert_eq!(rtt[n] - over[n], 5_000_000.0, "sample {n}");
        // The delay is really there: at least 5 ms, and the rest is overhead.
        assert!(rtt[n] >= 5_000_000.0 - 300_000.0, "sample {n}: {}", rtt[n]);
        checked += 1;
    }
    assert!(checked > 1400);
    let s = sb.json("run", "summary.json");
    let p50 = s["round_trip_ns"]["p50"].as_u64().expect("p50");
    let o50 = s["overhead_ns"]["p50"].as_u64().expect("p50");
    // The delay is exactly 5 ms (above); what the machine adds on top is the overhead,
    // well under a millisecond here alone, a few on a machine that runs the whole test
    // suite beside it (6.5 ms round trip once in CI): bounded loosely, the benchmark
    // measures it (docs/07).
    assert!(
        (5_000_000..25_000_000).contains(&p50),
        "round trip p50 {p50}"
    );
    assert!(o50 < 20_000_000, "overhead p50 {o50}");
}

#[test]
fn realtime_1khz_loses_nothing_and_reports_everything() {
    let sb = Sandbox::new("realtime");
    let text = tactile_launch::PAPER_SCENARIO
        .replace("rate_hz = 100.0", "rate_hz = 1000.0")
        .replace("samples = 1200", "samples = 3000");
    let scenario = sb.write("s.toml", &text);
    let o = sb.run(&scenario, "run");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("round trip"), "{stdout}");
    let s = sb.json("run", "summary.json");
    assert_eq!(s["samples_sent"], 3000);
    assert_eq!(s["samples_received"], 3000);
    assert_eq!(s["samples_lost"], 0);
    for stream in ["c", "v", "h", "q"] {
        assert_eq!(s["channels"][stream]["lost"], 0, "stream {stream}");
        assert_eq!(s["channels"][stream]["received"], 3000, "stream {stream}");
    }
    for key in ["round_trip_ns", "overhead_ns"] {
        let p = &s[key];
        assert_eq!(p["count"], 3000, "{key}");
        let vals: Vec<u64> = ["p50", "p90", "p99", "p999", "max"]
            .iter()
            .map(|q| p[q].as_u64().expect("percentile"))
            .collect();
        assert!(
            vals[0] > 0 && vals.windows(2).all(|w| w[0] <= w[1]),
            "{key}: {vals:?}"
        );
    }
    assert!(s["tracking_rms_m"].as_f64().expect("tracking") < 0.01);
    assert!(s["deadline_misses"].as_u64().is_some());
    for f in ["latency.svg", "positions.svg", "forces.svg"] {
        let svg = std::fs::read_to_string(sb.path("run").join(f)).expect("plot");
        assert!(svg.starts_with("<svg") && svg.len() > 2000, "{f}");
    }
    for f in ["round_trip.hgrm", "overhead.hgrm"] {
        let h = std::fs::read_to_string(sb.path("run").join(f)).expect("hgrm");
        assert!(h.contains("Percentile") && h.contains("Total count"), "{f}");
    }
    let stages = s["stages_ns"].as_object().expect("stages");
    assert_eq!(stages.len(), 9);
    assert!(stages.values().all(|p| p["count"] == 3000));
}
