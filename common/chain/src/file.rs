//! The one reading of a URDF file. Every reader of an arm (the slave, the master's
//! gimbal, the live view, the report, the launcher's check) takes its URDF through
//! [`read`]: one size cap, one set of messages naming the file, and the text parsed
//! once, so a node reads and parses its URDF once and passes the model down. The rest
//! of the crate is pure; this is its only I/O.

use crate::{Error, Robot};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest URDF file read, bytes (the Panda's is 15 kB; meshes are separate files):
/// a bound on what a user's file can make a node hold.
pub const MAX_URDF_BYTES: u64 = 16 << 20;

/// A URDF file read and parsed: its text as written (the live view and the recordings
/// serve it as it is) and its model.
#[derive(Debug, Clone)]
pub struct UrdfFile {
    /// Where it was read from.
    pub path: PathBuf,
    /// The file's text.
    pub text: String,
    /// Its model.
    pub robot: Robot,
}

/// A URDF that could not be read or parsed; each message names the file.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read (missing, unreadable, grew while read).
    #[error("cannot read URDF {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A folder, a FIFO, a device: not a regular file.
    #[error("URDF {} is not a regular file", path.display())]
    NotAFile {
        /// The file.
        path: PathBuf,
    },
    /// Larger than [`MAX_URDF_BYTES`].
    #[error("URDF {} is {len} bytes, more than the {MAX_URDF_BYTES} a URDF may have", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size.
        len: u64,
    },
    /// Not UTF-8 text.
    #[error("URDF {} is not UTF-8 text", path.display())]
    NotText {
        /// The file.
        path: PathBuf,
    },
    /// Read, but not a URDF this crate takes.
    #[error("{}: {source}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What is wrong in it.
        source: Error,
    },
}

/// Reads the URDF at `path` (a regular file of at most [`MAX_URDF_BYTES`], read with
/// that bound so a file growing meanwhile cannot exhaust memory) and parses it.
pub fn read(path: &Path) -> Result<UrdfFile, ReadError> {
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(ReadError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    let too_large = |len| ReadError::TooLarge {
        path: path.to_path_buf(),
        len,
    };
    if meta.len() > MAX_URDF_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_URDF_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_URDF_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    let text = String::from_utf8(bytes).map_err(|_| ReadError::NotText {
        path: path.to_path_buf(),
    })?;
    let robot = Robot::parse(&text).map_err(|source| ReadError::Parse {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(UrdfFile {
        path: path.to_path_buf(),
        text,
        robot,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const ARM: &str = r#"<robot name="a"><link name="b"/><link name="t"/>
        <joint name="j" type="revolute"><parent link="b"/><child link="t"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;

    #[test]
    fn a_urdf_is_read_and_parsed_once() {
        let d = tempfile::tempdir().expect("temp dir");
        let p = d.path().join("ok.urdf");
        std::fs::write(&p, ARM).expect("write");
        let f = read(&p).expect("a URDF");
        assert_eq!(f.text, ARM);
        assert_eq!(f.path, p);
        assert!(crate::Chain::new(&f.robot, "b", "t").is_ok());
    }

    #[test]
    fn a_missing_large_or_broken_urdf_is_refused_naming_the_file() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let d = tmp.path();
        let missing = d.join("missing.urdf");
        let e = read(&missing).expect_err("missing").to_string();
        assert!(
            e.starts_with("cannot read URDF") && e.contains("missing.urdf"),
            "{e}"
        );
        let e = read(d).expect_err("a folder").to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let big = d.join("big.urdf");
        let f = std::fs::File::create(&big).expect("create");
        f.set_len(MAX_URDF_BYTES + 1).expect("sparse file");
        let e = read(&big).expect_err("too large").to_string();
        assert!(
            e.contains("big.urdf") && e.contains("more than the 16777216"),
            "{e}"
        );
        let bad = d.join("bad.urdf");
        std::fs::write(&bad, "<robot").expect("write");
        let e = read(&bad).expect_err("not XML").to_string();
        assert!(e.contains("bad.urdf") && e.contains("not XML"), "{e}");
    }
}
