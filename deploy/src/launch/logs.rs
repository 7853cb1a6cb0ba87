//! A node's log as the launcher quotes it when the node fails: its last lines,
//! bounded (the log of a long run can be large).

use std::path::Path;
use tactile_messages::Role;

/// The last lines of a node's log, bounded: the log of a long run can be large.
pub(super) fn log_tail(out: &Path, role: Role) -> String {
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
