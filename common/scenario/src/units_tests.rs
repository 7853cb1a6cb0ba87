//! The `_ms` keys' unit tests: each form read as its sample twin, both forms refused,
//! a value between samples refused with the two nearest that are not.
use crate::overrides::{apply, Set};
use crate::{Scenario, ScenarioError};

fn read(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::from_toml_str(text)
}

fn same(ms: &str, samples: &str) {
    let a = read(ms).unwrap_or_else(|e| panic!("{ms}: {e}"));
    let b = read(samples).unwrap_or_else(|e| panic!("{samples}: {e}"));
    assert_eq!(a, b, "{ms}\nis not\n{samples}");
    assert_eq!(a.to_toml(), b.to_toml());
}

fn refused(text: &str, needles: &[&str]) {
    let e = read(text).expect_err(text).to_string();
    for n in needles {
        assert!(e.contains(n), "{text}\n{e}\nlacks {n:?}");
    }
}

#[test]
fn a_delay_in_ms_is_the_delay_in_samples_at_the_rate() {
    same(
        "[network.forward]\ndelay_ms = 100\n",
        "[network.forward]\ndelay = [10, 10, 10]\n",
    );
    same(
        "rate_hz = 1000\n[network.backward]\ndelay_ms = [1, 2.0, 30]\n",
        "rate_hz = 1000\n[network.backward]\ndelay = [1, 2, 30]\n",
    );
    same(
        "rate_hz = 10000.0\n[network.forward]\ndelay_ms = 0.1\n",
        "rate_hz = 10000.0\n[network.forward]\ndelay = [1, 1, 1]\n",
    );
}

#[test]
fn a_schedule_and_a_jitter_in_ms_are_theirs_in_samples() {
    same(
        "[network.forward]\nschedule_ms = [[0, 50], [1000, 10, 20, 30]]\n",
        "[network.forward]\nschedule = [[0, 5, 5, 5], [100, 1, 2, 3]]\n",
    );
    same(
        "[network.forward.jitter]\njitter_ms = 20\ndistribution = \"normal\"\n",
        "[network.forward.jitter]\njitter = 2.0\ndistribution = \"normal\"\n",
    );
}

#[test]
fn both_forms_of_one_time_are_refused_naming_both() {
    for (text, a, b) in [
        (
            "[network.forward]\ndelay = [1, 1, 1]\ndelay_ms = 10\n",
            "network.forward.delay_ms",
            "network.forward.delay`",
        ),
        (
            "[network.backward]\nschedule = [[0, 1, 1, 1]]\nschedule_ms = [[0, 10]]\n",
            "network.backward.schedule_ms",
            "network.backward.schedule`",
        ),
        (
            "[network.forward.jitter]\njitter = 1.0\njitter_ms = 10\n",
            "network.forward.jitter.jitter_ms",
            "network.forward.jitter.jitter`",
        ),
    ] {
        refused(text, &[a, b, "both set"]);
    }
}

#[test]
fn a_time_between_samples_is_refused_with_the_nearest_that_are_not() {
    refused(
        "[network.forward]\ndelay_ms = 15\n",
        &[
            "network.forward.delay_ms",
            "15 ms is 1.5 samples at 100 Hz",
            "give 10 or 20 ms",
        ],
    );
    refused(
        "[network.forward]\ndelay_ms = [10, 10, 12]\n",
        &["network.forward.delay_ms[2]", "12 ms"],
    );
    refused(
        "[network.backward]\nschedule_ms = [[5, 10]]\n",
        &["network.backward.schedule_ms[0][0]", "5 ms is 0.5 samples"],
    );
}

#[test]
fn bad_times_in_ms_are_refused_naming_the_field() {
    for (text, needles) in [
        (
            "[network.forward]\ndelay_ms = -10\n",
            &[
                "network.forward.delay_ms",
                "-10 ms must be finite and non-negative",
            ][..],
        ),
        (
            "[network.forward]\ndelay_ms = nan\n",
            &["network.forward.delay_ms", "finite"],
        ),
        (
            "[network.forward]\ndelay_ms = inf\n",
            &["network.forward.delay_ms", "finite"],
        ),
        (
            "[network.forward]\ndelay_ms = 1e12\n",
            &["network.forward.delay_ms", "beyond 100000"],
        ),
        (
            "[network.forward]\ndelay_ms = \"100\"\n",
            &["network.forward.delay_ms", "not a number"],
        ),
        (
            "[network.forward]\ndelay_ms = [10, 10]\n",
            &["network.forward.delay_ms", "has 2 elements"],
        ),
        (
            "[network.forward]\nschedule_ms = [[0, 10, 10]]\n",
            &["network.forward.schedule_ms[0]", "a row is"],
        ),
        (
            "[network.forward]\nschedule_ms = [[100, 10], [100, 20]]\n",
            &["network.forward.schedule_ms[1]", "strictly increasing"],
        ),
        (
            "[network.forward.jitter]\njitter_ms = -1\n",
            &["network.forward.jitter.jitter_ms", "non-negative"],
        ),
        (
            "[network.forward.jitter]\njitter_ms = 1e9\n",
            &["network.forward.jitter.jitter_ms", "beyond 10000"],
        ),
        (
            "rate_hz = 5\n[network.forward]\ndelay_ms = 10\n",
            &["rate_hz", "outside 100..=10000"],
        ),
        (
            "[network.forward]\ndelay_ms = 10\ndelya = 1\n",
            &["unknown field `delya`"],
        ),
        // A mistake the text as written makes too keeps its line and column.
        (
            "[network.forward]\ndelya = 1\ndelay_ms = 10\n",
            &["line 2, column 1: field `network.forward.delya`: unknown field `delya`"],
        ),
    ] {
        refused(text, needles);
    }
}

#[test]
fn a_set_in_one_unit_replaces_the_files_time_in_the_other() {
    let file = "[network.forward]\ndelay = [1, 1, 1]\n[network.forward.jitter]\njitter = 1.0\n";
    let sets = [
        Set::parse("network.forward.delay_ms=50").expect("set"),
        Set::parse("network.forward.jitter.jitter_ms=30").expect("set"),
    ];
    let s = read(&apply(file, &sets).expect("apply")).expect("valid");
    assert_eq!(s.network.forward.delay, [5; 3]);
    assert_eq!(s.network.forward.jitter.map(|j| j.jitter), Some(3.0));
    let back = [Set::parse("network.forward.delay=[2,2,2]").expect("set")];
    let file = "[network.forward]\ndelay_ms = 10\n";
    let s = read(&apply(file, &back).expect("apply")).expect("valid");
    assert_eq!(s.network.forward.delay, [2; 3]);
}

#[test]
fn check_shows_each_time_in_samples_and_in_ms() {
    let s = read(
        "rate_hz = 1000\n[network.forward]\ndelay_ms = 50\nschedule_ms = [[0, 50], [3000, 1, 2, 3]]\n[network.forward.jitter]\njitter_ms = 2.5\ndistribution = \"normal\"\n[network.backward]\ndelay = [1, 2, 3]\n",
    )
    .expect("valid");
    assert_eq!(
        super::describe("forward", &s.network.forward, s.rate_hz),
        "network.forward: delay 50 samples (50 ms at 1000 Hz); jitter 2.5 samples (2.5 ms), normal, correlation 0; schedule from sample 0 (0 ms) delay 50 samples (50 ms), from sample 3000 (3000 ms) delay [1, 2, 3] samples ([1, 2, 3] ms)"
    );
    assert_eq!(
        super::describe("backward", &s.network.backward, 300.0),
        "network.backward: delay [1, 2, 3] samples ([3.333, 6.667, 10] ms at 300 Hz)"
    );
}

/// An `_ms` key does not change how the rest is read: an over-long array is named by
/// its field (as without one), a wrong type names its key (review of issue 52, 1).
#[test]
fn a_mistake_beside_an_ms_key_is_named_as_without_it() {
    for (text, needles) in [
        (
            "[network.forward]\ndelay_ms = 100\nnoise_std = [0.001, 0.001, 0.001, 0.001]\n",
            &["network.forward.noise_std", "has 4 elements; it takes 3"][..],
        ),
        (
            "[network.forward]\ndelay_ms = 100\nloss = \"high\"\n",
            &["network.forward.loss", "invalid type: string \"high\""],
        ),
        (
            "[network.forward]\ndelay_ms = 100\n[network.backward]\nloss = \"high\"\n",
            &["network.backward.loss", "invalid type"],
        ),
    ] {
        refused(text, needles);
    }
}

/// A schedule's start in ms is a sample count like the sample form's, which has no
/// delay cap: 2,000 s at 100 Hz is sample 200,000 (review of issue 52, 2).
#[test]
fn a_schedule_start_in_ms_is_not_capped_as_a_delay() {
    same(
        "[network.forward]\nschedule_ms = [[0, 10], [2000000, 20]]\n",
        "[network.forward]\nschedule = [[0, 1, 1, 1], [200000, 2, 2, 2]]\n",
    );
    refused(
        "[network.forward]\nschedule_ms = [[1e300, 10]]\n",
        &["network.forward.schedule_ms[0][0]", "beyond"],
    );
    refused(
        "[network.forward]\nschedule_ms = [[0, 1e12]]\n",
        &["network.forward.schedule_ms[0][1]", "beyond 100000"],
    );
}

/// What `check` prints at a rate that does not divide 1000 reads back: one sample at
/// 300 Hz is shown 3.333 ms, and `delay_ms = 3.333` is that sample; a value between
/// samples is told short numbers (review of issue 52, 8).
#[test]
fn a_time_printed_to_the_microsecond_reads_back_as_its_sample() {
    same(
        "rate_hz = 300\n[network.forward]\ndelay_ms = [3.333, 6.667, 10]\n",
        "rate_hz = 300\n[network.forward]\ndelay = [1, 2, 3]\n",
    );
    same(
        "rate_hz = 7000\n[network.forward]\nschedule_ms = [[0.143, 0.286]]\n",
        "rate_hz = 7000\n[network.forward]\nschedule = [[1, 2, 2, 2]]\n",
    );
    let e = read("rate_hz = 300\n[network.forward]\ndelay_ms = 3.33\n")
        .expect_err("between samples")
        .to_string();
    assert!(e.contains("give 0 or 3.333 ms"), "{e}");
    assert!(e.contains("0.999 samples"), "{e}");
    assert!(e.contains("whole number of samples"), "{e}");
    assert!(!e.contains("3333333"), "{e}");
    let e = read("[network.forward]\ndelay_ms = 11\n")
        .expect_err("1.1")
        .to_string();
    assert!(e.contains("11 ms is 1.1 samples"), "{e}");
}

/// Two `--set`s of one time in its two units are refused naming both; a set in one
/// unit still replaces the file's other (review of issue 52, 3).
#[test]
fn two_sets_of_one_time_in_two_units_are_refused() {
    let file = "[network.forward]\ndelay = [1, 1, 1]\n";
    let sets = [
        Set::parse("network.forward.delay=[5,5,5]").expect("set"),
        Set::parse("network.forward.delay_ms=10").expect("set"),
    ];
    let e = apply(file, &sets).expect_err("twins").to_string();
    assert!(
        e.contains("network.forward.delay=[5,5,5]") && e.contains("network.forward.delay_ms=10"),
        "{e}"
    );
    // Not twins: another channel, or another key.
    let other = [
        Set::parse("network.forward.delay=[5,5,5]").expect("set"),
        Set::parse("network.backward.delay_ms=10").expect("set"),
        Set::parse("network.backward.jitter.jitter_ms=10").expect("set"),
    ];
    let s = read(&apply(file, &other).expect("apply")).expect("valid");
    assert_eq!(s.network.backward.delay, [1; 3]);
}
