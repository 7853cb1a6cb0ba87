//! A node that makes no progress: its process stopped (SIGSTOP, a job-control stop, a
//! debugger) while the run goes on.
//!
//! The kernel says it (`/proc/PID/stat`, state `T` or `t`). A node's record is no
//! sign: a node waits without writing for as long as its peers or its device take
//! (before the master's first sample the emulator and the slave write nothing), so
//! a record standing still is a wait as often as a freeze. A node that hangs while
//! it runs is the peers' to notice: the master's peer timeout breaks the loop.

use std::time::{Duration, Instant};

/// How long a node may stay stopped, by default, before the run counts it as frozen.
pub const DEFAULT_STALL: Duration = Duration::from_secs(5);

/// Since when a process has been seen stopped.
#[derive(Debug, Default)]
pub struct Progress {
    stopped_since: Option<Instant>,
}

impl Progress {
    /// Watches a process from now (just started or restarted).
    pub fn new() -> Progress {
        Progress::default()
    }

    /// How long process `pid` has been stopped, as of `now` (None while it runs).
    pub fn stopped_for(&mut self, pid: u32, now: Instant) -> Option<Duration> {
        if !is_stopped(pid) {
            self.stopped_since = None;
            return None;
        }
        let since = *self.stopped_since.get_or_insert(now);
        Some(now.saturating_duration_since(since))
    }

    /// Since when the process has been seen stopped, if it is (as of the last look).
    pub fn since(&self) -> Option<Instant> {
        self.stopped_since
    }
}

/// The state letter of process `pid` (`R`, `S`, `T`, ...), `?` if unknown.
fn state_letter(pid: u32) -> String {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    // The state follows the command's name, which is in parentheses and may hold any
    // character: read after the last `)`.
    stat.rfind(')')
        .and_then(|i| stat[i + 1..].split_whitespace().next())
        .unwrap_or("?")
        .to_string()
}

/// True if process `pid` is stopped (by a signal or a debugger).
pub fn is_stopped(pid: u32) -> bool {
    matches!(state_letter(pid).as_str(), "T" | "t")
}

/// A process's state as the kernel says it, in words.
pub fn state_of(pid: u32) -> String {
    match state_letter(pid).as_str() {
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
    fn a_stopped_process_is_named_stopped() {
        let mut child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .expect("sleep");
        let pid = rustix::process::Pid::from_child(&child);
        assert!(!is_stopped(child.id()), "{}", state_of(child.id()));
        rustix::process::kill_process(pid, rustix::process::Signal::STOP).expect("SIGSTOP");
        let mut seen = String::new();
        for _ in 0..100 {
            seen = state_of(child.id());
            if seen.starts_with("stopped") {
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let mut p = Progress::new();
        let t0 = Instant::now();
        assert_eq!(p.stopped_for(child.id(), t0), Some(Duration::ZERO));
        let later = p.stopped_for(child.id(), t0 + Duration::from_secs(3));
        rustix::process::kill_process(pid, rustix::process::Signal::CONT).expect("SIGCONT");
        std::thread::sleep(Duration::from_millis(50));
        let resumed = p.stopped_for(child.id(), t0 + Duration::from_secs(4));
        let _ = child.kill();
        let _ = child.wait();
        assert_eq!(seen, "stopped (SIGSTOP or a job-control stop)");
        assert_eq!(later, Some(Duration::from_secs(3)));
        assert_eq!(resumed, None, "running again");
    }
}
