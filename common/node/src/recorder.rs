//! A node's record as it runs: the writer with its bookkeeping (events into the log as
//! well, counters every second).

use crate::args::NodeError;
use crate::record::{peak_rss_kb, Event, Record, RecordWriter, Start, Stop, Totals};
use serde::Serialize;
use std::path::{Path, PathBuf};
use tactile_messages::clock::now_ns;
use tactile_messages::Role;

/// The record file of `role` in `dir`.
pub fn record_path(dir: &Path, role: Role) -> PathBuf {
    dir.join(format!("{role}.rec"))
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
    pub fn open(dir: &Path, role: Role, append: bool) -> Result<Self, NodeError> {
        let path = record_path(dir, role);
        let writer = RecordWriter::create(&path, append)
            .map_err(|e| NodeError::Failed(format!("opening {}: {e}", path.display())))?;
        Ok(Recorder {
            writer,
            next_counters_ns: now_ns() + COUNTERS_EVERY_NS,
        })
    }

    fn put(&mut self, r: &Record<S, C>) -> Result<(), NodeError> {
        self.writer.write(r).map_err(|e| {
            NodeError::Failed(format!("writing {}: {e}", self.writer.path().display()))
        })
    }

    /// The start of a segment.
    pub fn start(&mut self, start: Start) -> Result<(), NodeError> {
        tracing::info!(
            "start: {} of run {:?} ({} link, scenario {:?}, {} samples at {} Hz, {} {}, wake {} us early, poll {} us{})",
            start.role,
            start.prefix,
            start.link,
            start.scenario,
            start.samples,
            start.rate_hz,
            start.sched.policy,
            start.sched.priority,
            start.sched.wake_early_us,
            start.sched.poll_us,
            start.sched.cpu.map_or(String::new(), |c| format!(", CPU {c}"))
        );
        self.put(&Record::Start(start))
    }

    /// The run token this node joined.
    pub fn run(&mut self, token: u64) -> Result<(), NodeError> {
        tracing::info!("joined run {token:016x}");
        self.put(&Record::Run(token))
    }

    /// One sample's record.
    pub fn sample(&mut self, s: S) -> Result<(), NodeError> {
        self.put(&Record::Sample(s))
    }

    /// An event, logged and recorded.
    pub fn event(&mut self, sample: u64, what: impl Into<String>) -> Result<(), NodeError> {
        let what = what.into();
        tracing::info!("sample {sample}: {what}");
        self.put(&Record::Event(Event {
            sample,
            mono_ns: now_ns(),
            what,
        }))
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

    /// Writes the counters now.
    pub fn counters(&mut self, counters: C) -> Result<(), NodeError> {
        self.put(&Record::Counters(Totals {
            counters,
            peak_rss_kb: peak_rss_kb(),
        }))
    }

    /// The end of the segment: final counters, then `Stop`.
    pub fn stop(&mut self, counters: C, reason: &str) -> Result<(), NodeError> {
        self.counters(counters)?;
        tracing::info!("stop: {reason} (peak RSS {} kB)", peak_rss_kb());
        self.put(&Record::Stop(Stop {
            reason: reason.to_string(),
            mono_ns: now_ns(),
        }))
    }
}
