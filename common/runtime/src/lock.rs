//! Run names (prefixes) and the locks that keep two runs apart.
//!
//! Every node of a run holds an exclusive `flock` on `<prefix>.<role>.lock` (and the
//! launcher on `<prefix>.run.lock`) for as long as it lives; the kernel releases it
//! when the process dies, however it dies, so a crash never leaves a stale lock. A
//! second node of the same role under the same prefix, or a second launcher, finds
//! the lock held and refuses to start, naming the process that holds it: two runs
//! with one prefix would otherwise read each other's samples. A launcher asks
//! [`in_use`] for every lock of its prefix before it starts or writes anything.
//!
//! A lock removes its file when released; a process that takes a lock checks that
//! the file it locked is still the one at the path (it may have been removed between
//! the open and the lock), so removal never lets two holders in. Files left by killed
//! processes are removed by [`clean_stale`].

use rustix::fs::{flock, FlockOperation};
use std::io::{Seek, Write};
use std::path::PathBuf;

/// Longest prefix accepted. It names shared-memory objects and files, and iceoryx2's
/// event sockets, whose paths hold it twice within the 108 bytes a Unix socket path
/// may have: 26 characters was measured to be the most that works. The bench adds up
/// to two characters to a user's prefix for its runs, so users get 24.
pub const MAX_PREFIX_LEN: usize = 24;

/// Why a run's prefix cannot be taken: the prefix itself, the lock's file, or another
/// process holding it.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Empty or longer than [`MAX_PREFIX_LEN`].
    #[error("--prefix {0:?}: must be 1 to {MAX_PREFIX_LEN} characters long")]
    Length(String),
    /// Starts with another character than a letter or a digit.
    #[error("--prefix {0:?}: must start with a letter or a digit")]
    Start(String),
    /// Holds a character outside `A-Z a-z 0-9 _ -`.
    #[error("--prefix {0:?}: character {1:?} not allowed (use A-Z a-z 0-9 _ -)")]
    Character(String, char),
    /// The lock's folder or file could not be made or opened.
    #[error("{doing} {}: {source}", path.display())]
    Io {
        /// `creating`, `opening`.
        doing: &'static str,
        /// The folder or file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// Another process holds it.
    #[error("prefix {prefix:?} is in use: {who} holds it; wait for that run to end or choose another --prefix")]
    InUse {
        /// The prefix.
        prefix: String,
        /// The holder, as it described itself.
        who: String,
    },
}

/// Checks a prefix: 1 to 24 characters from `A-Z a-z 0-9 _ -`, starting with a letter
/// or digit.
pub fn check_prefix(prefix: &str) -> Result<(), LockError> {
    if prefix.is_empty() || prefix.len() > MAX_PREFIX_LEN {
        return Err(LockError::Length(prefix.to_string()));
    }
    if !prefix.starts_with(|c: char| c.is_ascii_alphanumeric()) {
        return Err(LockError::Start(prefix.to_string()));
    }
    if let Some(c) = prefix
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || *c == '_' || *c == '-'))
    {
        return Err(LockError::Character(prefix.to_string(), c));
    }
    Ok(())
}

/// A held lock; released (and its file removed) when dropped, released by the kernel
/// when the process ends.
#[derive(Debug)]
pub struct Lock {
    file: std::fs::File,
    /// The lock file.
    pub path: PathBuf,
}

impl Drop for Lock {
    fn drop(&mut self) {
        // Removed while still held: a process waiting on this file finds it gone and
        // opens a new one (see `locked_file`).
        let _ = std::fs::remove_file(&self.path);
        let _ = flock(&self.file, FlockOperation::Unlock);
    }
}

/// The locks of one run: the launcher's and one per node.
pub const RUN_LOCKS: [&str; 4] = ["run", "master", "emulator", "slave"];

/// True if `file` is still the file at `path` (not removed or replaced since opened).
fn still_at(file: &std::fs::File, path: &std::path::Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Opens `path` (creating it with `create`) and locks it without waiting: `Ok(None)`
/// if another process holds it, the open file if this one does now.
fn locked_file(path: &std::path::Path, create: bool) -> std::io::Result<Option<std::fs::File>> {
    loop {
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(create)
            .truncate(false)
            .open(path)?;
        if flock(&file, FlockOperation::NonBlockingLockExclusive).is_err() {
            return Ok(None);
        }
        if still_at(&file, path) {
            return Ok(Some(file));
        }
        if !create {
            return Err(std::io::ErrorKind::NotFound.into());
        }
    }
}

/// Who holds `<prefix>.<what>.lock`, if anyone (a description, or "another process").
fn holder(path: &std::path::Path) -> Option<String> {
    match locked_file(path, false) {
        Ok(Some(file)) => {
            drop(Lock {
                file,
                path: path.to_path_buf(),
            });
            None
        }
        Ok(None) => {
            let who = std::fs::read_to_string(path).unwrap_or_default();
            let who = who.trim();
            Some(if who.is_empty() {
                "another process".into()
            } else {
                who.into()
            })
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        // A lock file this process may not open is someone's: never taken for free.
        Err(e) => Some(format!(
            "a process this one cannot see ({}: {e})",
            path.display()
        )),
    }
}

/// Refuses a prefix that any process of a run holds (a launcher or any node started
/// by hand), naming the holder; creates nothing. Checked before a launcher starts
/// anything, so a refused run never touches the live one.
pub fn in_use(prefix: &str) -> Result<(), LockError> {
    check_prefix(prefix)?;
    for what in RUN_LOCKS {
        if let Some(who) = holder(&lock_path(prefix, what)) {
            return Err(in_use_message(prefix, &who));
        }
    }
    Ok(())
}

fn in_use_message(prefix: &str, who: &str) -> LockError {
    LockError::InUse {
        prefix: prefix.to_string(),
        who: who.to_string(),
    }
}

/// Every lock of run `prefix`, if no other process holds any (held while the caller
/// removes what a dead run left, so no node of that prefix starts meanwhile).
pub fn take_all(prefix: &str, holder_text: &str) -> Option<Vec<Lock>> {
    // Asked first, then taken without waiting: a live run's locks are never held here
    // for longer than a probe, or one of its nodes starting now could be refused.
    if !idle(prefix) {
        return None;
    }
    RUN_LOCKS
        .iter()
        .map(|what| take_with(prefix, what, holder_text, 1).ok())
        .collect()
}

/// True if no process holds any lock of `prefix`.
pub fn idle(prefix: &str) -> bool {
    RUN_LOCKS
        .iter()
        .all(|what| holder(&lock_path(prefix, what)).is_none())
}

/// Removes the lock files that no live process holds (left by killed processes).
pub fn clean_stale() {
    let Ok(dir) = std::fs::read_dir(lock_dir()) else {
        return;
    };
    for entry in dir.flatten() {
        // `holder` takes a free lock and drops it, which removes the file.
        let _ = holder(&entry.path());
    }
}

/// The lock files' folder: a name no prefix can take (prefixes start with a letter or
/// a digit), so no run's iceoryx2 folder is ever it.
pub fn lock_dir() -> PathBuf {
    PathBuf::from(tactile_transport::ipc::ROOT).join(".locks")
}

/// The lock file of `what` in run `prefix`.
fn lock_path(prefix: &str, what: &str) -> PathBuf {
    lock_dir().join(format!("{prefix}.{what}.lock"))
}

/// Takes `<prefix>.<what>.lock`, writing `holder` (a description of this process) into
/// it; if another process holds it, the error says who.
pub fn take(prefix: &str, what: &str, holder_text: &str) -> Result<Lock, LockError> {
    // A free lock may be held for a moment by another process's probe (`holder`,
    // `take_all`): 40 tries over 200 ms before it counts as in use.
    take_with(prefix, what, holder_text, 40)
}

fn take_with(prefix: &str, what: &str, holder_text: &str, tries: u32) -> Result<Lock, LockError> {
    check_prefix(prefix)?;
    let dir = lock_dir();
    std::fs::create_dir_all(&dir).map_err(|source| LockError::Io {
        doing: "creating",
        path: dir.clone(),
        source,
    })?;
    let path = lock_path(prefix, what);
    let mut opened = None;
    for k in 0..tries {
        if k > 0 {
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        opened = locked_file(&path, true).map_err(|source| LockError::Io {
            doing: "opening",
            path: path.clone(),
            source,
        })?;
        if opened.is_some() {
            break;
        }
    }
    let Some(mut file) = opened else {
        let who = holder(&path).unwrap_or_else(|| "another process".into());
        return Err(in_use_message(prefix, &who));
    };
    let _ = file.set_len(0);
    let _ = file.rewind();
    let _ = file.write_all(holder_text.as_bytes());
    Ok(Lock { file, path })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lock_that_cannot_be_opened_keeps_the_systems_reason() {
        use std::error::Error as _;
        let e = LockError::Io {
            doing: "opening",
            path: PathBuf::from("/x.lock"),
            source: std::io::Error::from(std::io::ErrorKind::PermissionDenied),
        };
        assert!(e.to_string().starts_with("opening /x.lock: "), "{e}");
        let io = e.source().and_then(|c| c.downcast_ref::<std::io::Error>());
        assert_eq!(
            io.map(std::io::Error::kind),
            Some(std::io::ErrorKind::PermissionDenied)
        );
    }

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
        let e = take(&p, "master", "B").expect_err("second").to_string();
        assert!(e.contains("the master of run A (pid 1)"), "{e}");
        drop(held);
        let again = take(&p, "master", "B").expect("free again");
        assert!(again.path.exists());
        let path = again.path.clone();
        drop(again);
        assert!(!path.exists(), "a released lock removes its file");
    }

    #[test]
    fn in_use_sees_every_lock_of_a_run_and_creates_nothing() {
        let p = format!("inuse{}", std::process::id());
        assert!(in_use(&p).is_ok());
        for what in RUN_LOCKS {
            assert!(!lock_dir().join(format!("{p}.{what}.lock")).exists());
        }
        let slave = take(&p, "slave", "a slave by hand (pid 7)").expect("take");
        let e = in_use(&p).expect_err("held").to_string();
        assert!(e.contains("a slave by hand (pid 7)"), "{e}");
        assert!(!idle(&p));
        drop(slave);
        assert!(idle(&p));
    }

    #[test]
    fn stale_lock_files_are_removed_held_ones_kept() {
        let p = format!("stale{}", std::process::id());
        let dir = lock_dir();
        std::fs::create_dir_all(&dir).expect("dir");
        let stale = dir.join(format!("{p}.master.lock"));
        std::fs::write(&stale, "a killed master").expect("write");
        let held = take(&p, "slave", "alive").expect("take");
        clean_stale();
        assert!(!stale.exists(), "a lock nobody holds is removed");
        assert!(held.path.exists(), "a held lock is kept");
        assert_eq!(
            std::fs::read_to_string(&held.path).ok().as_deref(),
            Some("alive")
        );
    }
}
