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
            "with --set rate_hz=fast: field `rate_hz`: invalid type: string \"fast\", expected f64",
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
    // A swept seed is the seed column every row has.
    assert!(
        lines[0].starts_with("run,combination,network.forward.delay,seed,samples_sent"),
        "{}",
        lines[0]
    );
    // Each row is a view of its run's summary.
    let header = cells(lines[0]);
    let col = |name: &str| header.iter().position(|h| h == name).expect(name);
    for k in 0..6 {
        let sum = sb.json(&format!("sw/run-{k:04}"), "summary.json");
        let row = cells(lines[1 + k]);
        assert_eq!(row[0], format!("run-{k:04}"));
        assert_eq!(row[col("samples_sent")], sum["samples_sent"].to_string());
        let rms = sum["tracking_rms_m"].as_f64().expect("rms");
        let cell: f64 = row[col("tracking_rms_m")].parse().expect("rms");
        assert_eq!(cell, rms, "row {k}");
        assert!(!sb.path(&format!("sw/run-{k:04}/trace.csv")).exists());
    }
    // The delay shows in the round trip: 0, 10 and 40 samples forward, to the
    // nanosecond (in process a round trip is the delay itself; the histogram's bucket
    // read 10,002,431 ns for 10 ms), and the summary says its percentiles are exact.
    let rt = |k: usize| {
        let p = &sb.json(&format!("sw/run-{k:04}"), "summary.json")["round_trip_ns"];
        assert_eq!(p["exact"], true, "{p}");
        p["p50"].as_u64().expect("p50")
    };
    let (a, b, c) = (rt(0), rt(2), rt(4));
    assert_eq!((b - a, c - a), (10_000_000, 40_000_000), "{a} {b} {c}");
    let p50 = &cells(lines[1 + 2])[col("round_trip_p50_ns")];
    assert_eq!(*p50, b.to_string(), "sweep.csv's cell is the summary's");
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

/// One time set twice in its two units (`delay` and `delay_ms`) is refused naming
/// both, exit 2, nothing run: a run kept the last silently, a sweep ran its
/// combinations as duplicates (issue 52 review, 3).
#[test]
fn one_time_set_in_both_units_is_refused_before_any_run() {
    let sb = Sandbox::new("twinset");
    let s = sb.write("s.toml", &scenario(100));
    let s = s.to_str().expect("utf-8");
    let refused = |cmd: &str, extra: &[&str], a: &str, b: &str| {
        let out = format!("{cmd}-out");
        let mut args = vec![cmd, s, "--out", out.as_str(), "--set", a, "--set", b];
        args.extend_from_slice(extra);
        let o = sb.tactile(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        let named = err.contains(a) && err.contains(b) && err.contains("two units");
        assert!(named, "{err}");
        assert!(!sb.path(&out).exists(), "nothing ran");
    };
    let (a, b) = (
        "network.forward.delay=[5,5,5]",
        "network.forward.delay_ms=10",
    );
    refused("run", &["--in-process"], a, b);
    let (a, b) = (
        "network.forward.delay=[1,1,1],[2,2,2]",
        "network.forward.delay_ms=10,20",
    );
    refused("sweep", &[], a, b);
}

/// `tactile sweep` over the paper scenario with two axes (3 x 2 = 6 combinations),
/// extra arguments, into `out`; asserts success.
fn sweep(sb: &Sandbox, out: &str, extra: &[&str]) -> std::process::Output {
    let s = sb.path("s.toml");
    if !s.exists() {
        // Network noise makes the metrics depend on the seed.
        let text = scenario(600).replace(
            "[network.forward]\ndelay = [0, 0, 0]\nnoise_std = [0.0, 0.0, 0.0]",
            "[network.forward]\ndelay = [0, 0, 0]\nnoise_std = [0.0005, 0.0005, 0.0005]",
        );
        assert!(text.contains("0.0005"), "the scenario's noise line changed");
        sb.write("s.toml", &text);
    }
    let mut args = vec![
        "sweep",
        s.to_str().expect("utf-8"),
        "--set",
        "network.forward.delay=[0,0,0],[5,5,5],[20,20,20]",
        "--set",
        "control.kind=none,tdpa",
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn read(sb: &Sandbox, out: &str, file: &str) -> String {
    std::fs::read_to_string(sb.path(out).join(file)).expect(file)
}

#[test]
fn parallel_sharded_and_resumed_sweeps_give_the_same_table() {
    let sb = Sandbox::new("sweep-par");
    sweep(&sb, "one", &["--jobs", "1"]);
    let table = read(&sb, "one", "sweep.csv");
    assert_eq!(table.lines().count(), 1 + 6);
    // A column says whether each run failed: none did.
    let header: Vec<&str> = table.lines().next().unwrap_or("").split(',').collect();
    let failed = header
        .iter()
        .position(|c| *c == "failed")
        .expect("a failed column");
    // Counted from the end: the metrics are numbers, a swept vector is quoted commas.
    let cell = |r: &str| {
        r.rsplit(',')
            .nth(header.len() - 1 - failed)
            .map(str::to_string)
    };
    assert!(
        table
            .lines()
            .skip(1)
            .all(|r| cell(r).as_deref() == Some("0")),
        "{table}"
    );
    sweep(&sb, "two", &["--jobs", "2"]);
    assert_eq!(
        read(&sb, "two", "sweep.csv"),
        table,
        "--jobs 2 equals --jobs 1"
    );
    // Four shards (6 combinations: 2, 2, 1, 1), merged: the same table.
    let shards: Vec<String> = (1..=4).map(|k| format!("shard{k}")).collect();
    for (k, dir) in shards.iter().enumerate() {
        sweep(&sb, dir, &["--shard", &format!("{}/4", k + 1)]);
    }
    let mut args = vec!["sweep", "--merge"];
    args.extend(shards.iter().map(String::as_str));
    args.extend(["--out", "merged"]);
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        read(&sb, "merged", "sweep.csv"),
        table,
        "merged shards equal the whole"
    );
    assert!(sb.path("merged").join("sweep-position_rms_m.svg").exists());
    // Three shards of four are not the whole: merged, the missing runs are named.
    let o = sb.tactile(&[
        "sweep", "--merge", "shard1", "shard2", "shard3", "--out", "part",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("run-0003"));
    // Resume: a run whose report is gone is run again, the others are kept.
    std::fs::remove_file(sb.path("one").join("run-0004").join("summary.json")).expect("rm");
    let o = sweep(&sb, "one", &["--resume"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("5 runs kept from before"));
    assert_eq!(read(&sb, "one", "sweep.csv"), table);
    // Another combination's run left in a run's folder, and a run that failed: both
    // are run again, never put in the table.
    let one = sb.path("one");
    for f in ["scenario.toml", "summary.json"] {
        std::fs::copy(one.join("run-0005").join(f), one.join("run-0002").join(f)).expect("cp");
    }
    let path = one.join("run-0001").join("summary.json");
    let mut s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json");
    s["failed"] = serde_json::Value::Bool(true);
    std::fs::write(&path, s.to_string()).expect("write");
    let o = sweep(&sb, "one", &["--resume"]);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("4 runs kept from before"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(read(&sb, "one", "sweep.csv"), table);
    // A slice of another sweep is refused.
    std::fs::create_dir(sb.path("other")).expect("mkdir");
    let spec = read(&sb, "shard4", "sweep.json")
        .replace("control.kind=none,tdpa", "control.kind=none,wave");
    sb.write("other/sweep.json", &spec);
    let o = sb.tactile(&["sweep", "--merge", "shard1", "other", "--out", "bad"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("a slice of another sweep"));
}

#[test]
fn seeds_give_a_mean_and_an_interval_per_metric() {
    let sb = Sandbox::new("sweep-seeds");
    sweep(&sb, "s3", &["--seeds", "3"]);
    let table = read(&sb, "s3", "sweep-summary.csv");
    let header: Vec<&str> = table.lines().next().expect("header").split(',').collect();
    assert_eq!(header[3], "seeds");
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let rows: Vec<Vec<String>> = table.lines().skip(1).map(cells).collect();
    assert_eq!(rows.len(), 6);
    // Seed-independent: samples sent; seed-dependent: tracking with network noise.
    let (sent, sent_ci) = (col("samples_sent_mean"), col("samples_sent_ci95"));
    let (track, track_ci) = (col("tracking_rms_m_mean"), col("tracking_rms_m_ci95"));
    for r in &rows {
        assert_eq!(r[3], "3");
        assert_eq!((r[sent].as_str(), r[sent_ci].as_str()), ("600", "0"));
        let ci: f64 = r[track_ci].parse().expect("interval");
        let mean: f64 = r[track].parse().expect("mean");
        assert!(ci > 0.0 && ci < mean, "{ci} of {mean}");
    }
    // sweep.csv: every run; the mean is theirs.
    let runs = read(&sb, "s3", "sweep.csv");
    assert_eq!(runs.lines().count(), 1 + 18);
    let rh = cells(runs.lines().next().expect("h"));
    let rc = |name: &str| rh.iter().position(|h| h == name).expect(name);
    let first: Vec<f64> = runs
        .lines()
        .skip(1)
        .map(cells)
        .filter(|r| r[rc("combination")] == "0")
        .map(|r| r[rc("tracking_rms_m")].parse().expect("f64"))
        .collect();
    assert_eq!(first.len(), 3);
    let mean: f64 = rows[0][track].parse().expect("mean");
    assert!((first.iter().sum::<f64>() / 3.0 - mean).abs() < 1e-15);
    assert!(sb
        .path("s3")
        .join("run-0000-s2")
        .join("summary.json")
        .exists());
}

/// A script reads the tables the same way whatever `--seeds`: `sweep.csv` one row per
/// run, `sweep-summary.csv` one per combination, their columns the same for one seed
/// as for two (an interval of one run is empty), list values as JSON.
#[test]
fn the_tables_have_the_same_columns_whatever_the_seeds() {
    let sb = Sandbox::new("sweep-cols");
    sweep(&sb, "one", &[]);
    sweep(&sb, "two", &["--seeds", "2"]);
    for file in ["sweep.csv", "sweep-summary.csv"] {
        let head = |out: &str| read(&sb, out, file).lines().next().map(str::to_owned);
        assert_eq!(head("one"), head("two"), "{file}");
    }
    assert_eq!(read(&sb, "one", "sweep.csv").lines().count(), 1 + 6);
    assert_eq!(read(&sb, "two", "sweep.csv").lines().count(), 1 + 12);
    let summary = read(&sb, "one", "sweep-summary.csv");
    let head = cells(summary.lines().next().expect("header"));
    let ci = head
        .iter()
        .position(|h| h == "tracking_rms_m_ci95")
        .expect("ci");
    let delay = head
        .iter()
        .position(|h| h == "network.forward.delay")
        .expect("delay");
    for line in summary.lines().skip(1) {
        let row = cells(line);
        assert_eq!(row[ci], "", "one run bounds nothing: {line}");
        let v: serde_json::Value = serde_json::from_str(&row[delay]).expect("a JSON list");
        assert_eq!(v.as_array().map(Vec::len), Some(3), "{line}");
    }
}

/// `sweep.csv`'s seed is the one each run's `scenario.toml` says it ran with (the
/// scenario's seed 1, then 2 and 3), not the seed's index.
#[test]
fn every_run_s_seed_is_the_one_it_ran_with() {
    let sb = Sandbox::new("sweep-seed");
    sweep(&sb, "s", &["--seeds", "3"]);
    let runs = read(&sb, "s", "sweep.csv");
    let head = cells(runs.lines().next().expect("header"));
    let col = |name: &str| head.iter().position(|h| h == name).expect(name);
    let mut seen = std::collections::BTreeSet::new();
    for line in runs.lines().skip(1) {
        let row = cells(line);
        let toml = read(&sb, &format!("s/{}", row[col("run")]), "scenario.toml");
        let ran = toml
            .lines()
            .find_map(|l| l.strip_prefix("seed = "))
            .expect("seed line");
        assert_eq!(row[col("seed")], ran, "{line}");
        seen.insert(row[col("seed")].clone());
    }
    assert_eq!(seen.into_iter().collect::<Vec<_>>(), ["1", "2", "3"]);
}

/// A CSV line's cells, commas inside quotes kept (`"[0,0,0]"`).
fn cells(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            c => cur.push(c),
        }
    }
    out.push(cur);
    out
}

#[test]
fn a_sweep_says_its_scenarios_warnings_once() {
    let sb = Sandbox::new("sweep-warn");
    let text = util::wall_delay().replace("samples = 8000", "samples = 200");
    let s = sb.write("s.toml", &text);
    let o = sb.tactile(&[
        "sweep",
        s.to_str().expect("utf-8"),
        "--set",
        "environment.objects[0].stiffness=[600,600,600],[800,800,800]",
        "--set",
        "control.kind=none,tdpa",
        "--out",
        "sw",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let warned = err.matches("stiffness[0] = 800 N/m is above").count();
    assert_eq!(warned, 1, "two runs share the warning, said once:\n{err}");
}

/// `-q` and `--quiet` as on `tactile run`: no progress line, the closing line still.
#[test]
fn a_quiet_sweep_says_no_progress() {
    let sb = Sandbox::new("sweep-q");
    let err = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).into_owned();
    let loud = sweep(&sb, "loud", &[]);
    assert!(err(&loud).contains("6/6 runs"), "{}", err(&loud));
    for (out, q) in [("q1", "-q"), ("q2", "--quiet")] {
        let o = sweep(&sb, out, &[q]);
        assert!(!err(&o).contains("runs,"), "{q}: {}", err(&o));
        assert!(String::from_utf8_lossy(&o.stdout).contains("tactile sweep: 6 runs"));
        assert_eq!(read(&sb, out, "sweep.csv"), read(&sb, "loud", "sweep.csv"));
    }
}

/// `--jobs` past 4 x the CPUs is capped, saying so; `--merge` into one of the folders
/// it merges (spelt otherwise) is refused with exit 2, naming it, the folder untouched.
#[test]
fn jobs_are_capped_and_a_merge_never_writes_into_its_input() {
    let sb = Sandbox::new("sweep-cap");
    let o = sweep(&sb, "all", &["--jobs", "100000"]);
    let err = String::from_utf8_lossy(&o.stderr);
    let cap: usize = err
        .split("--jobs 100000: capped at ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no cap said: {err}"));
    let cpus = std::thread::available_parallelism().map_or(1, usize::from);
    assert!((1..=4 * cpus).contains(&cap), "{cap} for {cpus} CPUs");
    sweep(&sb, "s1", &["--shard", "1/2"]);
    sweep(&sb, "s2", &["--shard", "2/2"]);
    let before = read(&sb, "s1", "sweep.csv");
    let o = sb.tactile(&["sweep", "--merge", "s1", "s2", "--out", "./s2/../s1"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("one of the folders merged") && err.contains("s1"),
        "{err}"
    );
    assert_eq!(read(&sb, "s1", "sweep.csv"), before, "s1 untouched");
}

/// A key written `+KEY` moves with the key before it, value for value; a value given
/// twice (however written), or two that give one scenario, is refused before any
/// run; a merge says why a run a folder holds is not whole.
#[test]
fn paired_keys_repeated_values_and_a_merge_that_says_why() {
    let sb = Sandbox::new("sweep-pairs");
    let s = sb.write("s.toml", &scenario(200));
    let s = s.to_str().expect("utf-8");
    let paired = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "sweep",
            s,
            "-q",
            "--set",
            "network.forward.delay=[0,0,0],[2,2,2],[5,5,5]",
            "--set",
            "+network.backward.delay=[0,0,0],[2,2,2],[5,5,5]",
            "--set",
            "control.kind=none,tdpa",
            "--out",
            out,
        ];
        args.extend_from_slice(extra);
        sb.tactile(&args)
    };
    let o = paired("p", &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = read(&sb, "p", "sweep.csv");
    let rows: Vec<Vec<String>> = table.lines().skip(1).map(cells).collect();
    assert_eq!(rows.len(), 6, "{table}");
    for (k, r) in rows.iter().enumerate() {
        let d = ["[0,0,0]", "[2,2,2]", "[5,5,5]"][k / 2];
        assert_eq!((r[2].as_str(), r[3].as_str()), (d, d), "{table}");
    }
    // The plots draw the pair by its first key.
    assert!(sb.path("p").join("sweep-position_rms_m.svg").exists());
    for set in [
        "control.kind=tdpa,tdpa",
        "control.kind=tdpa,\"tdpa\"",
        "network.forward.delay_ms=10,10.0",
        // Both 10 samples at 1 kHz: one scenario.
        "network.forward.delay_ms=10,10.0000001",
    ] {
        let o = sb.tactile(&["sweep", s, "--set", set, "--out", "dup"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(
            err.contains("are one value") || err.contains("would run the same scenario"),
            "{set}: {err}"
        );
        assert!(!sb.path("dup").join("run-0000").exists(), "{set}");
    }
    // Two slices, one with a run whose summary is damaged: merged, that run is named
    // with why, not called missing.
    for k in ["1/2", "2/2"] {
        let o = paired(&format!("shard{}", &k[..1]), &["--shard", k]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    std::fs::write(
        sb.path("shard2").join("run-0001").join("summary.json"),
        "{\"samples_",
    )
    .expect("damage");
    let o = sb.tactile(&["sweep", "--merge", "shard1", "shard2", "--out", "m"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("1 runs are whole in none of the folders")
            && err.contains("run-0001: its summary.json is unreadable (EOF while parsing"),
        "{err}"
    );
    assert_eq!(read(&sb, "m", "sweep.csv").lines().count(), 1 + 5);
}
