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

/// Why a file a user names cannot be read, or a scenario cannot be taken; each message
/// is one line naming the file and the problem.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The operating system refused (missing, unreadable, grew while read).
    #[error("cannot read {what} {}: {source}", path.display())]
    Io {
        /// What the file is (`scenario`, `trajectory`).
        what: String,
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A folder, a FIFO, a device.
    #[error("{what} {} is {}", path.display(), if *.folder { "a folder" } else { "not a regular file" })]
    NotAFile {
        /// What the file is.
        what: String,
        /// The file.
        path: PathBuf,
        /// A folder (else another kind that is no regular file).
        folder: bool,
    },
    /// Larger than its kind may be.
    #[error("{what} {} is {len} bytes, more than the {max} a {what} may have", path.display())]
    TooLarge {
        /// What the file is.
        what: String,
        /// The file.
        path: PathBuf,
        /// Its size.
        len: u64,
        /// The most its kind may have.
        max: u64,
    },
    /// Not UTF-8.
    #[error("{what} {} is not UTF-8 text: {source}", path.display())]
    NotText {
        /// What the file is.
        what: String,
        /// The file.
        path: PathBuf,
        /// Where it stops being UTF-8.
        source: std::string::FromUtf8Error,
    },
    /// Read, but not a valid scenario.
    #[error("{}: {}", path.display(), source.to_string().trim_end())]
    Scenario {
        /// The scenario file.
        path: PathBuf,
        /// What is wrong in it.
        source: tactile_scenario::ScenarioError,
    },
    /// An input the scenario names is not there.
    #[error(
        "input file {name:?} is not there: it is resolved against the scenario's own folder, \
         {}, not the current one, so it names {}; for a scenario copied from another \
         folder, write the copy with its paths resolved (`tactile check ORIGINAL.toml > \
         copy.toml`, from anywhere) or give the file's absolute path",
        base_dir.display(),
        full.display()
    )]
    Missing {
        /// The path as the scenario writes it.
        name: String,
        /// The scenario's folder.
        base_dir: PathBuf,
        /// Where it was looked for.
        full: PathBuf,
    },
}

/// Reads `path` as UTF-8 text if it is a regular file of at most `max` bytes; the
/// error is one line naming the file and the problem.
pub fn read_text(path: &Path, what: &str, max: u64) -> Result<String, FileError> {
    let mut bytes = Vec::new();
    open_bounded(path, what, max)?
        .read_to_end(&mut bytes)
        .map_err(io_error(path, what))?;
    String::from_utf8(bytes).map_err(|source| FileError::NotText {
        what: what.to_string(),
        path: path.to_path_buf(),
        source,
    })
}

/// The I/O error of reading `what` at `path`.
fn io_error<'a>(path: &'a Path, what: &'a str) -> impl FnOnce(std::io::Error) -> FileError + 'a {
    move |source| FileError::Io {
        what: what.to_string(),
        path: path.to_path_buf(),
        source,
    }
}

/// Opens `path` for reading a piece at a time if it is a regular file of at most
/// `max` bytes; reading past `max` (a file that grows while it is read) is an error.
/// For a large input read as a stream, so its whole text is never held.
pub fn open_bounded(path: &Path, what: &str, max: u64) -> Result<Bounded, FileError> {
    let meta = std::fs::metadata(path).map_err(io_error(path, what))?;
    if !meta.is_file() {
        return Err(FileError::NotAFile {
            what: what.to_string(),
            path: path.to_path_buf(),
            folder: meta.is_dir(),
        });
    }
    if meta.len() > max {
        return Err(FileError::TooLarge {
            what: what.to_string(),
            path: path.to_path_buf(),
            len: meta.len(),
            max,
        });
    }
    let file = std::fs::File::open(path).map_err(io_error(path, what))?;
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
pub fn load_scenario(path: &Path) -> Result<(Scenario, PathBuf), FileError> {
    let text = read_text(path, "scenario", MAX_SCENARIO_BYTES)?;
    let scenario = Scenario::from_toml_str(&text).map_err(|source| FileError::Scenario {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((scenario, base_dir(path)))
}

/// Checks that every file `scenario` reads (a trajectory, a URDF, a recorded network)
/// is there, resolved against `base_dir`, the scenario's folder. A relative path that
/// is not says how paths are resolved and how to copy a scenario elsewhere: a copy of
/// a shipped scenario keeps its relative paths, which then point nowhere.
pub fn inputs_present(scenario: &Scenario, base_dir: &Path) -> Result<(), FileError> {
    for p in scenario.input_paths() {
        let full = base_dir.join(&p);
        if full.exists() || Path::new(&p).is_absolute() {
            continue;
        }
        return Err(FileError::Missing {
            name: p,
            base_dir: base_dir.to_path_buf(),
            full,
        });
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
        let e = read_text(dir.path(), "scenario", 10)
            .expect_err("a folder")
            .to_string();
        assert!(e.contains("is a folder"), "{e}");
        let big = dir.path().join("big.toml");
        std::fs::write(&big, vec![b'#'; 11]).expect("write");
        let e = read_text(&big, "scenario", 10)
            .expect_err("too large")
            .to_string();
        assert!(e.contains("11 bytes, more than the 10"), "{e}");
        let e = read_text(Path::new("/dev/zero"), "scenario", 10)
            .expect_err("a device")
            .to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let ok = dir.path().join("ok.toml");
        std::fs::write(&ok, "name = \"x\"\n").expect("write");
        assert_eq!(
            read_text(&ok, "scenario", 100).expect("text"),
            "name = \"x\"\n"
        );
    }

    #[test]
    fn a_file_error_keeps_its_cause() {
        use std::error::Error as _;
        let dir = tempfile::tempdir().expect("tempdir");
        let gone = dir.path().join("gone.toml");
        let e = read_text(&gone, "scenario", 10).expect_err("missing");
        assert!(e.to_string().starts_with("cannot read scenario "), "{e}");
        let io = e.source().and_then(|c| c.downcast_ref::<std::io::Error>());
        assert_eq!(
            io.map(std::io::Error::kind),
            Some(std::io::ErrorKind::NotFound)
        );
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, "rate_hz = \"fast\"\n").expect("write");
        let e = load_scenario(&bad).expect_err("a string for a number");
        assert!(e.to_string().starts_with(&bad.display().to_string()), "{e}");
        assert!(e
            .source()
            .is_some_and(|c| c.is::<tactile_scenario::ScenarioError>()));
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
