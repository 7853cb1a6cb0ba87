//! One node program under supervision: its process, how it ended, its log's last
//! lines (the launcher's words when a node dies).

use super::stall::Progress;
use signal_hook::consts::{SIGINT, SIGTERM};
use std::path::Path;
use std::process::{Child, ExitStatus};
use std::time::{Duration, Instant};
use tactile_messages::Role;
use tactile_runtime::exit::EXIT_INTERRUPTED;

/// How a child process ended, in words.
pub fn describe(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(c), _) => format!("exited with status {c}"),
        (None, Some(s)) => format!("was killed by signal {s}"),
        _ => "ended".to_string(),
    }
}

/// True if a node ended because of a stop request: its own exit status for one
/// (130), or killed by SIGINT or SIGTERM.
pub(crate) fn stopped_by_signal(status: ExitStatus) -> bool {
    use std::os::unix::process::ExitStatusExt;
    status.code() == Some(i32::from(EXIT_INTERRUPTED))
        || matches!(status.signal(), Some(s) if s == SIGINT || s == SIGTERM)
}

/// One node program under supervision.
pub(crate) struct Proc {
    pub(crate) role: Role,
    pub(crate) child: Child,
    pub(crate) status: Option<ExitStatus>,
    pub(crate) restarts: u32,
    /// Set while a dead process waits out the restart backoff.
    pub(crate) restart_at: Option<Instant>,
    /// Since when its process is stopped: a node stopped too long is frozen.
    pub(crate) progress: Progress,
}

impl Proc {
    pub(crate) fn signal(&self, sig: rustix::process::Signal) {
        if let Some(pid) = rustix::process::Pid::from_raw(self.child.id() as i32) {
            let _ = rustix::process::kill_process(pid, sig);
        }
    }

    /// SIGTERM, then SIGKILL after `grace`; records how it ended.
    pub(crate) fn stop(&mut self, grace: Duration) {
        if self.status.is_some() {
            return;
        }
        self.signal(rustix::process::Signal::TERM);
        let until = Instant::now() + grace;
        while Instant::now() < until {
            if let Ok(Some(s)) = self.child.try_wait() {
                self.status = Some(s);
                return;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = self.child.kill();
        self.status = self.child.wait().ok();
    }

    /// True while the program runs.
    pub(crate) fn running(&mut self) -> bool {
        self.status.is_none() && !matches!(self.child.try_wait(), Ok(Some(_)))
    }

    /// The exit status if it has ended since the last look.
    pub(crate) fn ended(&mut self) -> Option<ExitStatus> {
        if self.status.is_some() || self.restart_at.is_some() {
            return None;
        }
        self.child.try_wait().ok().flatten()
    }
}

/// The last lines of a node's log, bounded: the log of a long run can be large.
pub(crate) fn log_tail(out: &Path, role: Role) -> String {
    let tail = log_lines(out, role);
    if tail.trim().is_empty() {
        // A full disk leaves the log unwritten too: say so rather than nothing.
        return format!("(its log, {role}.log, says nothing: it could not be written, or the node wrote nothing before it ended)");
    }
    tail
}

/// The last five lines of a node's log, from its last 4 kB.
fn log_lines(out: &Path, role: Role) -> String {
    use std::io::{Read, Seek, SeekFrom};
    let Ok(mut f) = std::fs::File::open(out.join(format!("{role}.log"))) else {
        return String::new();
    };
    let len = f.metadata().map_or(0, |m| m.len());
    let _ = f.seek(SeekFrom::Start(len.saturating_sub(4096)));
    let mut text = String::new();
    let _ = f.take(4096).read_to_string(&mut text);
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(5)..].join("\n")
}
