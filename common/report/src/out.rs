//! The output folder of a run or a report: held by one process at a time, and every
//! file put there under a temporary name, renamed when whole.
//!
//! Two runs into one folder would delete each other's records while their nodes write
//! them, and report each other's samples as their own; a report killed half-way (a full
//! disk, SIGKILL) would leave a truncated trace beside an older summary. So a run or a
//! report takes `OUT/.tactile.lock` (an exclusive `flock`, released by the kernel
//! however the process ends) before it removes or writes anything, and each file is
//! written as `NAME.partial` and renamed: a reader sees the old file or the new, never
//! half of one. `summary.json` is written last, so a folder without it holds no whole
//! report.

use crate::Error;
use rustix::fs::{flock, FlockOperation};
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

pub use crate::ours::LOCK_FILE;

/// An output folder held by this process; released (its lock file removed) on drop.
#[derive(Debug)]
pub struct OutLock {
    file: std::fs::File,
    path: PathBuf,
}

impl Drop for OutLock {
    fn drop(&mut self) {
        // Removed while held: a process waiting on the old file finds it gone.
        let _ = std::fs::remove_file(&self.path);
        let _ = flock(&self.file, FlockOperation::Unlock);
    }
}

/// True if `file` is still the file at `path`.
fn still_at(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Makes `out` (a folder) and takes it for this process, `holder` saying who holds it;
/// refused (bad input, exit 2, nothing touched) while another process holds it, or
/// when it holds anything but an earlier output of ours ([`crate::ours`]).
pub fn take(out: &Path, holder: &str) -> Result<OutLock, Error> {
    crate::ours::refuse_foreign(out)?;
    make_out_dir(out)?;
    let path = out.join(LOCK_FILE);
    let io = |e| Error::io(format!("locking {}", path.display()))(e);
    loop {
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io)?;
        if flock(&file, FlockOperation::NonBlockingLockExclusive).is_err() {
            let who = std::fs::read_to_string(&path).unwrap_or_default();
            let who = if who.trim().is_empty() {
                "another process"
            } else {
                who.trim()
            };
            return Err(Error::BadInput(format!(
                "--out {}: {who} is writing into it; wait for it to end or choose another --out",
                out.display()
            )));
        }
        if !still_at(&file, &path) {
            continue;
        }
        file.set_len(0).map_err(io)?;
        file.rewind().map_err(io)?;
        let _ = writeln!(file, "{holder}");
        return Ok(OutLock { file, path });
    }
}

/// Makes the output folder `out`; a path that exists and is not a folder is bad input
/// (a typo naming a file must not become a confusing I/O failure).
pub fn make_out_dir(out: &Path) -> Result<(), Error> {
    if out.exists() && !out.is_dir() {
        return Err(Error::BadInput(format!(
            "--out {}: is a file, not a folder",
            out.display()
        )));
    }
    std::fs::create_dir_all(out).map_err(Error::io(format!("creating {}", out.display())))
}

/// The temporary name a file is written under until it is whole.
pub fn partial(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".partial");
    path.with_file_name(name)
}

/// Writes `path` by `write` under its temporary name and renames it when `write`
/// succeeded; after a failure the temporary file is removed and `path` is as it was.
pub fn whole<T, E>(path: &Path, write: impl FnOnce(&Path) -> Result<T, E>) -> Result<T, E>
where
    E: From<std::io::Error>,
{
    let tmp = partial(path);
    match write(&tmp) {
        Ok(v) => {
            if let Err(e) = std::fs::rename(&tmp, path) {
                let _ = std::fs::remove_file(&tmp);
                return Err(e.into());
            }
            Ok(v)
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Removes `path` if it is there.
pub fn remove_if_there(path: &Path) -> Result<(), Error> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(Error::io(format!("removing {}", path.display()))(e))
        }
        _ => Ok(()),
    }
}

/// Writes `text` to `path` whole or not at all.
pub fn write_file(path: &Path, text: &str) -> Result<(), Error> {
    whole(path, |tmp| std::fs::write(tmp, text))
        .map_err(Error::io(format!("writing {}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_folder_is_refused_naming_its_holder_and_free_again_after() {
        let dir = tempfile::tempdir().expect("tempdir");
        let out = dir.path().join("out");
        let held = take(&out, "tactile run (pid 1)").expect("taken");
        let e = take(&out, "another").expect_err("held");
        assert!(matches!(e, Error::BadInput(_)), "{e}");
        assert!(
            e.to_string()
                .contains("tactile run (pid 1) is writing into it"),
            "{e}"
        );
        drop(held);
        assert!(!out.join(LOCK_FILE).exists());
        take(&out, "another").expect("free again");
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_partial_one() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("summary.json");
        std::fs::write(&path, "old").expect("write");
        let r: Result<(), std::io::Error> = whole(&path, |tmp| {
            std::fs::write(tmp, "half")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "old");
        assert!(!partial(&path).exists());
        write_file(&path, "new").expect("write");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "new");
    }
}
