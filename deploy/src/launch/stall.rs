//! A node that makes no progress: its record stops growing while its process lives.
//!
//! Every node's loop writes its record at least once a second (a sample, or the
//! counters when no sample came), so a record that stands still for longer than the
//! run's stall limit belongs to a node that no longer runs its loop: stopped by SIGSTOP
//! or a debugger, or hung. Before its loop starts a node may wait (for its peers, its
//! device) without writing: a record is watched only once it has grown since the
//! process started.

use std::path::PathBuf;
use std::time::{Duration, Instant};

/// How long a node may make no progress, by default, before the run counts it as
/// frozen: five times the longest a running loop goes without writing its record.
pub const DEFAULT_STALL: Duration = Duration::from_secs(5);

/// The growth of one node's record.
#[derive(Debug)]
pub struct Progress {
    record: PathBuf,
    len: u64,
    since: Instant,
    moving: bool,
}

fn len_of(path: &std::path::Path) -> u64 {
    std::fs::metadata(path).map_or(0, |m| m.len())
}

impl Progress {
    /// Watches `record` from now (a node just started or restarted).
    pub fn new(record: PathBuf) -> Progress {
        Progress {
            len: len_of(&record),
            record,
            since: Instant::now(),
            moving: false,
        }
    }

    /// How long the record has stood still, once it has moved at all; None while it
    /// grows or has not started to.
    pub fn still_for(&mut self, now: Instant) -> Option<Duration> {
        let len = len_of(&self.record);
        if len != self.len {
            (self.len, self.since, self.moving) = (len, now, true);
            return None;
        }
        self.moving
            .then(|| now.saturating_duration_since(self.since))
    }
}

/// A process's state as the kernel says it (`/proc/PID/stat`), in words.
pub fn state_of(pid: u32) -> String {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    // The state follows the command's name, which is in parentheses and may hold any
    // character: read after the last `)`.
    let state = stat
        .rfind(')')
        .and_then(|i| stat[i + 1..].split_whitespace().next())
        .unwrap_or("?");
    match state {
        "T" => "stopped (SIGSTOP or a job-control stop)".into(),
        "t" => "stopped by a debugger".into(),
        "D" => "in uninterruptible sleep (waiting for a disk or a device)".into(),
        "Z" => "a zombie".into(),
        "R" => "running".into(),
        "S" => "sleeping".into(),
        other => format!("in state {other}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_is_watched_once_it_moves_and_stands_still_from_its_last_growth() {
        let dir = tempfile::tempdir().expect("tempdir");
        let rec = dir.path().join("slave.rec");
        std::fs::write(&rec, b"start").expect("write");
        let mut p = Progress::new(rec.clone());
        let t0 = Instant::now();
        assert_eq!(
            p.still_for(t0 + Duration::from_secs(60)),
            None,
            "not moved yet"
        );
        std::fs::write(&rec, b"start, then a sample").expect("write");
        assert_eq!(p.still_for(t0 + Duration::from_secs(61)), None);
        assert_eq!(
            p.still_for(t0 + Duration::from_secs(64)),
            Some(Duration::from_secs(3))
        );
    }

    #[test]
    fn a_stopped_process_is_named_stopped() {
        let mut child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .expect("sleep");
        let pid = rustix::process::Pid::from_child(&child);
        assert_eq!(state_of(child.id()), "sleeping");
        rustix::process::kill_process(pid, rustix::process::Signal::STOP).expect("SIGSTOP");
        let mut seen = String::new();
        for _ in 0..100 {
            seen = state_of(child.id());
            if seen.starts_with("stopped") {
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = child.kill();
        let _ = child.wait();
        assert_eq!(seen, "stopped (SIGSTOP or a job-control stop)");
    }
}
