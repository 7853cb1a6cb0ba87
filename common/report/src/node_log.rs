//! What one node's record says about the node, everything but its samples: starts,
//! runs, events, counters, how it ended, what was damaged, and the sample rows the
//! join could not use (why each was left out is counted apart, so the report can say
//! which part of the run a figure comes from).

use std::path::PathBuf;
use tactile_records::{Damage, Record, Start, Totals};

/// Events kept per node in the report; further ones are counted, not kept, so a node
/// that broke a million times still gives a readable report.
pub const MAX_EVENTS: usize = 200;

/// What one node's record says about the node (everything but the samples).
#[derive(Debug, Clone)]
pub struct NodeLog<C> {
    /// The record file.
    pub path: PathBuf,
    /// One `Start` per segment (a restarted node appends a segment) whose start frame
    /// was read.
    pub starts: Vec<Start>,
    /// Segments whose `Start` frame was lost to damage: their records are kept (they
    /// follow the last whole start, or open the file).
    pub starts_lost: u64,
    /// Run tokens the node joined.
    pub runs: Vec<u64>,
    /// Events, as `(sample, what)`, at most [`MAX_EVENTS`].
    pub events: Vec<(u64, String)>,
    /// Events not kept.
    pub events_omitted: u64,
    /// Last counters of each segment.
    pub counters: Vec<Totals<C>>,
    /// How each segment ended: the `Stop` reason, or `None` where the file ends
    /// without one (the node was killed).
    pub stops: Vec<Option<String>>,
    /// Highest sample number in the record.
    pub last_sample: Option<u64>,
    /// Stretches of the record that held no whole frame (torn by a kill, corrupted),
    /// skipped: the first few, where and how long.
    pub damage: Vec<Damage>,
    /// Bytes and stretches skipped in all.
    pub damaged: (u64, u64),
    /// Sample records that matched no sample of the master (outside the window,
    /// or read after their sample was joined: out of order by more than the join
    /// looks ahead).
    pub unjoined: u64,
    /// Sample records numbered at or past the run's sample count (no sample of the
    /// run has such a number): dropped, never joined nor held.
    pub invalid: u64,
    /// Sample records for a sample number the record already gave (a second step, a
    /// second `Sent`, or more rows than a node writes for one sample): dropped.
    pub duplicates: u64,
}

impl<C> Default for NodeLog<C> {
    fn default() -> Self {
        NodeLog {
            path: PathBuf::new(),
            starts: Vec::new(),
            starts_lost: 0,
            runs: Vec::new(),
            events: Vec::new(),
            events_omitted: 0,
            counters: Vec::new(),
            stops: Vec::new(),
            last_sample: None,
            damage: Vec::new(),
            damaged: (0, 0),
            unjoined: 0,
            invalid: 0,
            duplicates: 0,
        }
    }
}

impl<C: Clone> NodeLog<C> {
    pub(crate) fn take<S>(&mut self, r: Record<S, C>) -> Option<S> {
        if self.stops.is_empty() && !matches!(r, Record::Start(_)) {
            // The file's first frame was damaged: its records still form a segment.
            self.starts_lost += 1;
            self.stops.push(None);
        }
        match r {
            Record::Start(s) => {
                self.starts.push(s);
                self.stops.push(None);
            }
            Record::Run(t) => {
                if !self.runs.contains(&t) {
                    self.runs.push(t);
                }
            }
            Record::Sample(s) => return Some(s),
            Record::Event(e) => {
                if self.events.len() < MAX_EVENTS {
                    self.events.push((e.sample, e.what));
                } else {
                    self.events_omitted += 1;
                }
            }
            Record::Counters(c) => {
                // The last counters of the current segment replace the earlier ones.
                if self.counters.len() < self.segments() {
                    self.counters.push(c);
                } else if let Some(last) = self.counters.last_mut() {
                    *last = c;
                }
            }
            Record::Stop(s) => {
                if let Some(last) = self.stops.last_mut() {
                    *last = Some(s.reason);
                }
            }
            // The reader hands a block's samples out one by one: none comes whole.
            Record::Samples(_) => {}
        }
        None
    }

    /// Sample rows the join left out, for any reason.
    pub fn left_out(&self) -> u64 {
        self.unjoined + self.invalid + self.duplicates
    }

    /// Segments in the record: one per start, read or lost.
    pub fn segments(&self) -> usize {
        self.stops.len()
    }

    /// Peak RSS over the segments, kB.
    pub fn peak_rss_kb(&self) -> u64 {
        self.counters
            .iter()
            .map(|c| c.peak_rss_kb)
            .max()
            .unwrap_or(0)
    }

    /// How the node's record ends, in words. `cut_short`: a stop request ended the
    /// reading at that sample, so a stop not seen may lie further on in the record.
    pub fn ending(&self, cut_short: Option<u64>) -> String {
        let last = self
            .last_sample
            .map_or("before any sample".to_string(), |n| {
                format!("after sample {n}")
            });
        match (self.stops.last(), cut_short) {
            (None, _) => "no start recorded".into(),
            (Some(Some(reason)), _) => format!("{reason}, {last}"),
            (Some(None), Some(n)) => format!(
                "not read to its end: the report was cut short at sample {n} by a stop request"
            ),
            (Some(None), None) => {
                format!("record ends {last} without a stop: the node was killed or crashed")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record read to its end without a stop is a killed node; one whose reading a
    /// stop request cut short says only that (its stop may lie further on).
    #[test]
    fn a_missing_stop_is_a_kill_only_when_the_record_was_read_to_its_end() {
        let log = NodeLog::<()> {
            stops: vec![None],
            last_sample: Some(14_334),
            ..NodeLog::default()
        };
        assert_eq!(
            log.ending(None),
            "record ends after sample 14334 without a stop: the node was killed or crashed"
        );
        assert_eq!(
            log.ending(Some(9_000)),
            "not read to its end: the report was cut short at sample 9000 by a stop request"
        );
        let stopped = NodeLog::<()> {
            stops: vec![Some("interrupted".into())],
            last_sample: Some(3),
            ..NodeLog::default()
        };
        assert_eq!(stopped.ending(Some(2)), "interrupted, after sample 3");
    }
}
