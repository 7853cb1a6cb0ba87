//! One node's record read for the join: front to back once, through a look-ahead
//! window keyed by sample number, in memory bounded whatever the file holds.
//!
//! A record is in sample order but for the entries a node writes late (an answer, a
//! backward passage: within [`LATE_WINDOW`] samples). A crafted or damaged record need
//! not be: so every row is checked before it is held. A number at or past the run's
//! sample count is no sample of the run (counted `invalid`); a number already joined
//! is counted `unjoined` at once; more than [`PER_SAMPLE`] rows of one number are
//! counted `duplicates`. None of these is held, so a file of a million copies of one
//! row costs its reading time and no memory. A sample whose rows are not all in (its
//! `Sent` and its answer or miss; a step; a passage each way) is looked for up to
//! [`REORDER_ROWS`] rows further on, so a block written out of its place (two blocks
//! swapped) still joins; a sample that truly lacks a row (a hold, a lost packet, the
//! run's last) costs only that read-ahead, made once and kept.

use crate::node_log::NodeLog;
use crate::Error;
use std::collections::BTreeMap;
use std::path::PathBuf;
use tactile_messages::samples::LATE_WINDOW;
use tactile_records::{Record, RecordError, RecordReader};

/// Rows of one sample number a source holds: more than any node writes for one
/// sample in a segment (the master: a `Sent`, an answer or a miss; the emulator: a
/// passage each way), with room for a restarted node's second segment.
pub(crate) const PER_SAMPLE: usize = 8;

/// Rows a source holds at most while it looks ahead for a sample's missing rows: the
/// largest block a writer makes (about 7 MB of the paper arm's rows); a block of a
/// 1 kHz run (50 samples) may be this many rows out of its place and still join.
pub(crate) const REORDER_ROWS: usize = tactile_records::block::MAX_ROWS;

/// Whether a sample's rows, as held, are all a node writes for it.
pub(crate) type Complete<S> = fn(&mut dyn Iterator<Item = &S>) -> bool;

/// How a node's rows are read: a row's sample number (None: a row of no sample),
/// and whether a sample's rows are all in.
pub(crate) type Keys<S> = (fn(&S) -> Option<u64>, Complete<S>);

/// Records read between two looks at the stop request (a look may read the clock).
const STOP_EVERY: u64 = 4096;

/// One record file read through a look-ahead window, keyed by sample number.
pub(crate) struct Source<S, C> {
    reader: Option<RecordReader<Record<S, C>>>,
    pub(crate) log: NodeLog<C>,
    /// The rows held, by sample number, in the order read.
    ahead: BTreeMap<u64, Vec<S>>,
    /// Rows in `ahead`.
    held: usize,
    /// Highest sample number held so far.
    front: Option<u64>,
    /// Samples below this one were joined: a row of one comes too late.
    floor: u64,
    /// The run's sample count: numbers from here on are no sample of the run.
    limit: u64,
    key: fn(&S) -> Option<u64>,
    complete: Complete<S>,
    /// Records read, for the stop request's look.
    read: u64,
    /// A stop request came while reading: the join ends.
    pub(crate) stopped: bool,
}

impl<S, C> Source<S, C>
where
    S: serde::de::DeserializeOwned,
    C: Clone + serde::de::DeserializeOwned,
{
    /// Opens `path` (None: the node left no record); numbers from `limit` on are
    /// counted invalid.
    pub(crate) fn open(
        path: Option<PathBuf>,
        limit: u64,
        (key, complete): Keys<S>,
    ) -> Result<Self, Error> {
        let mut log = NodeLog::default();
        let reader = match path {
            Some(p) => {
                log.path = p.clone();
                Some(RecordReader::open(&p).map_err(|e| Error::BadInput(e.to_string()))?)
            }
            None => None,
        };
        Ok(Source {
            reader,
            log,
            ahead: BTreeMap::new(),
            held: 0,
            front: None,
            floor: 0,
            limit,
            key,
            complete,
            read: 0,
            stopped: false,
        })
    }

    /// Whether to read on for sample `n`: until a row past `n + LATE_WINDOW` is in
    /// (every row of `n` a node writes in order is then read), and while a row of
    /// `n` is missing, until [`REORDER_ROWS`] rows are held.
    fn wants(&self, n: u64) -> bool {
        if self
            .front
            .is_none_or(|f| f <= n.saturating_add(LATE_WINDOW))
        {
            return true;
        }
        let whole = self
            .ahead
            .get(&n)
            .is_some_and(|rows| (self.complete)(&mut rows.iter()));
        self.held < REORDER_ROWS && !whole
    }

    /// Reads on for sample `n` (see [`Source::wants`]), or to the file's end.
    fn fill_to(&mut self, n: u64, stop: &dyn Fn() -> bool) -> Result<(), Error> {
        while !self.stopped && self.wants(n) {
            let Some(reader) = self.reader.as_mut() else {
                return Ok(());
            };
            let next = match reader.next_record_until(stop) {
                Ok(next) => next,
                Err(RecordError::Stopped { .. }) => {
                    self.stopped = true;
                    return Ok(());
                }
                Err(e) => return Err(Error::Failed(e.to_string())),
            };
            let Some(rec) = next else {
                self.close();
                return Ok(());
            };
            self.read += 1;
            if self.read.is_multiple_of(STOP_EVERY) && stop() {
                self.stopped = true;
            }
            if let Some(s) = self.log.take(rec) {
                if let Some(k) = (self.key)(&s) {
                    self.hold(k, s);
                }
            }
        }
        Ok(())
    }

    /// Holds row `s` of sample `k`, or counts why not.
    fn hold(&mut self, k: u64, s: S) {
        if k >= self.limit {
            self.log.invalid += 1;
            return;
        }
        self.log.last_sample = Some(self.log.last_sample.map_or(k, |l| l.max(k)));
        if k < self.floor {
            self.log.unjoined += 1;
            return;
        }
        let rows = self.ahead.entry(k).or_default();
        if rows.len() >= PER_SAMPLE {
            self.log.duplicates += 1;
            return;
        }
        rows.push(s);
        self.held += 1;
        self.front = Some(self.front.map_or(k, |f| f.max(k)));
    }

    /// Stops reading, keeping what the reader skipped as damage.
    fn close(&mut self) {
        if let Some(reader) = self.reader.take() {
            self.log.damage = reader.damage().to_vec();
            self.log.damaged = reader.damaged();
        }
    }

    /// The first sample after `n` with a row held (a sample missing from the record
    /// is a gap, not its end: the join goes on from the next one there is).
    pub(crate) fn next_after(&self, n: u64) -> Option<u64> {
        self.ahead
            .range(n.saturating_add(1)..)
            .next()
            .map(|(k, _)| *k)
    }

    /// The log as read so far (a join cut short).
    pub(crate) fn into_log(mut self) -> NodeLog<C> {
        self.close();
        self.log
    }

    /// The rows of sample `n`; rows of earlier samples are counted as unjoined, and
    /// so is any row of them read from now on.
    pub(crate) fn take(&mut self, n: u64, stop: &dyn Fn() -> bool) -> Result<Vec<S>, Error> {
        // Raised before reading: when the master's spine jumps far ahead, the rows
        // between are counted as they are read, not held until this sample is in
        // (they would be counted unjoined anyway, and held they cost memory in
        // proportion to the file).
        self.floor = self.floor.max(n);
        self.fill_to(n, stop)?;
        while let Some(entry) = self.ahead.first_entry() {
            if *entry.key() >= n {
                break;
            }
            let stale = entry.remove().len();
            self.held -= stale;
            self.log.unjoined += stale as u64;
        }
        let rows = self.ahead.remove(&n).unwrap_or_default();
        self.held -= rows.len();
        self.floor = self.floor.max(n.saturating_add(1));
        Ok(rows)
    }

    /// Reads the rest of the file (for its events and counters): every sample row
    /// left is counted, none held.
    pub(crate) fn finish(mut self, stop: &dyn Fn() -> bool) -> Result<NodeLog<C>, Error> {
        self.log.unjoined += self.held as u64;
        self.ahead.clear();
        self.held = 0;
        self.floor = u64::MAX;
        self.front = None;
        while self.reader.is_some() && !self.stopped {
            self.fill_to(u64::MAX, stop)?;
        }
        // Only a row numbered u64::MAX itself (with no sample count known) is held.
        self.log.unjoined += self.held as u64;
        self.close();
        Ok(self.log)
    }
}
