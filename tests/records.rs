//! Records that survive what happens to files: a node killed mid-frame and restarted
//! into its torn record, and bytes corrupted in the middle of a record. Every whole
//! frame is read (a frame of samples is a block: at most 50 ms of them, 50 at 1 kHz);
//! the report says what was skipped.

use crate::util;

use std::path::Path;
use tactile_records::slave::{SlaveSample, SlaveTotals};
use tactile_records::{Record, RecordReader};
use util::{column, finish, kill_once_recorded, start_node, Sandbox};

type SlaveRecord = Record<SlaveSample, SlaveTotals>;

/// Every record of a slave's file, with the bytes and stretches skipped.
fn slave_records(path: &Path) -> (Vec<SlaveRecord>, (u64, u64)) {
    let mut r = RecordReader::<SlaveRecord>::open(path).expect("a record");
    let mut all = Vec::new();
    while let Some(rec) = r.next_record().expect("readable") {
        all.push(rec);
    }
    (all, r.damaged())
}

/// The issue's reproduction: three nodes by hand at 1 kHz, the slave killed with
/// SIGKILL, seven bytes cut off its record, the slave restarted with `--append`, and
/// the report: both segments' whole frames are there, nothing lost but the torn one.
#[test]
fn a_torn_record_appended_to_keeps_every_whole_frame_of_both_segments() {
    let sb = Sandbox::new("tornappend");
    let scenario = sb.write("s.toml", &util::paper_1khz(5000));
    let master = start_node(&sb, "master", &scenario, "m", &[]);
    let emulator = start_node(&sb, "emulator", &scenario, "e", &[]);
    let slave = start_node(&sb, "slave", &scenario, "s", &[]);
    let rec = sb.path("s").join("slave.rec");
    kill_once_recorded(slave, &rec, 600);
    let (before, damaged) = slave_records(&rec);
    assert_eq!(damaged, (0, 0), "a SIGKILL between writes tears nothing");
    let len = std::fs::metadata(&rec).expect("record").len();
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(&rec)
        .expect("open");
    f.set_len(len - 7).expect("cut");
    drop(f);
    let (torn, damaged) = slave_records(&rec);
    // The last frame is a block of at most 50 samples (50 ms at 1 kHz) or one entry.
    let lost = before.len() - torn.len();
    assert!((1..=50).contains(&lost), "{lost} records lost");
    assert_eq!(
        torn[..],
        before[..torn.len()],
        "only the torn frame is lost"
    );
    assert_eq!(damaged.1, 1, "the torn tail is one damaged stretch");
    let slave = start_node(&sb, "slave", &scenario, "s", &["--append"]);
    for (role, child) in [("slave", slave), ("master", master), ("emulator", emulator)] {
        let (code, err) = finish(child);
        assert_eq!(code, Some(0), "{role}: {err}");
    }
    let (after, damaged) = slave_records(&rec);
    assert_eq!(damaged, (0, 0), "the append trimmed the torn tail first");
    assert_eq!(after[..torn.len()], torn[..], "the first segment is intact");
    let starts = after
        .iter()
        .filter(|r| matches!(r, Record::Start(_)))
        .count();
    assert_eq!(starts, 2, "two segments");
    let o = sb.tactile(&["report", "m", "e", "s", "--out", "r"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = sb.json("r", "summary.json");
    let node = &s["nodes"]["slave"];
    assert_eq!(node["pids"].as_array().map(Vec::len), Some(2), "{node}");
    assert_eq!(node["damaged_stretches"], 0, "{node}");
    // Every step either segment recorded is in the trace.
    let steps: Vec<u64> = after
        .iter()
        .filter_map(|r| match r {
            Record::Sample(SlaveSample::Step(s, ..)) => Some(s.n),
            _ => None,
        })
        .collect();
    let v3 = column(&sb.trace("r"), "v_3");
    let missing: Vec<&u64> = steps
        .iter()
        .filter(|n| v3.get(**n as usize).is_none_or(|v| *v == 0.0))
        .collect();
    assert!(
        missing.is_empty(),
        "steps recorded but not reported: {missing:?}"
    );
    sb.assert_no_leftover_processes();
}

/// Inverts 20 bytes in the middle of the record `rec`.
fn corrupt_middle(rec: &Path) {
    let mut bytes = std::fs::read(rec).expect("record");
    let mid = bytes.len() / 2;
    for b in &mut bytes[mid..mid + 20] {
        *b = !*b;
    }
    std::fs::write(rec, &bytes).expect("write");
}

/// Bytes corrupted in the middle of a record cost the frames they touch, not the
/// report: the rest of the trace is what it was, and the summary says what it skipped.
#[test]
fn corrupted_bytes_mid_record_cost_only_their_frames() {
    let sb = Sandbox::new("corrupt");
    let scenario = sb.write("s.toml", &util::wall_delay());
    sb.simulate(&scenario, "clean");
    let clean = sb.trace("clean");
    std::fs::create_dir(sb.path("bad")).expect("folder");
    for role in ["master", "emulator", "slave"] {
        let from = sb.path("clean").join(format!("{role}.rec"));
        std::fs::copy(from, sb.path("bad").join(format!("{role}.rec"))).expect("copy");
    }
    corrupt_middle(&sb.path("bad").join("slave.rec"));
    let o = sb.tactile(&["report", "bad"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("node slave: record damaged:"), "{text}");
    let s = sb.json("bad", "summary.json");
    assert_eq!(s["nodes"]["slave"]["damaged_stretches"], 1);
    let lost = s["nodes"]["slave"]["damaged_bytes"]
        .as_u64()
        .expect("bytes");
    // A block of the slave's is 50 steps, a few kB (two if the bytes straddle them).
    assert!(
        (20..20_000).contains(&lost),
        "{lost} bytes skipped for 20 corrupted"
    );
    let damaged = sb.trace("bad");
    let changed = clean
        .lines()
        .zip(damaged.lines())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(clean.lines().count(), damaged.lines().count());
    assert!((1..=100).contains(&changed), "{changed} rows differ");
    // The master's record damaged too: its lost samples are gaps, the rest reported.
    corrupt_middle(&sb.path("bad").join("master.rec"));
    let o = sb.tactile(&["report", "bad"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = sb.json("bad", "summary.json");
    assert_eq!(
        s["nodes"]["master"]["damaged_stretches"], 1,
        "{}",
        s["nodes"]["master"]
    );
    // A damaged block takes its samples out: a Sent's row leaves the trace, an
    // Answer's row stays, marked not received (a block holds both, 50 samples).
    let bad = sb.trace("bad");
    let rows = bad.lines().count();
    let all = clean.lines().count();
    let unreceived = |t: &str| {
        util::column(t, "received")
            .iter()
            .filter(|r| **r == 0.0)
            .count()
    };
    let gone = all - rows + unreceived(&bad) - unreceived(&clean);
    assert!(
        rows + 100 >= all && (1..=100).contains(&gone),
        "{rows} rows of {all}, {gone} samples lost"
    );
}

/// Copies the three records of `from` into a new folder `to`, under `names` (a
/// record's file name by role: master, emulator, slave).
fn copy_records(sb: &Sandbox, from: &str, to: &str, names: [&str; 3]) {
    std::fs::create_dir(sb.path(to)).expect("folder");
    for (role, name) in ["master", "emulator", "slave"].iter().zip(names) {
        if name.is_empty() {
            continue;
        }
        let src = sb.path(from).join(format!("{role}.rec"));
        std::fs::copy(src, sb.path(to).join(format!("{name}.rec"))).expect("copy");
    }
}

/// One bit flipped in the master's first frame (its start, which holds the scenario)
/// costs that frame: the scenario is read from another node's start, every sample is
/// reported, and the summary says a start was lost.
#[test]
fn a_damaged_first_frame_costs_only_that_frame() {
    let sb = Sandbox::new("firstframe");
    let scenario = sb.write("s.toml", &util::wall_delay());
    sb.simulate(&scenario, "clean");
    copy_records(&sb, "clean", "bad", ["master", "emulator", "slave"]);
    let rec = sb.path("bad").join("master.rec");
    let mut bytes = std::fs::read(&rec).expect("record");
    // Past the magic (8) and the frame's header (12): inside the start's body.
    bytes[8 + 12 + 40] ^= 0x10;
    std::fs::write(&rec, &bytes).expect("write");
    let o = sb.tactile(&["report", "bad"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        sb.trace("bad"),
        sb.trace("clean"),
        "every sample reported alike"
    );
    let s = sb.json("bad", "summary.json");
    assert_eq!(s["nodes"]["master"]["damaged_stretches"], 1);
    let events = s["events"].to_string();
    assert!(
        events.contains("master: 1 segment start(s) lost to damage"),
        "{events}"
    );
    assert_eq!(s["master"], sb.json("clean", "summary.json")["master"]);
}

/// Records under each other's names are refused, naming the file and what it holds;
/// a missing record is named in the summary.
#[test]
fn records_are_checked_by_their_content_and_a_missing_one_is_named() {
    let sb = Sandbox::new("swapped");
    let scenario = sb.write("s.toml", &util::wall_delay());
    sb.simulate(&scenario, "clean");
    copy_records(&sb, "clean", "swapped", ["master", "slave", "emulator"]);
    let o = sb.tactile(&["report", "swapped"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("emulator.rec holds the slave's record, not the emulator's"),
        "{err}"
    );
    copy_records(&sb, "clean", "noslave", ["master", "emulator", ""]);
    let o = sb.tactile(&["report", "noslave"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let events = sb.json("noslave", "summary.json")["events"].to_string();
    assert!(
        events.contains("slave: no slave.rec among the records reported"),
        "{events}"
    );
}

/// In-process runs of different scenarios carry different run tokens, so their
/// records are not joined into one report: the master's and emulator's of one run
/// beside the slave's of another (another seed) are refused, naming the runs. Two
/// runs of one scenario give the same token (their traces stay byte-identical).
#[test]
fn records_of_different_in_process_runs_are_not_joined() {
    let sb = Sandbox::new("mixedruns");
    let a = sb.write("a.toml", &util::wall_delay());
    let b = sb.write(
        "b.toml",
        &util::wall_delay().replace("seed = 1", "seed = 7"),
    );
    sb.simulate(&a, "a");
    sb.simulate(&a, "a2");
    sb.simulate(&b, "b");
    let token = |run: &str| sb.json(run, "summary.json")["run"].clone();
    assert_eq!(token("a"), token("a2"), "one scenario, one token");
    assert_ne!(token("a"), token("b"), "another seed, another token");
    std::fs::create_dir(sb.path("mix")).expect("folder");
    for (role, from) in [("master", "a"), ("emulator", "a"), ("slave", "b")] {
        let name = format!("{role}.rec");
        std::fs::copy(sb.path(from).join(&name), sb.path("mix").join(&name)).expect("copy");
    }
    let o = sb.tactile(&["report", "mix"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("not one run"), "{err}");
}
