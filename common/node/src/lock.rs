//! Run names (prefixes) and the locks that keep two runs apart.
//!
//! Every node of a run holds an exclusive `flock` on `<prefix>.<role>.lock` (and the
//! launcher on `<prefix>.run.lock`) for as long as it lives; the kernel releases it
//! when the process dies, however it dies, so a crash never leaves a stale lock. A
//! second node of the same role under the same prefix, or a second launcher, finds
//! the lock held and refuses to start, naming the process that holds it: two runs
//! with one prefix would otherwise read each other's samples.

use rustix::fs::{flock, FlockOperation};
use std::io::{Read, Seek, Write};
use std::path::PathBuf;

/// Longest prefix accepted. It names shared-memory objects and files, and iceoryx2's
/// event sockets, whose paths hold it twice within the 108 bytes a Unix socket path
/// may have: 26 characters was measured to be the most that works. The bench adds up
/// to two characters to a user's prefix for its runs, so users get 24.
pub const MAX_PREFIX_LEN: usize = 24;

/// Checks a prefix: 1 to 24 characters from `A-Z a-z 0-9 _ -`, starting with a letter
/// or digit.
pub fn check_prefix(prefix: &str) -> Result<(), String> {
    if prefix.is_empty() || prefix.len() > MAX_PREFIX_LEN {
        return Err(format!(
            "--prefix {prefix:?}: must be 1 to {MAX_PREFIX_LEN} characters long"
        ));
    }
    if !prefix.starts_with(|c: char| c.is_ascii_alphanumeric()) {
        return Err(format!(
            "--prefix {prefix:?}: must start with a letter or a digit"
        ));
    }
    if let Some(c) = prefix
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || *c == '_' || *c == '-'))
    {
        return Err(format!(
            "--prefix {prefix:?}: character {c:?} not allowed (use A-Z a-z 0-9 _ -)"
        ));
    }
    Ok(())
}

/// A held lock; released when dropped or when the process ends.
#[derive(Debug)]
pub struct Lock {
    _file: std::fs::File,
    /// The lock file.
    pub path: PathBuf,
}

fn lock_dir() -> PathBuf {
    PathBuf::from(crate::ipc::ROOT).join("locks")
}

/// Takes `<prefix>.<what>.lock`, writing `holder` (a description of this process) into
/// it; if another process holds it, the error says who.
pub fn take(prefix: &str, what: &str, holder: &str) -> Result<Lock, String> {
    check_prefix(prefix)?;
    let dir = lock_dir();
    std::fs::create_dir_all(&dir).map_err(|e| format!("creating {}: {e}", dir.display()))?;
    let path = dir.join(format!("{prefix}.{what}.lock"));
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(|e| format!("opening {}: {e}", path.display()))?;
    if flock(&file, FlockOperation::NonBlockingLockExclusive).is_err() {
        let mut who = String::new();
        let _ = file.read_to_string(&mut who);
        let who = who.trim();
        return Err(format!(
            "prefix {prefix:?} is in use: {} holds it; wait for that run to end or choose another --prefix",
            if who.is_empty() { "another process" } else { who }
        ));
    }
    let _ = file.set_len(0);
    let _ = file.rewind();
    let _ = file.write_all(holder.as_bytes());
    Ok(Lock { _file: file, path })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefixes_are_checked() {
        assert!(check_prefix("run-1_a").is_ok());
        for bad in ["", "-x", "a/b", "a b", "ä", &"x".repeat(25)] {
            assert!(check_prefix(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn a_held_lock_names_its_holder() {
        let p = format!("locktest{}", std::process::id());
        let held = take(&p, "master", "the master of run A (pid 1)").expect("first");
        // flock locks belong to the open file: a second open in this process conflicts.
        let e = take(&p, "master", "B").expect_err("second");
        assert!(e.contains("the master of run A (pid 1)"), "{e}");
        drop(held);
        take(&p, "master", "B").expect("free again");
    }
}
