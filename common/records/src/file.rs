//! A record file written and read entry by entry: samples gathered into blocks of at
//! most 50 ms of the run ([`crate::block`], one frame each), every other entry (start,
//! run, event, counters, stop) a frame of its own, written at once.
//!
//! A block goes to the operating system when it is full, when 50 ms have passed since
//! its first sample (checked as samples come, every eighth), before any other entry,
//! and when the writer is dropped; so a node killed by SIGKILL loses at most the block
//! in hand, and damage on disk costs the blocks it touches, never the file.

use crate::block;
use crate::entry::{Record, SampleBlock};
use crate::frames::MAX_FRAME;
use crate::frames::{config, open_for_writing, seal, Damage, Frames, Next, RecordError, HEADER};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::VecDeque;
use std::io::Write;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use tactile_messages::clock::now_ns;

/// A block is written at the latest this long after its first sample, ns.
pub const BLOCK_NS: u64 = 50_000_000;

/// Bytes of a row encoded in one piece: more than any sample of the paper's arm or a
/// seven-joint arm takes.
const ROW: usize = 1024;

/// A block's rows, concatenated, each sample encoded straight into its place.
///
/// Before each row the buffer makes sure of a row's worth of room past the rows
/// (zeroed when it grows; it keeps its length between blocks), so a row is encoded in
/// place, with no copy: in the block bench, encoding into a separate slice and copying
/// took 1.6 times as long, through `io::Write` about three times. A row longer than
/// the room (a long arm's joints) goes through `io::Write`.
#[derive(Debug, Default)]
pub struct Rows {
    buf: Vec<u8>,
    used: usize,
}

impl Rows {
    /// Appends `sample`'s row and returns its length; on an error the rows are as
    /// they were (a half-encoded row would shift every later one).
    pub fn append<S: Serialize>(
        &mut self,
        sample: &S,
    ) -> Result<usize, bincode::error::EncodeError> {
        if self.buf.len() < self.used + ROW {
            self.buf.resize(self.used + ROW, 0);
        }
        let room = &mut self.buf[self.used..self.used + ROW];
        let n = match bincode::serde::encode_into_slice(sample, room, row_config()) {
            Err(bincode::error::EncodeError::UnexpectedEnd) => {
                self.buf.truncate(self.used);
                let long =
                    bincode::serde::encode_into_std_write(sample, &mut self.buf, row_config());
                if long.is_err() {
                    // What the failed encoding wrote past the rows.
                    self.buf.truncate(self.used);
                }
                long?
            }
            n => n?,
        };
        self.used += n;
        Ok(n)
    }

    /// The rows so far, concatenated.
    pub fn as_slice(&self) -> &[u8] {
        &self.buf[..self.used]
    }

    /// No rows (the buffer and its room kept).
    pub fn clear(&mut self) {
        self.used = 0;
    }
}

/// Samples of a block are encoded with fixed-width integers, so each field sits at
/// the same offset in rows of one shape ([`crate::block`]); with the frames' limit.
fn row_config() -> impl bincode::config::Config {
    bincode::config::standard()
        .with_fixed_int_encoding()
        .with_limit::<{ MAX_FRAME as usize }>()
}

/// The length of `entry`'s frame body as a [`RecordWriter`] encodes it, counted
/// without writing it: what a scenario's check measures a run's start entry with, so
/// it refuses what a node could not record.
pub fn body_len<E: Serialize>(entry: &E) -> Result<usize, bincode::error::EncodeError> {
    let mut size = bincode::enc::write::SizeWriter::default();
    bincode::serde::encode_into_writer(entry, &mut size, config())?;
    Ok(size.bytes_written)
}

/// An entry longer than a frame may be: a reader would take it for damage.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("a record of {len} bytes is longer than a frame may be ({MAX_FRAME} bytes)")]
pub struct TooLong {
    /// The entry's body, bytes.
    pub len: usize,
}

/// A frame body of `len` bytes, or [`TooLong`] past [`MAX_FRAME`].
pub fn fits(len: usize) -> Result<(), TooLong> {
    if len > MAX_FRAME as usize {
        return Err(TooLong { len });
    }
    Ok(())
}

/// Appends records to a node's file: entries one `write` each, samples a block at a
/// time.
pub struct RecordWriter<T> {
    file: std::fs::File,
    buf: Vec<u8>,
    /// The block in hand: its rows, and their lengths.
    rows: Rows,
    lens: Vec<usize>,
    started_ns: u64,
    block_rows: usize,
    planes: Vec<u8>,
    scratch: Vec<u8>,
    /// The block in hand packed: kept, so a block costs no allocation.
    packed: Vec<u8>,
    path: PathBuf,
    _t: PhantomData<fn(&T)>,
}

impl<T> std::fmt::Debug for RecordWriter<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordWriter")
            .field("path", &self.path)
            .field("pending", &self.lens.len())
            .field("block_rows", &self.block_rows)
            .finish()
    }
}

impl<T> RecordWriter<T> {
    /// Rows a block holds at most (a node's rows for 50 ms of its samples; never more
    /// than a reader accepts).
    pub fn set_block_rows(&mut self, rows: usize) {
        self.block_rows = rows.clamp(1, block::MAX_ROWS);
    }

    /// Writes the block in hand, if any (one frame, one system call).
    pub fn flush(&mut self) -> std::io::Result<()> {
        if self.lens.is_empty() {
            return Ok(());
        }
        let raw_len = block::pack(
            self.rows.as_slice(),
            &self.lens,
            &mut self.planes,
            &mut self.scratch,
            &mut self.packed,
        )?;
        let entry = Record::<(), ()>::Samples(SampleBlock {
            samples: u32::try_from(self.lens.len()).map_err(std::io::Error::other)?,
            raw_len,
            packed: crate::entry::Packed(std::mem::take(&mut self.packed)),
        });
        self.rows.clear();
        self.lens.clear();
        let put = self.put(&entry);
        if let Record::Samples(b) = entry {
            self.packed = b.packed.0;
        }
        put
    }

    fn put<E: Serialize>(&mut self, entry: &E) -> std::io::Result<()> {
        // The entry is encoded after room for the frame's header, filled in after.
        self.buf.clear();
        self.buf.resize(HEADER, 0);
        bincode::serde::encode_into_std_write(entry, &mut self.buf, config())
            .map_err(std::io::Error::other)?;
        // A reader would take a longer one for damage: refused here instead.
        fits(self.buf.len() - HEADER)
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))?;
        seal(&mut self.buf);
        self.file.write_all(&self.buf)
    }

    /// Cuts the file back to `len` bytes (a segment taken back out), the block in
    /// hand with it.
    pub fn truncate(&mut self, len: u64) -> std::io::Result<()> {
        self.rows.clear();
        self.lens.clear();
        self.file.set_len(len)
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl<T> Drop for RecordWriter<T> {
    /// However the writer goes (a node's error included), the block in hand is written.
    fn drop(&mut self) {
        if let Err(e) = self.flush() {
            tracing::warn!(
                "{}: the last block of samples was lost: {e}",
                self.path.display()
            );
        }
    }
}

impl<S: Serialize, C: Serialize> RecordWriter<Record<S, C>> {
    /// Creates `path` afresh, or with `append` continues an existing record file (a
    /// restarted node of the same run) after trimming a torn tail; a file that is not
    /// a record of this format is never touched.
    pub fn create(path: &Path, append: bool) -> std::io::Result<Self> {
        Ok(RecordWriter {
            file: open_for_writing(path, append)?,
            buf: Vec::with_capacity(512),
            rows: Rows::default(),
            lens: Vec::new(),
            started_ns: 0,
            block_rows: 1,
            planes: Vec::new(),
            scratch: Vec::new(),
            packed: Vec::new(),
            path: path.to_path_buf(),
            _t: PhantomData,
        })
    }

    /// Writes one record: a sample into the block in hand, anything else in a frame
    /// of its own at once (after the block, so the file keeps the order).
    pub fn write(&mut self, record: &Record<S, C>) -> std::io::Result<()> {
        match record {
            Record::Sample(s) => self.write_sample(s),
            other => {
                self.flush()?;
                self.put(other)
            }
        }
    }

    /// Adds one sample to the block in hand, written when full or 50 ms old.
    pub fn write_sample(&mut self, sample: &S) -> std::io::Result<()> {
        let len = self.rows.append(sample).map_err(std::io::Error::other)?;
        self.lens.push(len);
        let n = self.lens.len();
        if n == 1 {
            self.started_ns = now_ns();
        }
        // The clock is read every eighth sample: a block is late by a few samples at
        // most, for an eighth of the cost.
        if n >= self.block_rows
            || (n.is_multiple_of(8) && now_ns().saturating_sub(self.started_ns) >= BLOCK_NS)
        {
            self.flush()?;
        }
        Ok(())
    }
}

/// The run tokens a record holds (`Record::Run`), in order, each once; none if the
/// file cannot be read. Sample blocks are skipped unpacked.
pub fn runs_in(path: &Path) -> Vec<u64> {
    let mut runs = Vec::new();
    let Ok(mut r) = RecordReader::<crate::AnyRecord>::open(path) else {
        return runs;
    };
    r.samples = false;
    while let Ok(Some(rec)) = r.next_record() {
        if let Record::Run(t) = rec {
            if !runs.contains(&t) {
                runs.push(t);
            }
        }
    }
    runs
}

/// How many rows the whole sample blocks of a record hold, counted from the blocks'
/// headers without unpacking them; 0 if the file cannot be read. How far a node that
/// is still writing has got, in rows rather than bytes (a block's size depends on its
/// compression and on the node's block length, its row count does not). A row is one
/// of the role's sample entries: the slave writes one a sample, the master two (c(n)
/// sent, then q(n) come back or missed).
pub fn rows_in(path: &Path) -> u64 {
    let Ok(mut frames) = Frames::open(path) else {
        return 0;
    };
    let mut n = 0;
    while let Ok(Next::Frame) = frames.next_frame(&|| false) {
        let decoded =
            bincode::serde::decode_from_slice::<Record<(), ()>, _>(&frames.body, config());
        if let Ok((Record::Samples(b), _)) = decoded {
            n += u64::from(b.samples);
        }
    }
    n
}

/// Reads a record file back, record by record, in bounded memory: damaged stretches
/// are skipped and reported in [`RecordReader::damage`], never the whole file.
pub struct RecordReader<T> {
    frames: Frames,
    path: String,
    /// Samples of the block read last, not handed out yet.
    pending: VecDeque<T>,
    /// Whether sample blocks are unpacked (or skipped).
    samples: bool,
}

impl<T> std::fmt::Debug for RecordReader<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordReader")
            .field("path", &self.path)
            .field("pending", &self.pending.len())
            .finish()
    }
}

impl<S: DeserializeOwned, C: DeserializeOwned> RecordReader<Record<S, C>> {
    /// Opens a record file and checks its magic.
    pub fn open(path: &Path) -> Result<Self, RecordError> {
        Ok(RecordReader {
            frames: Frames::open(path)?,
            path: path.display().to_string(),
            pending: VecDeque::new(),
            samples: true,
        })
    }

    /// The next record, `None` at the end of the file. A frame whose checksum holds
    /// but whose body does not decode (another build's types) counts as damage too,
    /// and a block that does not unpack as a whole.
    pub fn next_record(&mut self) -> Result<Option<Record<S, C>>, RecordError> {
        self.next_record_until(&|| false)
    }

    /// [`RecordReader::next_record`], looking at `stop` (a stop request) while it
    /// reads through damage, which may be the whole file: once `stop` says so, the
    /// answer is [`RecordError::Stopped`].
    pub fn next_record_until(
        &mut self,
        stop: &dyn Fn() -> bool,
    ) -> Result<Option<Record<S, C>>, RecordError> {
        loop {
            if let Some(r) = self.pending.pop_front() {
                return Ok(Some(r));
            }
            let next = self
                .frames
                .next_frame(stop)
                .map_err(|source| RecordError::Io {
                    path: self.path.clone(),
                    source,
                })?;
            match next {
                Next::Frame => {}
                Next::End => return Ok(None),
                Next::Stopped => {
                    return Err(RecordError::Stopped {
                        path: self.path.clone(),
                    })
                }
            }
            let body = &self.frames.body;
            let decoded = bincode::serde::decode_from_slice::<Record<S, C>, _>(body, config());
            let whole = match decoded {
                Ok((Record::Samples(b), used)) if used == body.len() => {
                    !self.samples || self.unpack(&b)
                }
                Ok((r, used)) if used == body.len() => return Ok(Some(r)),
                _ => false,
            };
            if !whole {
                let bytes = (HEADER + self.frames.body.len()) as u64;
                let start = self.frames.offset - bytes;
                self.frames.note_damage(start, bytes);
            }
        }
    }

    /// Puts a block's samples in `pending`; false (and none of them) if any row does
    /// not decode.
    fn unpack(&mut self, b: &SampleBlock) -> bool {
        let Ok((rows, lens)) = block::unpack(b.samples, b.raw_len, &b.packed.0) else {
            return false;
        };
        let mut at = 0;
        for l in lens {
            let row = &rows[at..at + l];
            at += l;
            match bincode::serde::decode_from_slice::<S, _>(row, row_config()) {
                Ok((s, used)) if used == l => self.pending.push_back(Record::Sample(s)),
                _ => {
                    self.pending.clear();
                    return false;
                }
            }
        }
        true
    }

    /// The damaged stretches skipped so far (the first [`crate::frames::MAX_KEPT_DAMAGE`]).
    pub fn damage(&self) -> &[Damage] {
        &self.frames.damage
    }

    /// Bytes and stretches skipped so far, all of them.
    pub fn damaged(&self) -> (u64, u64) {
        (self.frames.damaged_bytes, self.frames.damaged_stretches)
    }

    /// Bytes read from the file so far: the reader's work, which stays within twice
    /// the file's size whatever damage it reads through.
    pub fn bytes_read(&self) -> u64 {
        self.frames.bytes_read
    }
}

/// The magic this build writes, for the tests' hand-made files.
#[cfg(test)]
pub(crate) const THIS_MAGIC: [u8; 8] = crate::frames::MAGIC;

#[cfg(test)]
#[path = "file_tests.rs"]
mod tests;
