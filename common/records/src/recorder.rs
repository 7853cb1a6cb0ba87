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
/// at most a second old.
#[derive(Debug)]
pub struct Recorder<S, C> {
    writer: RecordWriter<Record<S, C>>,
    next_counters_ns: u64,
}

/// Counters are written this often, ns.
pub const COUNTERS_EVERY_NS: u64 = 1_000_000_000;

impl<S: Serialize, C: Serialize> Recorder<S, C> {
    /// Opens `ROLE.rec` in `dir` (afresh, or appended to with `append`).
    pub fn open(dir: &Path, role: Role, append: bool) -> Result<Self, WriteError> {
        let path = record_path(dir, role);
        let writer = RecordWriter::create(&path, append).map_err(|source| WriteError {
            action: "opening",
            path: path.display().to_string(),
            source,
        })?;
        Ok(Recorder {
            writer,
            next_counters_ns: now_ns() + COUNTERS_EVERY_NS,
        })
    }

    fn put(&mut self, r: &Record<S, C>) -> Result<(), WriteError> {
        self.writer.write(r).map_err(|source| WriteError {
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
        self.put(&Record::Start(start))
    }

    /// The run token this node joined.
    pub fn run(&mut self, token: u64) -> Result<(), WriteError> {
        tracing::info!("joined run {token:016x}");
        self.put(&Record::Run(token))
    }

    /// One sample's record.
    pub fn sample(&mut self, s: S) -> Result<(), WriteError> {
        self.put(&Record::Sample(s))
    }

    /// True once a second has passed since the counters were last written (then the
    /// node writes them with [`Recorder::counters`]).
    pub fn counters_due(&mut self) -> bool {
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
