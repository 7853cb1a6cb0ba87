//! Reading the files a user names: scenarios, trajectories, device geometries.
//!
//! Every input is checked before it is read: it must be a regular file (not a folder,
//! a FIFO that would block forever, or a device that never ends) and no larger than a
//! limit that suits its kind, and it is read with that bound, so a file that grows
//! while it is read cannot exhaust memory either.

use std::io::Read;
use std::path::{Path, PathBuf};
use tactile_scenario::Scenario;

/// Largest scenario file accepted (a scenario is a few hundred lines of TOML).
pub const MAX_SCENARIO_BYTES: u64 = 1 << 20;
/// Largest device file accepted.
pub const MAX_DEVICE_BYTES: u64 = 64 << 10;
/// Largest trajectory file accepted (a million rows of x,y,z is about 60 MB).
pub const MAX_TRAJECTORY_BYTES: u64 = 128 << 20;

/// Reads `path` as UTF-8 text if it is a regular file of at most `max` bytes; the
/// error is one line naming the file and the problem.
pub fn read_text(path: &Path, what: &str, max: u64) -> Result<String, String> {
    let shown = path.display();
    let mut bytes = Vec::new();
    open_bounded(path, what, max)?
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {what} {shown}: {e}"))?;
    String::from_utf8(bytes).map_err(|e| format!("{what} {shown} is not UTF-8 text: {e}"))
}

/// Opens `path` for reading a piece at a time if it is a regular file of at most
/// `max` bytes; reading past `max` (a file that grows while it is read) is an error.
/// For a large input read as a stream, so its whole text is never held.
pub fn open_bounded(path: &Path, what: &str, max: u64) -> Result<Bounded, String> {
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {what} {shown}: {e}"))?;
    if !meta.is_file() {
        let kind = if meta.is_dir() {
            "a folder"
        } else {
            "not a regular file"
        };
        return Err(format!("{what} {shown} is {kind}"));
    }
    if meta.len() > max {
        return Err(format!(
            "{what} {shown} is {} bytes, more than the {} a {what} may have",
            meta.len(),
            max
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read {what} {shown}: {e}"))?;
    Ok(Bounded {
        inner: file.take(max + 1),
        max,
        read: 0,
    })
}

/// A file read with a bound: an error, not more bytes, past `max`.
#[derive(Debug)]
pub struct Bounded {
    inner: std::io::Take<std::fs::File>,
    max: u64,
    read: u64,
}

impl Read for Bounded {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        if self.read > self.max {
            return Err(std::io::Error::other(format!(
                "grew past {} bytes while it was read",
                self.max
            )));
        }
        Ok(n)
    }
}

/// The folder a scenario's relative paths are resolved against: the scenario's own.
pub fn base_dir(scenario: &Path) -> PathBuf {
    let parent = scenario
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    std::fs::canonicalize(&parent).unwrap_or(parent)
}

/// Reads and validates a scenario file; returns it with the folder its relative paths
/// are resolved against. The error names the file and the field.
pub fn load_scenario(path: &Path) -> Result<(Scenario, PathBuf), String> {
    let text = read_text(path, "scenario", MAX_SCENARIO_BYTES)?;
    let scenario = Scenario::from_toml_str(&text)
        .map_err(|e| format!("{}: {}", path.display(), e.to_string().trim_end()))?;
    Ok((scenario, base_dir(path)))
}

/// Checks that every file `scenario` reads (a trajectory, a URDF, a recorded network)
/// is there, resolved against `base_dir`, the scenario's folder. A relative path that
/// is not says how paths are resolved and how to copy a scenario elsewhere: a copy of
/// a shipped scenario keeps its relative paths, which then point nowhere.
pub fn inputs_present(scenario: &Scenario, base_dir: &Path) -> Result<(), String> {
    for p in scenario.input_paths() {
        let full = base_dir.join(&p);
        if full.exists() || Path::new(&p).is_absolute() {
            continue;
        }
        return Err(format!(
            "input file {p:?} is not there: it is resolved against the scenario's own folder, \
             {}, not the current one, so it names {}; for a scenario copied from another \
             folder, write the copy with its paths resolved (`tactile check ORIGINAL.toml > \
             copy.toml`, from anywhere) or give the file's absolute path",
            base_dir.display(),
            full.display()
        ));
    }
    Ok(())
}

/// True if `a` and `b` name the same existing file (same device and inode).
pub fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_fifos_and_large_files_are_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let e = read_text(dir.path(), "scenario", 10).expect_err("a folder");
        assert!(e.contains("is a folder"), "{e}");
        let big = dir.path().join("big.toml");
        std::fs::write(&big, vec![b'#'; 11]).expect("write");
        let e = read_text(&big, "scenario", 10).expect_err("too large");
        assert!(e.contains("11 bytes, more than the 10"), "{e}");
        let e = read_text(Path::new("/dev/zero"), "scenario", 10).expect_err("a device");
        assert!(e.contains("not a regular file"), "{e}");
        let ok = dir.path().join("ok.toml");
        std::fs::write(&ok, "name = \"x\"\n").expect("write");
        assert_eq!(
            read_text(&ok, "scenario", 100).as_deref(),
            Ok("name = \"x\"\n")
        );
    }

    #[test]
    fn the_same_file_is_recognised_through_another_path() {
        let dir = tempfile::tempdir().expect("tempdir");
        let a = dir.path().join("a.toml");
        std::fs::write(&a, "x").expect("write");
        let via = dir.path().join(".").join("a.toml");
        assert!(same_file(&a, &via));
        assert!(!same_file(&a, &dir.path().join("b.toml")));
    }
}
