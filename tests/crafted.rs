//! Records crafted against the report: a run's records rewritten with the records
//! crate's own writer, rows repeated, renumbered past the run, moved out of their
//! place. The report reads each in bounded memory and time, answers a stop request
//! while it reads, and says in its text which part of the run a figure comes from.

use crate::util::{self, Sandbox};
use std::path::Path;
use std::process::Command;
use tactile_records::master::{MasterSample, MasterTotals};
use tactile_records::slave::{SlaveSample, SlaveTotals};
use tactile_records::{Record, RecordReader, RecordWriter};

/// Samples of the run the records are made from.
const SAMPLES: u64 = 2000;

/// Copies of one row in a crafted block: as many as a block may hold.
const COPIES: usize = tactile_records::block::MAX_ROWS;

/// Simulates a lockstep run of [`SAMPLES`] into `clean` and copies its records into
/// `bad`.
fn clean_and_copy(sb: &Sandbox) {
    let text = util::wall_delay().replace("samples = 8000", &format!("samples = {SAMPLES}"));
    let scenario = sb.write("s.toml", &text);
    sb.simulate(&scenario, "clean");
    std::fs::create_dir(sb.path("bad")).expect("folder");
    for role in ["master", "emulator", "slave"] {
        let name = format!("{role}.rec");
        std::fs::copy(sb.path("clean").join(&name), sb.path("bad").join(&name)).expect("copy");
    }
}

/// A sandbox named `name` with a clean run's records copied into `bad`, and the
/// path of `role`'s record there.
fn crafted(name: &str, role: &str) -> (Sandbox, std::path::PathBuf) {
    let sb = Sandbox::new(name);
    clean_and_copy(&sb);
    let rec = sb.path("bad").join(format!("{role}.rec"));
    (sb, rec)
}

/// `tactile report bad`, which must succeed within a minute: its text.
fn reported(sb: &Sandbox) -> String {
    let o = util::output_within(report(sb, "bad"), std::time::Duration::from_secs(60));
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    text
}

/// Every entry of the record at `path`, in file order.
fn entries<S, C>(path: &Path) -> Vec<Record<S, C>>
where
    S: serde::de::DeserializeOwned,
    C: serde::de::DeserializeOwned,
{
    let mut r = RecordReader::<Record<S, C>>::open(path).expect("a record");
    let mut all = Vec::new();
    while let Some(e) = r.next_record().expect("readable") {
        all.push(e);
    }
    all
}

/// Writes `all` afresh to `path`, `rows` sample rows a block.
fn rewrite<'a, S, C>(path: &Path, all: impl IntoIterator<Item = &'a Record<S, C>>, rows: usize)
where
    S: serde::Serialize + 'a,
    C: serde::Serialize + 'a,
{
    let mut w = RecordWriter::<Record<S, C>>::create(path, false).expect("writer");
    w.set_block_rows(rows);
    for e in all {
        w.write(e).expect("write");
    }
}

/// The first sample row of `all`.
fn first_row<S: Clone, C>(all: &[Record<S, C>]) -> S {
    all.iter()
        .find_map(|e| match e {
            Record::Sample(s) => Some(s.clone()),
            _ => None,
        })
        .expect("a sample row")
}

/// `blocks` blocks of [`COPIES`] copies of `row`, appended to the record at `path`.
fn append_copies<S: serde::Serialize, C: serde::Serialize>(path: &Path, row: &S, blocks: usize) {
    let mut w = RecordWriter::<Record<S, C>>::create(path, true).expect("writer");
    w.set_block_rows(COPIES);
    for _ in 0..blocks * COPIES {
        w.write_sample(row).expect("write");
    }
}

/// `tactile report` of folder `dir` in the sandbox.
fn report(sb: &Sandbox, dir: &str) -> Command {
    sb.command(&["report", dir])
}

/// Files a report left under a partial name in `dir`.
fn partials(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .expect("folder")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect()
}

/// Issue 51: 400 frames of 16,384 repeated rows made the report hold every copy
/// (2.49 GB). Rows of a sample already held are counted and dropped.
#[test]
fn a_record_of_repeated_rows_costs_the_report_no_memory() {
    let (sb, rec) = crafted("repeated", "slave");
    let row = first_row(&entries::<SlaveSample, SlaveTotals>(&rec));
    let blocks = 150;
    append_copies::<SlaveSample, SlaveTotals>(&rec, &row, blocks);
    let (status, peak_kb) = util::run_measured(report(&sb, "bad"));
    assert!(status.success(), "{status}");
    // The run's own report peaks at a few tens of MB; holding the copies took 1.6 kB
    // a row, about 4 GB here.
    assert!(peak_kb < 256 * 1024, "peak RSS {peak_kb} kB");
    let s = sb.json("bad", "summary.json");
    let node = &s["nodes"]["slave"];
    let copies = (blocks * COPIES) as u64;
    let left_out =
        node["duplicates"].as_u64().unwrap_or(0) + node["unjoined"].as_u64().unwrap_or(0);
    assert_eq!(left_out, copies, "{node}");
    assert_eq!(s["samples_sent"], SAMPLES);
    assert!(partials(&sb.path("bad")).is_empty());
}

/// Issue 51: one master row numbered 2^62 made the report walk every number up to
/// it (forever); 10^9 took 8 s and made the record end "after sample 1000000000".
#[test]
fn sample_numbers_past_the_run_are_counted_not_walked_to() {
    let (sb, rec) = crafted("pastrun", "master");
    let mut all = entries::<MasterSample, MasterTotals>(&rec);
    let mut far = |k: usize, n: u64| {
        let mut row = first_row(&all);
        if let MasterSample::Sent(s) = &mut row {
            s.n = n;
        }
        all.insert(k, Record::Sample(row));
    };
    far(5, 1 << 62);
    far(2000, 1_000_000_000);
    rewrite(&rec, &all, 100);
    let text = reported(&sb);
    let s = sb.json("bad", "summary.json");
    let node = &s["nodes"]["master"];
    assert_eq!(node["invalid"], 2, "{node}");
    assert_eq!(node["last_sample"], SAMPLES - 1, "{node}");
    assert!(
        text.contains("master: 2 sample rows of")
            && text.contains("2 numbered past the run's 2000 samples"),
        "{text}"
    );
    assert_eq!(
        sb.trace("bad"),
        sb.trace("clean"),
        "the run's rows, as they were"
    );
}

/// Records the report takes long to read, in `bad` of a sandbox named `name`: a
/// master row numbered 2^62 and 400 blocks of one slave row repeated before the
/// run's own rows.
fn long_to_read(name: &str) -> Sandbox {
    let (sb, rec) = crafted(name, "master");
    let mut all = entries::<MasterSample, MasterTotals>(&rec);
    let mut row = first_row(&all);
    if let MasterSample::Sent(s) = &mut row {
        s.n = 1 << 62;
    }
    all.insert(3, Record::Sample(row));
    rewrite(&rec, &all, 100);
    let slave = sb.path("bad").join("slave.rec");
    let all = entries::<SlaveSample, SlaveTotals>(&slave);
    let copy = Record::Sample(first_row(&all));
    let at = all
        .iter()
        .position(|e| matches!(e, Record::Sample(_)))
        .unwrap_or(0);
    let copies = std::iter::repeat_n(&copy, 400 * COPIES);
    rewrite(
        &slave,
        all[..at].iter().chain(copies).chain(&all[at..]),
        COPIES,
    );
    sb
}

/// Runs `cmd`, sends it SIGTERM once it answers one (its stop handler in place, just
/// before it reads the records) and checks it ends within 3 s with exit 130 and no
/// partial file in `dir`; its output.
fn stopped_at_once(mut cmd: Command, dir: &Path) -> std::process::Output {
    let child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("report");
    let term = rustix::process::Signal::TERM;
    util::wait_for(
        "the stop handler",
        std::time::Duration::from_secs(30),
        || util::catches(child.id(), term),
    );
    let pid = rustix::process::Pid::from_child(&child);
    rustix::process::kill_process(pid, term).expect("SIGTERM");
    let t = std::time::Instant::now();
    let o = util::wait_within(child, std::time::Duration::from_secs(60));
    let took = t.elapsed();
    assert_eq!(
        o.status.code(),
        Some(130),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        took < std::time::Duration::from_secs(3),
        "took {took:?} after SIGTERM"
    );
    assert!(partials(dir).is_empty(), "{:?}", partials(dir));
    o
}

/// A report reading a long record answers SIGTERM at once: exit 130, the report of
/// what it joined written whole, no partial file left. (Before, the walk to a row
/// numbered 2^62 never looked at the request.)
#[test]
fn a_stop_request_ends_a_report_reading_a_long_record() {
    let sb = long_to_read("stopread");
    stopped_at_once(report(&sb, "bad"), &sb.path("bad"));
    let s = sb.json("bad", "summary.json");
    assert_eq!(s["interrupted"], true);
    assert!(
        s["events"]
            .to_string()
            .contains("report cut short at sample"),
        "{}",
        s["events"]
    );
}

/// Issue 51: `report --mcap-only` installed no stop handler: SIGTERM killed it and
/// left run.mcap.partial. It stops as the full report does (exit 130, no partial
/// file), and writes no run.mcap of part of the run.
#[test]
fn a_stop_request_ends_an_mcap_only_report_leaving_no_file() {
    let sb = long_to_read("stopmcap");
    let o = stopped_at_once(
        sb.command(&["report", "bad", "--mcap-only"]),
        &sb.path("bad"),
    );
    assert!(!sb.path("bad").join("run.mcap").exists());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("run.mcap not written"), "{err}");
}

/// The rows of `trace`'s column `name` that are zero.
fn zeros(trace: &str, name: &str) -> usize {
    util::column(trace, name)
        .iter()
        .filter(|v| **v == 0.0)
        .count()
}

/// Issue 51: one slave block renumbered far ahead left the slave's columns empty
/// from sample 25 on, and the text gave tracking from 25 samples without a word.
#[test]
fn a_block_renumbered_far_ahead_costs_its_rows_and_the_text_says_so() {
    let (sb, rec) = crafted("renumbered", "slave");
    let mut all = entries::<SlaveSample, SlaveTotals>(&rec);
    let mut moved = 0;
    for e in &mut all {
        if let Record::Sample(SlaveSample::Step(s, ..)) = e {
            if (25..50).contains(&s.n) {
                s.n += 1_000_000;
                moved += 1;
            }
        }
    }
    assert_eq!(moved, 25);
    rewrite(&rec, &all, 25);
    let text = reported(&sb);
    // v(n) as the slave received it: zero where the slave's columns are empty.
    let (clean, bad) = (sb.trace("clean"), sb.trace("bad"));
    let empty = zeros(&clean, "v_3");
    assert_eq!(
        zeros(&bad, "v_3"),
        empty + 25,
        "only the renumbered block's samples lack the slave's columns"
    );
    let s = sb.json("bad", "summary.json");
    assert_eq!(
        s["nodes"]["slave"]["invalid"], 25,
        "{}",
        s["nodes"]["slave"]
    );
    let line = text
        .lines()
        .find(|l| l.starts_with("warning: tracking over "))
        .unwrap_or_else(|| panic!("no warning on tracking: {text}"));
    let tracked: usize = line["warning: tracking over ".len()..]
        .split(' ')
        .next()
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    let whole = SAMPLES as usize - 25;
    assert!((whole - empty..=whole).contains(&tracked), "{line}");
    assert!(
        line.contains(&format!(
            "of {SAMPLES} samples: 0 of the slave's rows unjoined, 25 invalid"
        )),
        "{line}"
    );
}

/// Issue 51: two blocks of the master's swapped made the trace say "sent 1570" where
/// the master's own counters said 2000. A block out of its place joins where it
/// belongs.
#[test]
fn swapped_blocks_join_as_written_and_counts_agree() {
    let sb = Sandbox::new("swappedblk");
    clean_and_copy(&sb);
    for role in ["master", "slave"] {
        let rec = sb.path("bad").join(format!("{role}.rec"));
        if role == "master" {
            let mut all = entries::<MasterSample, MasterTotals>(&rec);
            swap_rows(&mut all, 200, 3000, 100);
            rewrite(&rec, &all, 100);
        } else {
            let mut all = entries::<SlaveSample, SlaveTotals>(&rec);
            swap_rows(&mut all, 300, 1700, 50);
            rewrite(&rec, &all, 50);
        }
    }
    let text = reported(&sb);
    assert!(
        text.contains(&format!("samples: sent {SAMPLES},")),
        "{text}"
    );
    assert!(!text.contains("warning:"), "{text}");
    assert_eq!(sb.trace("bad"), sb.trace("clean"));
}

/// Swaps the `len` sample rows from the `a`-th with those from the `b`-th (entries
/// between them stay where they are).
fn swap_rows<S, C>(all: &mut [Record<S, C>], a: usize, b: usize, len: usize) {
    let at: Vec<usize> = all
        .iter()
        .enumerate()
        .filter(|(_, e)| matches!(e, Record::Sample(_)))
        .map(|(k, _)| k)
        .collect();
    for i in 0..len {
        all.swap(at[a + i], at[b + i]);
    }
}

/// Issue 51: a master record of samples 0 and [`JUMP`] only (its start claiming
/// them) beside a slave record of every sample between: the slave's source read for
/// the far sample with its floor still at 1, holding every row between (1.6 kB a
/// row, memory in proportion to the file). They are counted as read, not held.
#[test]
fn a_jump_of_the_masters_spine_holds_no_rows_in_between() {
    const JUMP: u64 = 400_000;
    let (sb, rec) = crafted("spinejump", "master");
    let mut all = entries::<MasterSample, MasterTotals>(&rec);
    all.retain_mut(|e| match e {
        Record::Start(s) => {
            s.samples = JUMP + 1;
            true
        }
        Record::Sample(s) => {
            let n = match s {
                MasterSample::Sent(x) => &mut x.n,
                MasterSample::Answer(x) => &mut x.n,
                MasterSample::Miss(x) => &mut x.n,
            };
            if *n == 1 {
                *n = JUMP;
            }
            *n == 0 || *n == JUMP
        }
        _ => true,
    });
    rewrite(&rec, &all, 100);
    let slave = sb.path("bad").join("slave.rec");
    let all = entries::<SlaveSample, SlaveTotals>(&slave);
    let row = first_row(&all);
    let between = (0..JUMP).map(|n| {
        let mut r = row.clone();
        if let SlaveSample::Step(s, ..) = &mut r {
            s.n = n;
        }
        Record::Sample(r)
    });
    let at = all
        .iter()
        .position(|e| matches!(e, Record::Sample(_)))
        .unwrap_or(0);
    let rest: Vec<_> = all[at..]
        .iter()
        .filter(|e| !matches!(e, Record::Sample(_)))
        .cloned()
        .collect();
    let crafted: Vec<_> = all[..at]
        .iter()
        .cloned()
        .chain(between)
        .chain(rest)
        .collect();
    rewrite(&slave, &crafted, COPIES);
    let (status, peak_kb) = util::run_measured(report(&sb, "bad"));
    assert!(status.success(), "{status}");
    // Held, the rows between took about 640 MB.
    assert!(peak_kb < 256 * 1024, "peak RSS {peak_kb} kB");
    let s = sb.json("bad", "summary.json");
    let node = &s["nodes"]["slave"];
    assert_eq!(node["unjoined"], JUMP - 1, "{node}");
}

/// Issue 51: the sample count was the largest any start claimed, so a slave.rec whose
/// start says 2^63 lifted it for every node and its row numbered 10^9 was valid again
/// (the record ended "after sample 1000000000"). The master's start sets it; the
/// slave's claim is warned of.
#[test]
fn a_start_claiming_more_samples_lifts_no_limit() {
    let (sb, rec) = crafted("startclaim", "slave");
    let mut all = entries::<SlaveSample, SlaveTotals>(&rec);
    for e in &mut all {
        if let Record::Start(s) = e {
            s.samples = 1 << 63;
        }
    }
    let mut row = first_row(&all);
    if let SlaveSample::Step(s, ..) = &mut row {
        s.n = 1_000_000_000;
    }
    all.insert(all.len() - 1, Record::Sample(row));
    rewrite(&rec, &all, 100);
    let text = reported(&sb);
    let s = sb.json("bad", "summary.json");
    let node = &s["nodes"]["slave"];
    assert_eq!(node["invalid"], 1, "{node}");
    assert_eq!(node["last_sample"], SAMPLES - 1, "{node}");
    assert!(
        text.contains(&format!(
            "slave: its start claims {} samples where the run's count applied is {SAMPLES}",
            1u64 << 63
        )) && text.contains(&format!("1 numbered past the run's {SAMPLES} samples")),
        "{text}"
    );
}
