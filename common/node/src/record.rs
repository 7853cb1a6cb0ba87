//! Each node's own record: what it received, computed and commanded, its events and its
//! counters, written as the run goes.
//!
//! One file per node (`master.rec`, `emulator.rec`, `slave.rec`): an 8-byte magic, then
//! frames of a little-endian `u32` length and a bincode body. Every frame goes to the
//! operating system in one `write` as soon as it is made, so whatever a node wrote
//! before it was killed (even by SIGKILL) is in the file, and a node holds no more
//! than one frame in memory however long it runs. A node restarted into the same run
//! appends a new segment (a new `Start`) to its file. The report reads the files back
//! and joins them by sample number.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::io::{BufReader, Read, Write};
use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// First bytes of every record file; the last byte is the format version.
pub const MAGIC: [u8; 8] = *b"TACTREC\x04";
/// Largest frame a reader accepts; anything longer is corruption.
pub const MAX_FRAME: u32 = 1 << 20;

fn config() -> impl bincode::config::Config {
    bincode::config::standard()
}

/// One entry of a node's record. `S` is the node's per-sample record, `C` its counters.
// A record lives for one write or one read; boxing `Start` would allocate for nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Record<S, C> {
    /// A node started (a file holds one segment per start).
    Start(Start),
    /// The run this node joined: the token the master chose.
    Run(u64),
    /// One sample received, computed and commanded.
    Sample(S),
    /// Something that happened (peers found, break, resume, clamps, stop).
    Event(Event),
    /// Counters so far: written every second and at the end.
    Counters(Totals<C>),
    /// The node ended normally; nothing follows in this segment.
    Stop(Stop),
}

/// How a node started.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Start {
    /// `master`, `emulator` or `slave`.
    pub role: String,
    /// Version of the program.
    pub version: String,
    /// Process id.
    pub pid: u32,
    /// Host name.
    pub host: String,
    /// The clock domain: nodes with the same one share CLOCK_MONOTONIC (the kernel's
    /// boot id; `TACTILE_CLOCK_DOMAIN` overrides it), so a stage between their stamps is
    /// a true time; between two domains only an estimate is possible.
    pub clock: String,
    /// iceoryx2 prefix (or the link's name of the run).
    pub prefix: String,
    /// The link in use.
    pub link: String,
    /// Scenario name.
    pub scenario: String,
    /// The scenario as run, TOML, relative paths made absolute: the report reads the
    /// run's settings from here, and writes it out as `scenario.toml`.
    pub scenario_toml: String,
    /// Samples the scenario asks for.
    pub samples: u64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Scheduling: policy, priority, CPU, wake-up margin and poll budget.
    pub sched: crate::sched::Sched,
    /// Wall-clock time of the start, ms since the Unix epoch.
    pub unix_ms: u64,
    /// CLOCK_MONOTONIC at the start, ns.
    pub mono_ns: u64,
}

/// Something that happened to a node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Sample number when it happened.
    pub sample: u64,
    /// CLOCK_MONOTONIC, ns.
    pub mono_ns: u64,
    /// What happened.
    pub what: String,
}

/// A node's counters with its memory use.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Totals<C> {
    /// The node's own counters.
    pub counters: C,
    /// Peak resident set size so far, kB (getrusage's `ru_maxrss`).
    pub peak_rss_kb: u64,
}

/// How a node ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stop {
    /// `completed`, `interrupted`, or the failure.
    pub reason: String,
    /// CLOCK_MONOTONIC at the end, ns.
    pub mono_ns: u64,
}

/// Failures of reading a record.
#[derive(Debug, Error)]
pub enum RecordError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not a record of this format.
    #[error("{path}: not a Tactile record (or another format version)")]
    NotARecord {
        /// The file.
        path: String,
    },
    /// The file is a record of another format version (another build).
    #[error(
        "{path}: a Tactile record of format version {found}; this build reads version {reads}"
    )]
    OtherVersion {
        /// The file.
        path: String,
        /// Its version.
        found: u8,
        /// The version this build reads.
        reads: u8,
    },
    /// A frame could not be decoded.
    #[error("{path}: bad frame at byte {offset}: {detail}")]
    Corrupt {
        /// The file.
        path: String,
        /// Byte offset of the frame.
        offset: u64,
        /// What is wrong.
        detail: String,
    },
}

/// Appends records to a node's file, one `write` per record.
#[derive(Debug)]
pub struct RecordWriter<T> {
    file: std::fs::File,
    buf: Vec<u8>,
    path: PathBuf,
    _t: PhantomData<fn(&T)>,
}

impl<T: Serialize> RecordWriter<T> {
    /// Creates `path` afresh, or with `append` continues an existing record file (a
    /// restarted node of the same run); a file that is not a record is never touched.
    pub fn create(path: &Path, append: bool) -> std::io::Result<Self> {
        let exists = path.exists();
        let file = if append && exists {
            let mut head = [0u8; 8];
            let mut f = std::fs::File::open(path)?;
            let ok = f.read_exact(&mut head).is_ok() && head == MAGIC;
            if !ok {
                return Err(std::io::Error::other(format!(
                    "{} exists and is not a Tactile record; not appending to it",
                    path.display()
                )));
            }
            std::fs::OpenOptions::new().append(true).open(path)?
        } else {
            let mut f = std::fs::File::create(path)?;
            f.write_all(&MAGIC)?;
            f
        };
        Ok(RecordWriter {
            file,
            buf: Vec::with_capacity(512),
            path: path.to_path_buf(),
            _t: PhantomData,
        })
    }

    /// Writes one record (one system call; nothing stays buffered in the process).
    pub fn write(&mut self, record: &T) -> std::io::Result<()> {
        self.buf.clear();
        self.buf.extend_from_slice(&[0; 4]);
        bincode::serde::encode_into_std_write(record, &mut self.buf, config())
            .map_err(std::io::Error::other)?;
        let len = u32::try_from(self.buf.len() - 4).unwrap_or(u32::MAX);
        self.buf[..4].copy_from_slice(&len.to_le_bytes());
        self.file.write_all(&self.buf)
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Reads a record file back, frame by frame, in bounded memory.
#[derive(Debug)]
pub struct RecordReader<T> {
    input: BufReader<std::fs::File>,
    path: String,
    offset: u64,
    buf: Vec<u8>,
    /// Set when the file ends inside a frame (the node was killed mid-write).
    pub truncated_at: Option<u64>,
    _t: PhantomData<fn() -> T>,
}

impl<T: DeserializeOwned> RecordReader<T> {
    /// Opens a record file and checks its magic.
    pub fn open(path: &Path) -> Result<Self, RecordError> {
        let shown = path.display().to_string();
        let io = |source| RecordError::Io {
            path: shown.clone(),
            source,
        };
        let meta = std::fs::metadata(path).map_err(io)?;
        if !meta.is_file() {
            return Err(RecordError::NotARecord { path: shown });
        }
        let mut input = BufReader::new(std::fs::File::open(path).map_err(io)?);
        let mut head = [0u8; 8];
        if input.read_exact(&mut head).is_err() || head[..7] != MAGIC[..7] {
            return Err(RecordError::NotARecord { path: shown });
        }
        if head != MAGIC {
            return Err(RecordError::OtherVersion {
                path: shown,
                found: head[7],
                reads: MAGIC[7],
            });
        }
        Ok(RecordReader {
            input,
            path: shown,
            offset: 8,
            buf: Vec::new(),
            truncated_at: None,
            _t: PhantomData,
        })
    }

    /// Fills `buf` with exactly `n` bytes; false at a clean end, error inside a frame.
    fn fill(&mut self, n: usize) -> Result<usize, RecordError> {
        self.buf.resize(n, 0);
        let mut got = 0;
        while got < n {
            match self.input.read(&mut self.buf[got..]) {
                Ok(0) => break,
                Ok(k) => got += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(source) => {
                    return Err(RecordError::Io {
                        path: self.path.clone(),
                        source,
                    })
                }
            }
        }
        Ok(got)
    }

    /// The next record, `None` at the end of the file (or of its last whole frame).
    pub fn next_record(&mut self) -> Result<Option<T>, RecordError> {
        if self.truncated_at.is_some() {
            return Ok(None);
        }
        let got = self.fill(4)?;
        if got == 0 {
            return Ok(None);
        }
        if got < 4 {
            self.truncated_at = Some(self.offset);
            return Ok(None);
        }
        let len = u32::from_le_bytes([self.buf[0], self.buf[1], self.buf[2], self.buf[3]]);
        if len > MAX_FRAME {
            return Err(self.corrupt(format!("frame length {len} is absurd")));
        }
        let got = self.fill(len as usize)?;
        if got < len as usize {
            self.truncated_at = Some(self.offset);
            return Ok(None);
        }
        let decoded = bincode::serde::decode_from_slice::<T, _>(&self.buf, config());
        match decoded {
            Ok((v, used)) if used == len as usize => {
                self.offset += 4 + u64::from(len);
                Ok(Some(v))
            }
            Ok(_) => Err(self.corrupt("frame longer than its record".into())),
            Err(e) => Err(self.corrupt(e.to_string())),
        }
    }

    fn corrupt(&self, detail: String) -> RecordError {
        RecordError::Corrupt {
            path: self.path.clone(),
            offset: self.offset,
            detail,
        }
    }
}

/// Peak resident set size of this process so far, kB (0 if the kernel will not say).
pub fn peak_rss_kb() -> u64 {
    crate::sys::max_rss_kb()
}

#[cfg(test)]
mod tests {
    use super::*;

    type R = Record<u64, u64>;

    #[test]
    fn records_read_back_and_a_torn_frame_ends_the_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.rec");
        let mut w = RecordWriter::<R>::create(&path, false).expect("create");
        for n in 0..100u64 {
            w.write(&Record::Sample(n)).expect("write");
        }
        w.write(&Record::Event(Event {
            sample: 7,
            mono_ns: 1,
            what: "x".into(),
        }))
        .expect("write");
        drop(w);
        // A second segment appended, then a frame torn off mid-way.
        let mut w = RecordWriter::<R>::create(&path, true).expect("append");
        w.write(&Record::Sample(100)).expect("write");
        drop(w);
        let len = std::fs::metadata(&path).expect("meta").len();
        let mut bytes = std::fs::read(&path).expect("read");
        bytes.extend_from_slice(&[9, 0, 0, 0, 1, 2]);
        std::fs::write(&path, &bytes).expect("write");
        let mut r = RecordReader::<R>::open(&path).expect("open");
        let mut all = Vec::new();
        while let Some(rec) = r.next_record().expect("read") {
            all.push(rec);
        }
        assert_eq!(all.len(), 102);
        assert_eq!(all[0], Record::Sample(0));
        assert_eq!(all[101], Record::Sample(100));
        assert_eq!(r.truncated_at, Some(len));
    }

    #[test]
    fn garbage_is_refused_not_read() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.rec");
        std::fs::write(&path, b"hello world").expect("write");
        assert!(matches!(
            RecordReader::<R>::open(&path),
            Err(RecordError::NotARecord { .. })
        ));
        assert!(RecordWriter::<R>::create(&path, true).is_err());
        // A record of another build says which version it is.
        let mut old = MAGIC.to_vec();
        old[7] = 1;
        std::fs::write(&path, &old).expect("write");
        let e = match RecordReader::<R>::open(&path) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("a record of version 1 was opened"),
        };
        assert!(
            e.contains(&format!(
                "format version 1; this build reads version {}",
                MAGIC[7]
            )),
            "{e}"
        );
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&u32::MAX.to_le_bytes());
        std::fs::write(&path, &bytes).expect("write");
        let mut r = RecordReader::<R>::open(&path).expect("open");
        assert!(matches!(r.next_record(), Err(RecordError::Corrupt { .. })));
    }
}
