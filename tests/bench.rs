//! `tactile bench` end to end, small: every part runs and reports, and the same loop
//! over UDP is the same loop.

use crate::util;

use tactile_report::trace::signal_columns;
use util::Sandbox;

#[test]
fn bench_reports_both_transports_the_floor_and_the_throughput() {
    let sb = Sandbox::new("bench");
    let out = sb.path("bench");
    let o = sb.tactile(&[
        "bench",
        "--samples",
        "400",
        "--rates",
        "1000",
        "--lockstep-samples",
        "400",
        // A SCHED_FIFO 99 probe would stall the tests running beside this one; the
        // probe has its own unit test.
        "--probe-s",
        "0",
        "--out",
        out.to_str().expect("utf-8"),
        "--prefix",
        &sb.prefix,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    // The Zenoh loop is there when the build has the Zenoh link.
    let zenoh = cfg!(feature = "zenoh");
    let mut needles = vec![
        "iceoryx2 loop",
        "udp loop",
        "bare iceoryx2",
        "iceoryx2/udp",
        "lockstep throughput",
    ];
    if zenoh {
        needles.extend([
            "zenoh loop",
            "zenoh/udp",
            "live-on loop",
            "live-on/live-off",
        ]);
    }
    for needle in needles {
        assert!(text.contains(needle), "{needle}: {text}");
    }
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("bench.json")).expect("json"))
            .expect("parse");
    let r = &v["rates"][0];
    // Every round trip is accounted for, whatever the load on the machine: the trios
    // record late answers too; the bare hop counts a late one as a miss.
    let loops = r["loops"].as_array().expect("loops");
    let names: Vec<&str> = loops.iter().filter_map(|l| l["name"].as_str()).collect();
    let expected: &[&str] = if zenoh {
        &["iceoryx2", "udp", "zenoh", "live-off", "live-on"]
    } else {
        &["iceoryx2", "udp"]
    };
    assert_eq!(names, expected);
    for l in loops {
        assert_eq!(l["overhead_ns"]["count"].as_u64(), Some(400), "{l}");
        assert!(util::num(&l["overhead_ns"]["p50"]) > 0.0, "{l}");
        assert_eq!(l["samples_lost"], 0, "{l}");
    }
    let hop = r["bare_hop_round_trip_ns"]["count"]
        .as_u64()
        .expect("count");
    let hop_misses = r["bare_hop_deadline_misses"].as_u64().expect("misses");
    assert_eq!(hop + hop_misses, 400, "{r}");
    assert!(hop > 0 && util::num(&r["bare_hop_round_trip_ns"]["p50"]) > 0.0);
    if zenoh {
        // Every node's live view reached the viewer: the master's six topics and the
        // slave's three at 100 Hz over 0.4 s, 360 messages (the end of the run may cut
        // the last, and the view drops what its thread, below the loop's priority,
        // cannot take in time on a machine busy with other tests).
        let m = r["live_messages"].as_u64().expect("live messages");
        assert!((9 * 25..=9 * 40).contains(&m), "{m} live messages");
    }
    for k in ["iceoryx2/udp", "zenoh/udp", "live-on/live-off"]
        .iter()
        .take(1 + 2 * usize::from(zenoh))
    {
        assert!(
            r["ratios"][k].as_array().is_some_and(|a| a.len() == 3),
            "{k}: {r}"
        );
    }
    assert_eq!(loops[0]["stages_ns"].as_object().map(|m| m.len()), Some(9));
    assert!(util::num(&v["lockstep_samples_per_s"]) > 100.0);
    assert_eq!(v["machine"]["note"], "not probed (--probe-s 0)", "{v}");
    // Each trio left its own full report.
    for run in ["iceoryx2-1000", "udp-1000", "lockstep"]
        .into_iter()
        .chain(zenoh.then_some("zenoh-1000"))
    {
        assert!(out.join(run).join("summary.json").exists(), "{run}");
    }
    sb.assert_no_leftover_processes();
}

#[test]
fn lockstep_over_udp_equals_the_in_process_simulation() {
    let sb = Sandbox::new("udplock");
    let text = tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace(
            "noise_std = [0.0, 0.0, 0.0]\n\n[network.backward]",
            "noise_std = [0.001, 0.0, 0.0005]\n\n[network.backward]",
        );
    let scenario = sb.write("s.toml", &text);
    let o = sb.tactile(&[
        "run",
        scenario.to_str().expect("utf-8"),
        "--udp",
        "-q",
        "--prefix",
        &sb.prefix,
        "--out",
        sb.path("udp").to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    sb.simulate(&scenario, "sim");
    assert_eq!(
        signal_columns(&sb.trace("udp")),
        signal_columns(&sb.trace("sim"))
    );
    let s = sb.json("udp", "summary.json");
    assert_eq!(s["samples_lost"], 0);
    for stream in ["c", "v", "h", "q"] {
        assert_eq!(s["channels"][stream]["received"], 1200, "{stream}");
    }
    sb.assert_no_leftover_processes();
}
