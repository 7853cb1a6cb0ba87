//! A link with a rate and a queue (mm-link's semantics; `common/netem/src/link/`
//! checks them packet by packet against a transcription of `link_queue.cc`): a
//! shipped trace by name runs, repeats byte for byte in-process and as processes, and
//! reruns from its run folder; every bad setting and trace is refused with exit 2
//! naming the field, nothing started.

use crate::util;
use tactile_report::trace::signal_columns;
use util::Sandbox;

/// The shipped press over Verizon's LTE traces.
fn wall_lte() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wall-lte.toml")
}

/// The shipped trace named in `wall-lte.toml` is found beside the scenarios, copied
/// into the run's inputs, and the run repeats: twice in-process, once as processes,
/// once again from the run folder's own scenario, the same trace byte for byte; its
/// delays are the link's (they vary, and the queue makes some long).
#[test]
fn a_shipped_trace_by_name_runs_and_repeats() {
    let sb = Sandbox::new("link");
    let s = wall_lte();
    let s = s.to_str().expect("utf-8");
    let short = ["--set", "samples=3000"];
    for out in ["a", "b"] {
        let mut args = vec!["run", s, "--in-process", "--out", out, "-q"];
        args.extend(short);
        let o = sb.tactile(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let trace = sb.trace("a");
    assert_eq!(trace, sb.trace("b"), "same seed, same run");
    let inputs = sb.path("a").join("inputs");
    assert!(inputs.join("Verizon-LTE-short.up").is_file());
    assert!(inputs.join("Verizon-LTE-short.down").is_file());
    let written = std::fs::read_to_string(sb.path("a").join("scenario.toml")).expect("scenario");
    assert!(
        written.contains("path = \"inputs/Verizon-LTE-short.up\""),
        "{written}"
    );
    let again = sb.path("a").join("scenario.toml");
    let o = sb.tactile(&[
        "run",
        again.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        "c",
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(sb.trace("c"), trace, "rerun from the run folder");
    let mut args = vec!["run", s, "--out", "p", "--prefix", &sb.prefix, "-q"];
    args.extend(short);
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    sb.assert_no_leftover_processes();
    assert_eq!(
        signal_columns(&sb.trace("p")),
        signal_columns(&trace),
        "processes as in-process (the wall-clock columns aside)"
    );
    let delays = util::column(&trace, "delay_f_1");
    let longest = delays.iter().copied().fold(0.0, f64::max);
    let mut seen: Vec<u64> = delays.iter().map(|d| *d as u64).collect();
    seen.sort_unstable();
    seen.dedup();
    assert!(seen.len() > 5 && longest > 10.0, "{seen:?}");
}

/// Bad links and traces: exit 2, the field named, nothing started.
#[test]
fn bad_links_and_traces_are_refused_naming_the_field() {
    let sb = Sandbox::new("badlink");
    sb.write("empty.trace", "");
    sb.write("back.trace", "1\n5\n3\n");
    sb.write("zero.trace", "0\n0\n");
    sb.write("ok.trace", "1\n2\n");
    sb.write("back.csv", "time_ms,rate_bps\n0,1e6\n0,2e6\n");
    sb.write("stops.csv", "time_ms,rate_bps\n0,1e6\n5,0\n");
    // Over the size limit (100 MB), sparse: refused by its size before it is read,
    // as a trace of 10^8 lines (at least 200 MB) is.
    let huge = std::fs::File::create(sb.path("huge.trace")).expect("create");
    huge.set_len((100 << 20) + 1).expect("grow");
    let base = util::paper_1khz(200).replace("mode = \"realtime\"", "mode = \"lockstep\"");
    let link = |body: &str| format!("{base}\n[network.forward.link]\n{body}\n");
    let f = "network.forward.link";
    let cases = [
        (link("rate = 0.0"), format!("{f}.rate")),
        (link("rate = -1e6"), format!("{f}.rate")),
        (link("rate = nan"), format!("{f}.rate")),
        (link("rate = 1e6\nqueue = \"droptail\"\npackets = 0"), format!("{f}.packets")),
        (link("rate = 1e6\nqueue = \"drophead\"\nbytes = 0"), format!("{f}.bytes")),
        (link("rate = 1e6\nqueue = \"droptail\""), format!("{f}.queue")),
        (link("rate = 1e6\npackets = 10"), format!("{f}.packets")),
        (link("trace = \"nowhere-lte\""), format!("{f}.trace")),
        (link("trace = \"verizon-lte-short-up\"\nrate = 1e6"), f.to_string()),
        (link("path = \"ok.trace\"\npayload_bytes = 1500"), format!("{f}.payload_bytes")),
        (link("path = \"empty.trace\""), "no delivery opportunities".into()),
        (link("path = \"back.trace\""), "line 3: 3 ms goes back in time".into()),
        (link("path = \"zero.trace\""), "the trace lasts 0 ms".into()),
        (link("path = \"huge.trace\""), "huge.trace".into()),
        (link("path = \"gone.trace\""), "gone.trace".into()),
        (link("rate_trace = \"back.csv\""), "line 3: \"0,2e6\": time_ms does not increase".into()),
        (link("rate_trace = \"stops.csv\""), "the link would stop for good".into()),
        (link("rate_trace = \"\""), format!("{f}.rate_trace")),
        (
            base.replacen("delay = [0, 0, 0]", "delay = [3, 3, 3]", 1)
                + "\n[network.forward.link]\nrate = 1e6\n",
            f.to_string(),
        ),
        (
            format!("{base}\n[network.forward.replay]\npath = \"ok.trace\"\nformat = \"mahimahi\"\npacket_bytes = 250\n"),
            "network.forward.replay.packet_bytes".into(),
        ),
        (
            format!("{base}\n[network.forward.replay]\npath = \"ok.trace\"\nformat = \"mahimahi\"\nmax_queue_samples = 50\n"),
            "queue = \"droptail\", packets = N".into(),
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        sb.assert_refused(k, text, want);
    }
}

/// A rate over time: 3 Mbit/s, then 100 ms of nothing, then 3 Mbit/s again; the
/// packets sent in the outage wait for its end (delays up to 100 samples at 1 kHz),
/// and the run repeats.
#[test]
fn a_rate_over_time_holds_the_packets_through_its_outage() {
    let sb = Sandbox::new("ratetr");
    sb.write("rates.csv", "time_ms,rate_bps\n0,3e6\n200,0\n300,3e6\n");
    let text = util::paper_1khz(600).replace("mode = \"realtime\"", "mode = \"lockstep\"")
        + "\n[network.forward.link]\nrate_trace = \"rates.csv\"\n";
    let trace = util::run_twice(&sb, &text);
    let delays = util::column(&trace, "delay_f_1");
    let longest = delays.iter().copied().fold(0.0, f64::max);
    // The packet sent at 200 ms leaves at 300 ms and 0.74 us (278 bytes at 3 Mbit/s).
    assert_eq!(longest, 101.0, "{delays:?}");
    assert!(delays[..200].iter().all(|d| *d <= 1.0));
}

/// The disciplines beyond mm-link's FIFOs: a PIE link (its own random stream) and an
/// FQ-CoDel one repeat byte for byte in-process and as processes; their bad settings
/// are refused with exit 2 naming the field.
#[test]
fn aqm_links_repeat_and_refuse_bad_settings() {
    let sb = Sandbox::new("aqm");
    let base = util::paper_1khz(600).replace("mode = \"realtime\"", "mode = \"lockstep\"");
    // 278 bytes a ms on 2 Mbit/s: 111 % load, so PIE must drop.
    let pie = format!(
        "{base}\n[network.forward.link]\nrate = 2e6\nqueue = \"pie\"\npie = {{ target_ms = 5.0, max_burst_ms = 0.0 }}\n\n[network.backward.link]\nrate = 1e7\nqueue = \"fq_codel\"\n"
    );
    let trace = util::run_twice(&sb, &pie);
    let s = sb.write("p.toml", &pie);
    let o = sb.tactile(&[
        "run",
        s.to_str().expect("utf-8"),
        "--out",
        "p",
        "--prefix",
        &sb.prefix,
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    sb.assert_no_leftover_processes();
    assert_eq!(
        signal_columns(&sb.trace("p")),
        signal_columns(&trace),
        "processes as in-process"
    );
    // CoDel in Linux's arithmetic one way, weighted classes the other, then strict
    // priority: each runs and repeats.
    let sb2 = Sandbox::new("aqm2");
    for (fwd, back) in [
        (
            "queue = \"codel\"\ncodel = { arithmetic = \"linux\" }",
            "queue = \"weighted\"\nweighted = { classes = [{ flows = [0], weight = 3 }, { }] }",
        ),
        (
            "queue = \"priority\"\npriority = { classes = [{ flows = [0], packets = 5 }] }",
            "queue = \"pie\"\npackets = 50",
        ),
    ] {
        let text = format!(
            "{base}\n[network.forward.link]\nrate = 2e6\n{fwd}\n\n[network.backward.link]\nrate = 2e6\n{back}\n"
        );
        util::run_twice(&sb2, &text);
    }
    let link = |body: &str| format!("{base}\n[network.forward.link]\nrate = 1e6\n{body}\n");
    let f = "network.forward.link";
    let cases = [
        (
            link("queue = \"codel\"\ncodel = { target_ms = 0.0 }"),
            format!("{f}.codel.target_ms"),
        ),
        (
            link("queue = \"codel\"\ncodel = { interval_ms = nan }"),
            format!("{f}.codel.interval_ms"),
        ),
        (link("queue = \"pie\"\ncodel = { }"), format!("{f}.codel")),
        (
            link("queue = \"pie\"\npie = { alpha = -1.0 }"),
            format!("{f}.pie.alpha"),
        ),
        (
            link("queue = \"pie\"\npie = { tupdate_ms = 0.0 }"),
            format!("{f}.pie.tupdate_ms"),
        ),
        (
            link("queue = \"fq_codel\"\nfq_codel = { flows = 0 }"),
            format!("{f}.fq_codel.flows"),
        ),
        (
            link("queue = \"fq_codel\"\nfq_codel = { limit = 0 }"),
            format!("{f}.fq_codel.limit"),
        ),
        (
            link("queue = \"fq_codel\"\nfq_codel = { quantum = 0 }"),
            format!("{f}.fq_codel.quantum"),
        ),
        (
            link("queue = \"fq_codel\"\npackets = 10"),
            format!("{f}.packets"),
        ),
        (link("queue = \"priority\""), format!("{f}.priority")),
        (
            link("queue = \"priority\"\npriority = { classes = [] }"),
            format!("{f}.priority.classes"),
        ),
        (
            link("queue = \"priority\"\npriority = { classes = [{ flows = [0], weight = 2 }] }"),
            format!("{f}.priority.classes[0].weight"),
        ),
        (
            link(
                "queue = \"weighted\"\nweighted = { classes = [{ flows = [0] }, { flows = [0] }] }",
            ),
            format!("{f}.weighted.classes[1].flows"),
        ),
        (
            link("queue = \"weighted\"\nweighted = { classes = [{ flows = [0], packets = 0 }] }"),
            format!("{f}.weighted.classes[0].packets"),
        ),
        (
            link("queue = \"weighted\"\nweighted = { classes = [{ weight = 0 }] }"),
            format!("{f}.weighted.classes[0].weight"),
        ),
        (link("queue = \"red\""), "queue".into()),
        (
            link("queue = \"codel\"\ncodel = { arithmetic = \"bsd\" }"),
            "arithmetic".into(),
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        sb.assert_refused(k, text, want);
    }
}
