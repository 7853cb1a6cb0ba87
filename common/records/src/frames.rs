//! The record file's framing: an 8-byte magic, then frames of
//! `SYNC (4 bytes) | length (u32 LE) | CRC-32 of the body (u32 LE) | bincode body`.
//!
//! Every frame goes to the operating system in one `write` as soon as it is made (a
//! block of samples is one frame: [`crate::file`]). A frame torn by a kill, a full
//! disk or a power loss, or bytes corrupted anywhere, cost only the frames they touch:
//! the reader reports the stretch (where, how long) and resynchronises at the next
//! sync word that starts a frame whose checksum and body are whole. Appending (a
//! restarted node) first trims a torn tail, so the new segment starts on a frame.

use crate::ahead::Ahead;
use std::io::{BufReader, Read, Seek, Write};
use std::path::Path;
use thiserror::Error;

/// First bytes of every record file; the last byte is the format version.
pub const MAGIC: [u8; 8] = *b"TACTREC\x13";
/// The first bytes of every frame: where a reader picks up again after damage.
pub const SYNC: [u8; 4] = [0xA5, b'T', b'F', 0x5A];
/// Bytes before a frame's body: sync, length, checksum.
pub const HEADER: usize = 12;
/// Largest frame body a reader accepts; a longer length is damage.
pub const MAX_FRAME: u32 = 1 << 20;
/// Bytes a reader reads at a time while it resynchronises.
const CHUNK: usize = 1 << 16;
/// Damaged stretches a reader keeps the place of (the rest are counted).
pub const MAX_KEPT_DAMAGE: usize = 32;

/// bincode's standard encoding, with a limit: a length inside a whole frame (its
/// checksum right) can claim no more than a frame holds, so decoding damage never
/// tries to allocate gigabytes (the limit changes no byte written).
pub(crate) fn config() -> impl bincode::config::Config {
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
    /// A stop request came while the reader read through damage; asked again, it goes
    /// on from where it was.
    #[error("{path}: reading stopped by a stop request")]
    Stopped {
        /// The file.
        path: String,
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
#[cfg(test)]
pub(crate) fn frame(body: &[u8]) -> Vec<u8> {
    let mut f = vec![0; HEADER];
    f.extend_from_slice(body);
    seal(&mut f);
    f
}

/// Makes `f` a frame: fills its first [`HEADER`] bytes (left for it) for the body
/// after them. The writer encodes an entry straight after the room it leaves, so a
/// block is not copied into a frame of its own.
pub(crate) fn seal(f: &mut [u8]) {
    let (head, body) = f.split_at_mut(HEADER);
    head[..4].copy_from_slice(&SYNC);
    head[4..8].copy_from_slice(&u32::try_from(body.len()).unwrap_or(u32::MAX).to_le_bytes());
    head[8..].copy_from_slice(&crc32fast::hash(body).to_le_bytes());
}

/// Opens `path` for a node's writer: created afresh, or with `append` an existing
/// record (a restarted node of the same run) continued after its torn tail is trimmed;
/// a file that is not a record of this format is never touched.
pub(crate) fn open_for_writing(path: &Path, append: bool) -> std::io::Result<std::fs::File> {
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
    Ok(file)
}

/// The end of the last whole frame of an existing record: where an append goes.
pub(crate) fn whole_end(path: &Path) -> std::io::Result<u64> {
    // A file of another kind or version is the user's mistake (bad input), not a
    // failure of the disk: its kind says so to the node, which exits 2.
    let mut r = Frames::open(path).map_err(|e| match e {
        RecordError::Io { source, .. } => source,
        other => std::io::Error::new(std::io::ErrorKind::InvalidData, other.to_string()),
    })?;
    let mut end = r.offset;
    while r.next_frame(&|| false)? == Next::Frame {
        end = r.offset;
    }
    Ok(end)
}

/// What [`Frames::next_frame`] came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Next {
    /// A whole frame: its body is in [`Frames::body`].
    Frame,
    /// The end of the file.
    End,
    /// A stop request came while damage was being read through; asked again, the
    /// reader goes on from where it was.
    Stopped,
}

/// The frames of a record file, checked and resynchronised, in bounded memory and in
/// time linear in the file's size.
///
/// Frames are read in order, one header and one body at a time. Where no whole frame
/// starts, the reader looks for the next sync word that starts one, reading ahead
/// ([`Ahead`]); the bytes it read ahead are where it looks for frames until it is
/// past all it has read, so no byte is read more than twice (once by a frame that
/// proved damaged, once ahead) whatever the damage.
#[derive(Debug)]
pub(crate) struct Frames {
    input: BufReader<std::fs::File>,
    /// Where the next byte read from `input` comes from.
    pos: u64,
    /// Offset of the next frame.
    pub(crate) offset: u64,
    len: u64,
    /// The body of the frame just read.
    pub(crate) body: Vec<u8>,
    pub(crate) damage: Vec<Damage>,
    pub(crate) damaged_bytes: u64,
    pub(crate) damaged_stretches: u64,
    /// The bytes read ahead while resynchronising, while `offset` is before
    /// `read_to`.
    ahead: Option<Ahead>,
    /// The furthest offset read so far.
    read_to: u64,
    /// A piece of the file read ahead.
    chunk: Vec<u8>,
    /// Bytes read from the file in all: the work done, which a test bounds.
    pub(crate) bytes_read: u64,
}

impl Frames {
    pub(crate) fn open(path: &Path) -> Result<Frames, RecordError> {
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
            ahead: None,
            read_to: MAGIC.len() as u64,
            chunk: Vec::new(),
            bytes_read: 0,
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
        self.read_to = self.read_to.max(self.pos);
        self.bytes_read += got as u64;
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

    /// The first offset from `from` on where a whole frame starts (its body then in
    /// `self.body`), or the file's end; None if `stop` said so first. The bytes are
    /// read ahead into [`Ahead`], kept for the next frames.
    fn resync(&mut self, from: u64, stop: &dyn Fn() -> bool) -> std::io::Result<Option<u64>> {
        let mut ahead = self.ahead.take().unwrap_or_else(|| Ahead::new(from));
        let found = self.look(&mut ahead, from, stop);
        self.ahead = Some(ahead);
        found
    }

    /// [`Frames::resync`] through `ahead`.
    fn look(
        &mut self,
        ahead: &mut Ahead,
        from: u64,
        stop: &dyn Fn() -> bool,
    ) -> std::io::Result<Option<u64>> {
        let mut at = from.max(ahead.search);
        loop {
            ahead.search = at;
            if at + HEADER as u64 > self.len {
                return Ok(Some(self.len));
            }
            if ahead.end() < at + HEADER as u64 {
                ahead.forget_before(at);
                if !self.read_ahead(ahead, at + HEADER as u64, stop)? {
                    return Ok(None);
                }
                continue;
            }
            let Some(k) = ahead
                .bytes(at, ahead.end())
                .windows(SYNC.len())
                .position(|w| w == SYNC)
            else {
                // Keep the last bytes: a sync word may straddle what is read next.
                at = ahead.end() - (SYNC.len() - 1) as u64;
                continue;
            };
            at += k as u64;
            if at + HEADER as u64 > ahead.end() {
                continue;
            }
            let h = ahead.bytes(at, at + HEADER as u64);
            let len = u32::from_le_bytes([h[4], h[5], h[6], h[7]]);
            let crc = u32::from_le_bytes([h[8], h[9], h[10], h[11]]);
            let (body, end) = (at + HEADER as u64, at + HEADER as u64 + u64::from(len));
            if len <= MAX_FRAME && end <= self.len {
                ahead.forget_before(at);
                if !self.read_ahead(ahead, end, stop)? {
                    ahead.search = at;
                    return Ok(None);
                }
                if end <= ahead.end() && ahead.crc(body, end) == crc {
                    ahead.search = at;
                    self.body.clear();
                    self.body.extend_from_slice(ahead.bytes(body, end));
                    return Ok(Some(at));
                }
            }
            at += 1;
        }
    }

    /// Reads on into `ahead` until it holds the bytes up to `to` (or the file's end,
    /// which is moved up if the file proves shorter); false if `stop` said so first.
    fn read_ahead(
        &mut self,
        ahead: &mut Ahead,
        to: u64,
        stop: &dyn Fn() -> bool,
    ) -> std::io::Result<bool> {
        while ahead.end() < to.min(self.len) {
            if stop() {
                return Ok(false);
            }
            let n = CHUNK.min((self.len - ahead.end()) as usize);
            self.chunk.resize(n, 0);
            self.move_to(ahead.end())?;
            let mut chunk = std::mem::take(&mut self.chunk);
            let got = self.read_full(&mut chunk);
            self.chunk = chunk;
            let got = got?;
            if got == 0 {
                self.len = ahead.end();
                break;
            }
            ahead.push(&self.chunk[..got]);
        }
        Ok(true)
    }

    pub(crate) fn note_damage(&mut self, offset: u64, bytes: u64) {
        self.damaged_bytes += bytes;
        self.damaged_stretches += 1;
        if self.damage.len() < MAX_KEPT_DAMAGE {
            self.damage.push(Damage { offset, bytes });
        }
    }

    /// Advances to the next whole frame (its body in `self.body`). Damage on the way
    /// is noted and skipped; `stop` is looked at while damage is read through.
    pub(crate) fn next_frame(&mut self, stop: &dyn Fn() -> bool) -> std::io::Result<Next> {
        if self.offset >= self.len {
            return Ok(Next::End);
        }
        let at = self.offset;
        let found = if self.ahead.is_some() {
            self.resync(at, stop)?
        } else if self.frame_at(at)? {
            Some(at)
        } else {
            self.resync(at + 1, stop)?
        };
        let Some(start) = found else {
            return Ok(Next::Stopped);
        };
        if start > at {
            self.note_damage(at, start - at);
        }
        if start >= self.len {
            self.offset = self.len;
            self.ahead = None;
            return Ok(Next::End);
        }
        self.offset = start + (HEADER + self.body.len()) as u64;
        if self.offset >= self.read_to {
            // Past everything read: frames are read in order again.
            self.ahead = None;
        }
        Ok(Next::Frame)
    }
}

#[cfg(test)]
#[path = "resync_tests.rs"]
mod resync_tests;
