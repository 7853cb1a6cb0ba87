//! The record file's framing: an 8-byte magic, then frames of
//! `SYNC (4 bytes) | length (u32 LE) | CRC-32 of the body (u32 LE) | bincode body`.
//!
//! Every frame goes to the operating system in one `write` as soon as it is made, so
//! whatever a node wrote before it was killed (even by SIGKILL) is in the file, and a
//! node holds no more than one frame in memory however long it runs. A frame torn by a
//! kill, a full disk or a power loss, or bytes corrupted anywhere, cost only the frames
//! they touch: the reader reports the stretch (where, how long) and resynchronises at
//! the next sync word that starts a frame whose checksum and body are whole. Appending
//! (a restarted node) first trims a torn tail, so the new segment starts on a frame.

use serde::de::DeserializeOwned;
use serde::Serialize;
use std::io::{BufReader, Read, Seek, Write};
use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// First bytes of every record file; the last byte is the format version.
pub const MAGIC: [u8; 8] = *b"TACTREC\x0a";
/// The first bytes of every frame: where a reader picks up again after damage.
pub const SYNC: [u8; 4] = [0xA5, b'T', b'F', 0x5A];
/// Bytes before a frame's body: sync, length, checksum.
pub const HEADER: usize = 12;
/// Largest frame body a reader accepts; a longer length is damage.
pub const MAX_FRAME: u32 = 1 << 20;
/// Damaged stretches a reader keeps the place of (the rest are counted).
pub const MAX_KEPT_DAMAGE: usize = 32;

/// bincode's standard encoding, with a limit: a length inside a whole frame (its
/// checksum right) can claim no more than a frame holds, so decoding damage never
/// tries to allocate gigabytes (the limit changes no byte written).
fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<{ MAX_FRAME as usize }>()
}

/// Failures of opening or reading a record.
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
}

/// A stretch of a record that held no whole frame, skipped by the reader.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Damage {
    /// Byte offset where it starts.
    pub offset: u64,
    /// Its length, bytes.
    pub bytes: u64,
}

/// One frame's bytes for `body`.
fn frame(body: &[u8]) -> Vec<u8> {
    let mut f = Vec::with_capacity(HEADER + body.len());
    f.extend_from_slice(&SYNC);
    f.extend_from_slice(&u32::try_from(body.len()).unwrap_or(u32::MAX).to_le_bytes());
    f.extend_from_slice(&crc32fast::hash(body).to_le_bytes());
    f.extend_from_slice(body);
    f
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
    /// restarted node of the same run) after trimming a torn tail; a file that is not
    /// a record of this format is never touched.
    pub fn create(path: &Path, append: bool) -> std::io::Result<Self> {
        // Locked before anything is cut: a second writer of this record (two nodes
        // of one role given one --out) is refused with the first's record intact.
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)?;
        rustix::fs::flock(&file, rustix::fs::FlockOperation::NonBlockingLockExclusive).map_err(
            |_| {
                std::io::Error::new(
                    std::io::ErrorKind::WouldBlock,
                    "another process is writing this record (a node of the same role with the same --out)",
                )
            },
        )?;
        // A file killed before its magic was whole holds nothing: started afresh.
        let len = file.metadata()?.len();
        let started = len >= MAGIC.len() as u64 || {
            let mut head = Vec::new();
            (&file).read_to_end(&mut head)?;
            !MAGIC.starts_with(&head)
        };
        if append && len > 0 && started {
            let end = whole_end(path)?;
            file.set_len(end)?;
            file.seek(std::io::SeekFrom::End(0))?;
        } else {
            file.set_len(0)?;
            file.rewind()?;
            file.write_all(&MAGIC)?;
        }
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
        bincode::serde::encode_into_std_write(record, &mut self.buf, config())
            .map_err(std::io::Error::other)?;
        if self.buf.len() > MAX_FRAME as usize {
            // A reader would take it for damage: refuse it here instead.
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "a record of {} bytes is longer than a frame may be",
                    self.buf.len()
                ),
            ));
        }
        self.file.write_all(&frame(&self.buf))
    }

    /// Cuts the file back to `len` bytes (a segment taken back out).
    pub fn truncate(&mut self, len: u64) -> std::io::Result<()> {
        self.file.set_len(len)
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// The end of the last whole frame of an existing record: where an append goes.
fn whole_end(path: &Path) -> std::io::Result<u64> {
    let mut r = Frames::open(path).map_err(|e| std::io::Error::other(e.to_string()))?;
    let mut end = r.offset;
    while r.next_frame()? {
        end = r.offset;
    }
    Ok(end)
}

/// The run tokens a record holds (`Record::Run`), in order, each once; none if the
/// file cannot be read. Every other frame is skipped undecoded.
pub fn runs_in(path: &Path) -> Vec<u64> {
    let mut runs = Vec::new();
    let Ok(mut r) = RecordReader::<crate::AnyRecord>::open(path) else {
        return runs;
    };
    while let Ok(Some(rec)) = r.next_record() {
        if let crate::Record::Run(t) = rec {
            if !runs.contains(&t) {
                runs.push(t);
            }
        }
    }
    runs
}

/// The frames of a record file, checked and resynchronised, in bounded memory.
#[derive(Debug)]
struct Frames {
    input: BufReader<std::fs::File>,
    /// Where the next byte read from `input` comes from.
    pos: u64,
    /// Offset of the next frame.
    offset: u64,
    len: u64,
    /// The body of the frame just read.
    body: Vec<u8>,
    damage: Vec<Damage>,
    damaged_bytes: u64,
    damaged_stretches: u64,
}

impl Frames {
    fn open(path: &Path) -> Result<Frames, RecordError> {
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
        Ok(Frames {
            input,
            pos: MAGIC.len() as u64,
            offset: MAGIC.len() as u64,
            len: meta.len(),
            body: Vec::new(),
            damage: Vec::new(),
            damaged_bytes: 0,
            damaged_stretches: 0,
        })
    }

    /// Reads up to `buf.len()` bytes; the count read (short only at the end).
    fn read_full(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let mut got = 0;
        while got < buf.len() {
            match self.input.read(&mut buf[got..]) {
                Ok(0) => break,
                Ok(k) => got += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        self.pos += got as u64;
        Ok(got)
    }

    /// Moves the input to `at`; frames read in order need no seek, and a move within
    /// the buffer keeps it.
    fn move_to(&mut self, at: u64) -> std::io::Result<()> {
        if at != self.pos {
            self.input.seek_relative(at as i64 - self.pos as i64)?;
            self.pos = at;
        }
        Ok(())
    }

    /// Whether a whole frame starts at `at`; if so its body is in `self.body` and
    /// the input stands after it.
    fn frame_at(&mut self, at: u64) -> std::io::Result<bool> {
        if at + HEADER as u64 > self.len {
            return Ok(false);
        }
        self.move_to(at)?;
        let mut h = [0u8; HEADER];
        if self.read_full(&mut h)? < HEADER || h[..4] != SYNC {
            return Ok(false);
        }
        let len = u32::from_le_bytes([h[4], h[5], h[6], h[7]]);
        let crc = u32::from_le_bytes([h[8], h[9], h[10], h[11]]);
        if len > MAX_FRAME || at + (HEADER as u64) + u64::from(len) > self.len {
            return Ok(false);
        }
        let mut body = std::mem::take(&mut self.body);
        body.resize(len as usize, 0);
        let got = self.read_full(&mut body)?;
        let whole = got == body.len() && crc32fast::hash(&body) == crc;
        self.body = body;
        Ok(whole)
    }

    /// The first offset after `from` where a whole frame starts, or the file's end.
    fn resync(&mut self, from: u64) -> std::io::Result<u64> {
        let mut at = from;
        let mut chunk = vec![0u8; 1 << 16];
        while at + HEADER as u64 <= self.len {
            self.move_to(at)?;
            let n = self.read_full(&mut chunk)?;
            let Some(k) = chunk[..n].windows(SYNC.len()).position(|w| w == SYNC) else {
                // Keep the last bytes: a sync word may straddle the chunks.
                at += n.saturating_sub(SYNC.len() - 1).max(1) as u64;
                continue;
            };
            let candidate = at + k as u64;
            if self.frame_at(candidate)? {
                return Ok(candidate);
            }
            at = candidate + 1;
        }
        Ok(self.len)
    }

    fn note_damage(&mut self, offset: u64, bytes: u64) {
        self.damaged_bytes += bytes;
        self.damaged_stretches += 1;
        if self.damage.len() < MAX_KEPT_DAMAGE {
            self.damage.push(Damage { offset, bytes });
        }
    }

    /// Advances to the next whole frame (its body in `self.body`); false at the end.
    /// Damage on the way is noted and skipped.
    fn next_frame(&mut self) -> std::io::Result<bool> {
        if self.offset >= self.len {
            return Ok(false);
        }
        let at = self.offset;
        let start = if self.frame_at(at)? {
            at
        } else {
            let next = self.resync(at + 1)?;
            self.note_damage(at, next - at);
            next
        };
        if start >= self.len {
            self.offset = self.len;
            return Ok(false);
        }
        self.offset = start + (HEADER + self.body.len()) as u64;
        Ok(true)
    }
}

/// Reads a record file back, record by record, in bounded memory: damaged stretches
/// are skipped and reported in [`RecordReader::damage`], never the whole file.
#[derive(Debug)]
pub struct RecordReader<T> {
    frames: Frames,
    path: String,
    _t: PhantomData<fn() -> T>,
}

impl<T: DeserializeOwned> RecordReader<T> {
    /// Opens a record file and checks its magic.
    pub fn open(path: &Path) -> Result<Self, RecordError> {
        Ok(RecordReader {
            frames: Frames::open(path)?,
            path: path.display().to_string(),
            _t: PhantomData,
        })
    }

    /// The next record, `None` at the end of the file. A frame whose checksum holds
    /// but whose body does not decode (another build's types) counts as damage too.
    pub fn next_record(&mut self) -> Result<Option<T>, RecordError> {
        loop {
            let more = self.frames.next_frame().map_err(|source| RecordError::Io {
                path: self.path.clone(),
                source,
            })?;
            if !more {
                return Ok(None);
            }
            let body = &self.frames.body;
            match bincode::serde::decode_from_slice::<T, _>(body, config()) {
                Ok((v, used)) if used == body.len() => return Ok(Some(v)),
                _ => {
                    let bytes = (HEADER + body.len()) as u64;
                    let start = self.frames.offset - bytes;
                    self.frames.note_damage(start, bytes);
                }
            }
        }
    }

    /// The damaged stretches skipped so far (the first [`MAX_KEPT_DAMAGE`]).
    pub fn damage(&self) -> &[Damage] {
        &self.frames.damage
    }

    /// Bytes and stretches skipped so far, all of them.
    pub fn damaged(&self) -> (u64, u64) {
        (self.frames.damaged_bytes, self.frames.damaged_stretches)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    type R = (u64, String);

    fn write(path: &Path, n: u64) -> Vec<(u64, u64)> {
        let mut w = RecordWriter::<R>::create(path, false).expect("create");
        let mut spans = Vec::new();
        for k in 0..n {
            let start = std::fs::metadata(path).expect("meta").len();
            w.write(&(k, "x".repeat((k % 7) as usize))).expect("write");
            spans.push((start, std::fs::metadata(path).expect("meta").len()));
        }
        spans
    }

    fn read(path: &Path) -> (Vec<u64>, u64) {
        let mut r = RecordReader::<R>::open(path).expect("open");
        let mut got = Vec::new();
        while let Some((k, _)) = r.next_record().expect("read") {
            got.push(k);
        }
        (got, r.damaged().1)
    }

    #[test]
    fn a_torn_tail_is_trimmed_before_appending_and_nothing_whole_is_lost() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.rec");
        write(&path, 50);
        let len = std::fs::metadata(&path).expect("meta").len();
        let f = std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .expect("open");
        f.set_len(len - 7).expect("cut 7 bytes");
        let (got, damaged) = read(&path);
        assert_eq!(got, (0..49).collect::<Vec<_>>());
        assert_eq!(damaged, 1, "the torn tail is one damaged stretch");
        let mut w = RecordWriter::<R>::create(&path, true).expect("append");
        w.write(&(100, String::new())).expect("write");
        drop(w);
        let (got, damaged) = read(&path);
        assert_eq!(got.len(), 50);
        assert_eq!(got.last(), Some(&100));
        assert_eq!(damaged, 0, "the append trimmed the torn frame");
    }

    #[test]
    fn a_record_killed_before_its_magic_was_whole_starts_afresh_on_append() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.rec");
        std::fs::write(&path, &MAGIC[..3]).expect("write");
        let mut w = RecordWriter::<R>::create(&path, true).expect("append");
        w.write(&(1, String::new())).expect("write");
        drop(w);
        assert_eq!(read(&path), (vec![1], 0));
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
        let mut old = MAGIC.to_vec();
        old[7] = 4;
        std::fs::write(&path, &old).expect("write");
        let e = RecordReader::<R>::open(&path)
            .map(|_| ())
            .expect_err("version 4");
        let want = format!("format version 4; this build reads version {}", MAGIC[7]);
        assert!(e.to_string().contains(&want), "{e}");
    }

    #[test]
    fn a_whole_frame_claiming_a_huge_string_is_damage_not_a_crash() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.rec");
        write(&path, 3);
        // (7, a string of 2^62 bytes) in bincode's varints, in a frame whose checksum
        // holds: a writer of another build, or an attacker.
        let mut body = vec![7u8, 0xFD];
        body.extend_from_slice(&(1u64 << 62).to_le_bytes());
        body.extend_from_slice(b"abc");
        let mut bytes = std::fs::read(&path).expect("read");
        bytes.extend_from_slice(&frame(&body));
        std::fs::write(&path, &bytes).expect("write");
        let mut w = RecordWriter::<R>::create(&path, true).expect("append");
        w.write(&(9, String::new())).expect("write");
        drop(w);
        assert_eq!(read(&path), (vec![0, 1, 2, 9], 1));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Random cuts and corrupted stretches: every frame none of whose bytes was
        /// touched is read back, in order, and nothing else.
        #[test]
        fn no_whole_frame_is_lost(
            cut in 0usize..4000,
            stretches in proptest::collection::vec((0usize..4000, 1usize..40, any::<u8>()), 0..4),
        ) {
            let dir = tempfile::tempdir().expect("tempdir");
            let path = dir.path().join("x.rec");
            let spans = write(&path, 200);
            let mut bytes = std::fs::read(&path).expect("read");
            let magic = MAGIC.len();
            let cut = magic + cut.min(bytes.len() - magic);
            let mut touched = vec![false; bytes.len()];
            for (at, n, v) in &stretches {
                let at = magic + at % (bytes.len() - magic);
                for i in at..(at + n).min(bytes.len()) {
                    if bytes[i] != *v {
                        bytes[i] = *v;
                        touched[i] = true;
                    }
                }
            }
            bytes.truncate(cut.max(magic));
            std::fs::write(&path, &bytes).expect("write");
            let whole: Vec<u64> = spans
                .iter()
                .enumerate()
                .filter(|(_, (s, e))| {
                    (*e as usize) <= bytes.len() && !touched[*s as usize..*e as usize].contains(&true)
                })
                .map(|(k, _)| k as u64)
                .collect();
            let (got, _) = read(&path);
            prop_assert_eq!(got, whole);
        }
    }
}
