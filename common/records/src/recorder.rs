//! A node's record as it runs: the writer with its bookkeeping (events into the log as
//! well, counters every second).

use crate::entry::{Event, Record, Start, Stop, Totals};
use crate::RecordWriter;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tactile_messages::clock::now_ns;
use tactile_messages::Role;

/// The record file of `role` in `dir`.
pub fn record_path(dir: &Path, role: Role) -> PathBuf {
    dir.join(format!("{role}.rec"))
}

/// A record that could not be opened or written: the file and why.
#[derive(Debug, thiserror::Error)]
#[error("{action} {path}: {source}")]
pub struct WriteError {
    /// `opening` or `writing`.
    pub action: &'static str,
    /// The record file.
    pub path: String,
    /// Why.
    pub source: std::io::Error,
}

/// Where a loop's handlers say what happened to them: the record (and the log).
pub trait Events {
    /// Records `what` happened at sample `sample` (and logs it).
    fn event(&mut self, sample: u64, what: &str) -> Result<(), WriteError>;
}

/// A node's record writer with its bookkeeping: events go to the log as well, and the
/// counters are written every second, so a node killed at any moment leaves counters
/// at most a second old (and up to 10 ms of calls: [`counters_clock_every`]).
#[derive(Debug)]
pub struct Recorder<S, C> {
    writer: RecordWriter<Record<S, C>>,
    next_counters_ns: u64,
    /// [`Recorder::counters_due`] reads the clock at one call in `clock_every`
    /// (10 ms of samples, set by [`Recorder::start`]): a clock read a sample took
    /// about 1 % of the in-process run's time.
    clock_every: u32,
    /// Calls of [`Recorder::counters_due`] left until it reads the clock (at least 1).
    calls_left: u32,
    /// With `--append`: where the existing record ended and the runs it holds, so a
    /// node that turns out to have joined another run takes its segment back out.
    appended: Option<(u64, Vec<u64>)>,
    /// Set once the segment was taken back out: nothing more is written to the file.
    withdrawn: bool,
    role: Role,
}

/// Rows a block of `role`'s samples holds: 50 ms of samples at `rate_hz` (the master
/// writes two rows a sample, what it sent and the answer or miss; the emulator two,
/// a passage each way; the slave one).
pub fn block_rows(role: Role, rate_hz: f64) -> usize {
    let per_sample = if role == Role::Slave { 1 } else { 2 };
    let samples = (rate_hz * crate::file::BLOCK_NS as f64 * 1e-9).floor();
    // Any rate: a finite positive count, at least one sample.
    let samples = if samples.is_finite() {
        samples.clamp(1.0, 1e6) as usize
    } else {
        1
    };
    (samples * per_sample).min(crate::block::MAX_ROWS)
}

/// Counters are written this often, ns.
pub const COUNTERS_EVERY_NS: u64 = 1_000_000_000;

/// How many calls of [`Recorder::counters_due`] share one clock read at `rate_hz`:
/// 10 ms of samples, at least one. A node calls it about once a sample it handles
/// (the emulator twice), so counters come late by about 10 ms of calls at most: a
/// node that gets fewer calls (a slave under `loss`) by that many calls.
pub fn counters_clock_every(rate_hz: f64) -> u32 {
    let calls = (rate_hz * 0.01).floor();
    if calls.is_finite() {
        calls.clamp(1.0, 1000.0) as u32
    } else {
        1
    }
}

impl<S: Serialize, C: Serialize> Recorder<S, C> {
    /// Opens `ROLE.rec` in `dir` (afresh, or appended to with `append`).
    pub fn open(dir: &Path, role: Role, append: bool) -> Result<Self, WriteError> {
        let path = record_path(dir, role);
        let opening = |source| WriteError {
            action: "opening",
            path: path.display().to_string(),
            source,
        };
        let writer = RecordWriter::create(&path, append).map_err(opening)?;
        let appended = if append {
            let end = std::fs::metadata(&path).map_err(opening)?.len();
            Some((end, crate::file::runs_in(&path)))
        } else {
            None
        };
        Ok(Recorder {
            writer,
            next_counters_ns: now_ns() + COUNTERS_EVERY_NS,
            clock_every: 1,
            calls_left: 1,
            appended,
            withdrawn: false,
            role,
        })
    }

    fn put(&mut self, r: &Record<S, C>) -> Result<(), WriteError> {
        self.writing(|w| w.write(r))
    }

    /// Writes with `write`, unless the segment was taken back out; an error names the
    /// file.
    fn writing(
        &mut self,
        write: impl FnOnce(&mut RecordWriter<Record<S, C>>) -> std::io::Result<()>,
    ) -> Result<(), WriteError> {
        if self.withdrawn {
            return Ok(());
        }
        write(&mut self.writer).map_err(|source| WriteError {
            action: "writing",
            path: self.writer.path().display().to_string(),
            source,
        })
    }

    /// The start of a segment.
    pub fn start(&mut self, start: Start) -> Result<(), WriteError> {
        let s = &start.sched;
        tracing::info!(
            "start: {} of run {:?} ({} link, scenario {:?}, {} samples at {} Hz, {} {}, wake {} us early, poll {} us{})",
            start.role,
            start.prefix,
            start.link,
            start.scenario,
            start.samples,
            start.rate_hz,
            s.policy,
            s.priority,
            s.wake_early_us,
            s.poll_us,
            s.cpu.map_or(String::new(), |c| format!(", CPU {c}"))
        );
        self.writer
            .set_block_rows(block_rows(self.role, start.rate_hz));
        self.clock_every = counters_clock_every(start.rate_hz);
        self.put(&Record::Start(start))
    }

    /// The run token this node joined.
    /// Appended to a record of another run, the segment is taken back out (the other
    /// run's record left as it was) and the node fails: one record holds one run.
    pub fn run(&mut self, token: u64) -> Result<(), WriteError> {
        if let Some((end, runs)) = &self.appended {
            if !runs.is_empty() && !runs.contains(&token) {
                let shown: Vec<String> = runs.iter().map(|t| format!("{t:016x}")).collect();
                let path = self.writer.path().display().to_string();
                let undo = self.writer.truncate(*end);
                self.withdrawn = true;
                return Err(WriteError {
                    action: "appending to",
                    path,
                    source: std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        format!(
                            "it is the record of run {}, and this node joined run {token:016x}: \
                             --append continues a record of the same run only (give another --out){}",
                            shown.join(", "),
                            undo.err().map_or(String::new(), |e| format!(
                                "; taking this segment back out failed: {e}"
                            ))
                        ),
                    ),
                });
            }
        }
        tracing::info!("joined run {token:016x}");
        self.put(&Record::Run(token))
    }

    /// One sample's record, encoded from where it is: a sample is hundreds of bytes,
    /// and wrapping it in a [`Record`] first copied it once more.
    pub fn sample(&mut self, s: &S) -> Result<(), WriteError> {
        self.writing(|w| w.write_sample(s))
    }

    /// True once a second has passed since the counters were last written (then the
    /// node writes them with [`Recorder::counters`]).
    pub fn counters_due(&mut self) -> bool {
        self.calls_left -= 1;
        if self.calls_left > 0 {
            return false;
        }
        self.calls_left = self.clock_every;
        let now = now_ns();
        if now < self.next_counters_ns {
            return false;
        }
        self.next_counters_ns = now + COUNTERS_EVERY_NS;
        true
    }

    /// Writes the counters now, with the process's peak resident set size so far.
    pub fn counters(&mut self, counters: C, peak_rss_kb: u64) -> Result<(), WriteError> {
        self.put(&Record::Counters(Totals {
            counters,
            peak_rss_kb,
        }))
    }

    /// The end of the segment: final counters, then `Stop`.
    pub fn stop(&mut self, counters: C, peak_rss_kb: u64, reason: &str) -> Result<(), WriteError> {
        self.counters(counters, peak_rss_kb)?;
        tracing::info!("stop: {reason} (peak RSS {peak_rss_kb} kB)");
        self.put(&Record::Stop(Stop {
            reason: reason.to_string(),
            mono_ns: now_ns(),
        }))
    }
}

impl<S: Serialize, C: Serialize> Events for Recorder<S, C> {
    fn event(&mut self, sample: u64, what: &str) -> Result<(), WriteError> {
        tracing::info!("sample {sample}: {what}");
        self.put(&Record::Event(Event {
            sample,
            mono_ns: now_ns(),
            what: what.to_string(),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Rec = Recorder<u64, u64>;

    fn segment(dir: &Path, append: bool, run: u64) -> Result<(), WriteError> {
        let mut r = Rec::open(dir, Role::Slave, append)?;
        let joined = r.run(run);
        // A node that failed still ends its segment: nothing of it may reach the file.
        r.sample(&run)?;
        r.stop(0, 0, "failed")?;
        joined
    }

    #[test]
    fn blocks_hold_50_ms_and_never_more_than_a_reader_accepts() {
        assert_eq!(block_rows(Role::Master, 1000.0), 100);
        assert_eq!(block_rows(Role::Slave, 1000.0), 50);
        assert_eq!(block_rows(Role::Emulator, 10_000.0), 1000);
        assert_eq!(block_rows(Role::Slave, 1.0), 1);
        assert_eq!(block_rows(Role::Master, 1e9), crate::block::MAX_ROWS);
        assert_eq!(block_rows(Role::Master, f64::NAN), 2);
    }

    #[test]
    fn counters_are_due_at_the_first_clock_read_past_the_second() {
        assert_eq!(counters_clock_every(1000.0), 10);
        assert_eq!(counters_clock_every(250.0), 2);
        assert_eq!(counters_clock_every(10.0), 1);
        assert_eq!(counters_clock_every(1e9), 1000);
        assert_eq!(counters_clock_every(f64::NAN), 1);
        let dir = tempfile::tempdir().expect("tempdir");
        let mut r = Rec::open(dir.path(), Role::Master, false).expect("open");
        // Until the rate is known, every call reads the clock.
        r.next_counters_ns = 0;
        assert!(r.counters_due());
        r.next_counters_ns = 0;
        assert!(r.counters_due());
        // At 1 kHz, one call in ten reads the clock: overdue counters wait for it.
        r.clock_every = counters_clock_every(1000.0);
        r.next_counters_ns = 0;
        assert!(r.counters_due());
        r.next_counters_ns = 0;
        let due: Vec<usize> = (1..=20).filter(|_| r.counters_due()).collect();
        assert_eq!(due, [10]);
    }

    #[test]
    fn a_second_writer_of_a_record_is_refused_and_cuts_nothing() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut first = Rec::open(dir.path(), Role::Master, false).expect("first");
        first.run(3).expect("run");
        let path = record_path(dir.path(), Role::Master);
        let before = std::fs::read(&path).expect("record");
        let e = Rec::open(dir.path(), Role::Master, false).expect_err("second");
        assert!(
            e.to_string()
                .contains("another process is writing this record"),
            "{e}"
        );
        assert_eq!(std::fs::read(&path).expect("record"), before);
        drop(first);
        Rec::open(dir.path(), Role::Master, false).expect("free again");
    }

    #[test]
    fn an_append_into_another_runs_record_is_refused_and_leaves_it_as_it_was() {
        let dir = tempfile::tempdir().expect("tempdir");
        segment(dir.path(), false, 1).expect("first run");
        let path = record_path(dir.path(), Role::Slave);
        let before = std::fs::read(&path).expect("record");
        let e = segment(dir.path(), true, 2).expect_err("another run");
        let said = e.to_string();
        assert!(
            said.contains("it is the record of run 0000000000000001, and this node joined run 0000000000000002"),
            "{said}"
        );
        assert_eq!(std::fs::read(&path).expect("record"), before);
        // The same run continues.
        segment(dir.path(), true, 1).expect("same run");
        assert_eq!(crate::file::runs_in(&path), vec![1]);
        assert!(std::fs::read(&path).expect("record").len() > before.len());
    }
}
