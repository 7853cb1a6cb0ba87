//! Delay histograms in a closed loop: the wall press over the shipped 5G histograms
//! repeats byte for byte, in-process and as processes, its delays the histogram's;
//! bad histogram files and settings are refused naming the field (exit 2, nothing
//! started). (The draws against the file's distribution are unit tests in
//! common/netem/src/histogram_tests.rs, over 10^6 draws.)

use crate::util;

use util::{wall_delay, Sandbox};

/// The wall press with `forward` and `backward` as its channels' delay settings.
fn press(forward: &str, backward: &str) -> String {
    wall_delay()
        .replace("samples = 8000", "samples = 3000")
        .replacen("delay = [25, 25, 25]", forward, 1)
        .replacen("delay = [25, 25, 25]", backward, 1)
}

/// The 3.7 GHz histograms (downlink forward, correlated 0.5; uplink backward): two
/// in-process runs and a run as processes give the same trace; every value the slave
/// got fresh carries a delay the histogram gives at 1 kHz (3.0 to 17.1 ms rounded: 3
/// to 17 samples), many of them. (The 28 GHz URLLC ones, 0.5 to 3.3 ms, are a sample
/// or two at 1 kHz.)
#[test]
fn the_press_over_a_shipped_5g_histogram_repeats_with_its_delays() {
    let sb = Sandbox::new("hist");
    let text = press(
        "delay_histogram = { name = \"5g-3.7ghz-downlink\", correlation = 0.5 }",
        "delay_histogram = { name = \"5g-3.7ghz-uplink\" }",
    );
    let s = sb.write("s.toml", &text);
    // `check` says where each direction's delays come from.
    let o = sb.tactile(&["check", s.to_str().expect("utf-8")]);
    let shown = String::from_utf8_lossy(&o.stderr);
    assert!(
        shown.contains("network.forward: delay per packet from the histogram 5g-3.7ghz-downlink, correlation 0.5 (samples, 1 = 1 ms at 1000 Hz)"),
        "{shown}"
    );
    sb.simulate(&s, "a");
    sb.simulate(&s, "b");
    sb.run(&s, "c");
    let trace = sb.trace("a");
    assert_eq!(trace, sb.trace("b"), "same seed, same run");
    assert_eq!(
        util::signals(&trace),
        util::signals(&sb.trace("c")),
        "in-process and as processes"
    );
    let flags = util::column(&trace, "flags_f");
    let delays = util::column(&trace, "delay_f_1");
    let mut seen: Vec<u64> = flags
        .iter()
        .zip(&delays)
        .skip(10)
        .filter(|(f, _)| (**f as u32) & 1 == 0)
        .map(|(_, d)| *d as u64)
        .collect();
    assert!(seen.len() > 1000, "{} fresh", seen.len());
    seen.sort_unstable();
    seen.dedup();
    assert!(
        seen.len() > 5 && seen.iter().all(|d| (3..=17).contains(d)),
        "{seen:?}"
    );
    // Another seed, other delays.
    let o = sb.tactile(&[
        "run",
        s.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        "d",
        "-q",
        "--set",
        "seed=9",
    ]);
    assert!(o.status.success());
    assert_ne!(trace, sb.trace("d"));
}

/// Bad histograms: each refused with exit 2 and one line naming the field (and the
/// file and the line), nothing written.
#[test]
fn bad_histograms_are_refused_naming_the_field() {
    let sb = Sandbox::new("histbad");
    for (name, text) in [
        ("negative.csv", "delay_ms,count\n1,5\n2,-1\n3,0\n"),
        ("zero.csv", "delay_ms,count\n1,0\n2,0\n"),
        ("unsorted.csv", "delay_ms,count\n2,5\n1,3\n3,0\n"),
        ("nan.csv", "delay_ms,count\n1,5\nNaN,3\n3,0\n"),
        ("open.csv", "delay_ms,count\n1,5\n2,3\n"),
    ] {
        sb.write(name, text);
    }
    let s = sb.write(
        "s.toml",
        &press("delay = [0, 0, 0]", "delay = [25, 25, 25]"),
    );
    let s = s.to_str().expect("utf-8");
    let field = "network.forward.delay_histogram";
    for (set, needle) in [
        (
            "network.forward.delay_histogram={ path = \"negative.csv\" }",
            "negative.csv: line 3: count -1 is negative",
        ),
        (
            "network.forward.delay_histogram={ path = \"zero.csv\" }",
            "zero.csv: count: the counts add up to 0",
        ),
        (
            "network.forward.delay_histogram={ path = \"unsorted.csv\" }",
            "unsorted.csv: line 3: delay_ms 1 ms is not above",
        ),
        (
            "network.forward.delay_histogram={ path = \"nan.csv\" }",
            "nan.csv: line 3: delay_ms \"NaN\" is not a finite number",
        ),
        (
            "network.forward.delay_histogram={ path = \"open.csv\" }",
            "open.csv: line 3: count 3 on the last line",
        ),
        (
            "network.forward.delay_histogram={ path = \"gone.csv\" }",
            "gone.csv",
        ),
        (
            "network.forward.delay_histogram={ name = \"6g\" }",
            "delay_histogram.name`: \"6g\" is no shipped histogram",
        ),
        (
            "network.forward.delay_histogram={ name = \"5g-3.7ghz-uplink\", correlation = 1.0 }",
            "network.forward.delay_histogram.correlation",
        ),
        (
            "network.forward.delay_histogram={ name = \"5g-3.7ghz-uplink\", format = \"csv\" }",
            "network.forward.delay_histogram.format",
        ),
        (
            "network.forward.delay_histogram={ path = \"zero.csv\", format = \"xml\" }",
            "unknown variant `xml`",
        ),
    ] {
        sb.assert_bad_set(s, set, needle);
        if needle.contains(".csv:") {
            sb.assert_bad_set(s, set, field);
        }
    }
    // A histogram gives the whole delay: with a delay, jitter or replay it is refused.
    let both = sb.write(
        "both.toml",
        &press(
            "delay = [25, 25, 25]\ndelay_histogram = { name = \"5g-3.7ghz-downlink\" }",
            "delay = [25, 25, 25]",
        ),
    );
    sb.assert_bad_set(
        both.to_str().expect("utf-8"),
        "seed=2",
        "delay_histogram`: and `network.forward.delay` both set",
    );
    let hist = sb.write(
        "hist.toml",
        &press(
            "delay_histogram = { name = \"5g-3.7ghz-downlink\" }",
            "delay = [25, 25, 25]",
        ),
    );
    sb.assert_bad_set(
        hist.to_str().expect("utf-8"),
        "network.forward.jitter={ jitter = 2.0 }",
        "and `network.forward.jitter` both set",
    );
    // Nor beside a link, which gives each packet's delay too (either way round).
    sb.assert_bad_set(
        hist.to_str().expect("utf-8"),
        "network.forward.link={ rate = 1e6 }",
        "network.forward.link",
    );
}
