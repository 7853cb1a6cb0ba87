//! Joins the nodes' records into one row per sample.
//!
//! The master's record is the spine: one `Sent` per sample, then an `Answer` or a
//! `Miss`. The emulator's passages and the slave's steps for the same sample number
//! are matched to it. Every file is read front to back once, each through a look-ahead
//! window of [`LATE_WINDOW`] samples (the same window inside which the master matches
//! late answers), so joining a run of any length takes bounded memory. The records may
//! come from one folder or one folder per node, as they would from different hosts.

use crate::trace::{Stamps, TraceRow};
use crate::Error;
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use tactile_messages::samples::{stage, LATE_WINDOW};
use tactile_messages::Role;
use tactile_records::emulator::{Direction, EmulatorTotals, Passage};
use tactile_records::master::{Answer, MasterSample, MasterTotals, Miss, Sent};
use tactile_records::slave::{ArmJoints, SlaveSample, SlaveTotals, Step};
use tactile_records::{record_path, Damage, Record, RecordReader, Start, Totals};

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
    /// Sample records that matched no sample of the master (outside the window).
    pub unjoined: u64,
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
        }
    }
}

impl<C: Clone> NodeLog<C> {
    fn take<S>(&mut self, r: Record<S, C>) -> Option<S> {
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

    /// How the node's record ends, in words.
    pub fn ending(&self) -> String {
        let last = self
            .last_sample
            .map_or("before any sample".to_string(), |n| {
                format!("after sample {n}")
            });
        match self.stops.last() {
            None => "no start recorded".into(),
            Some(Some(reason)) => format!("{reason}, {last}"),
            Some(None) => {
                format!("record ends {last} without a stop: the node was killed or crashed")
            }
        }
    }
}

/// One record file read through a look-ahead window, keyed by sample number.
struct Source<S, C> {
    reader: Option<RecordReader<Record<S, C>>>,
    log: NodeLog<C>,
    ahead: BTreeMap<u64, Vec<S>>,
    /// Highest key read so far.
    front: Option<u64>,
    key: fn(&S) -> Option<u64>,
}

impl<S, C: Clone + serde::de::DeserializeOwned> Source<S, C>
where
    S: serde::de::DeserializeOwned,
{
    fn open(path: Option<PathBuf>, key: fn(&S) -> Option<u64>) -> Result<Self, Error> {
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
            front: None,
            key,
        })
    }

    /// Reads until a record past `n + LATE_WINDOW` is in, or the file ends.
    fn fill_to(&mut self, n: u64) -> Result<(), Error> {
        while self.front.is_none_or(|f| f <= n + LATE_WINDOW) {
            let Some(reader) = self.reader.as_mut() else {
                return Ok(());
            };
            let next = reader
                .next_record()
                .map_err(|e| Error::Failed(e.to_string()))?;
            let Some(rec) = next else {
                self.close();
                return Ok(());
            };
            if let Some(s) = self.log.take(rec) {
                if let Some(k) = (self.key)(&s) {
                    self.front = Some(self.front.map_or(k, |f| f.max(k)));
                    self.log.last_sample = Some(self.log.last_sample.map_or(k, |l| l.max(k)));
                    self.ahead.entry(k).or_default().push(s);
                }
            }
        }
        Ok(())
    }

    /// Stops reading, keeping what the reader skipped as damage.
    fn close(&mut self) {
        if let Some(reader) = self.reader.take() {
            self.log.damage = reader.damage().to_vec();
            self.log.damaged = reader.damaged();
        }
    }

    /// True if records of samples after `n` are waiting (a sample missing from the
    /// record is a gap, not its end).
    fn has_after(&self, n: u64) -> bool {
        self.ahead.keys().next_back().is_some_and(|&k| k > n)
    }

    /// The log as read so far (a join cut short).
    fn into_log(mut self) -> NodeLog<C> {
        self.close();
        self.log
    }

    /// The records of sample `n`; records of earlier samples are counted as unjoined.
    fn take(&mut self, n: u64) -> Result<Vec<S>, Error> {
        self.fill_to(n)?;
        while let Some(entry) = self.ahead.first_entry() {
            if *entry.key() >= n {
                break;
            }
            self.log.unjoined += entry.remove().len() as u64;
        }
        Ok(self.ahead.remove(&n).unwrap_or_default())
    }

    /// Reads the rest of the file (for its events and counters).
    fn finish(mut self) -> Result<NodeLog<C>, Error> {
        self.fill_to(u64::MAX - LATE_WINDOW)?;
        self.log.unjoined += self.ahead.values().map(|v| v.len() as u64).sum::<u64>();
        Ok(self.log)
    }
}

/// The three nodes' logs after a join.
#[derive(Debug, Clone)]
pub struct Logs {
    /// The master's.
    pub master: NodeLog<MasterTotals>,
    /// The emulator's (empty if it left no record).
    pub emulator: NodeLog<EmulatorTotals>,
    /// The slave's (empty if it left no record).
    pub slave: NodeLog<SlaveTotals>,
}

/// Finds each role's record in `dirs`: every role at most once, the master's required.
pub fn locate(dirs: &[PathBuf]) -> Result<[Option<PathBuf>; 3], Error> {
    let mut found: [Option<PathBuf>; 3] = [None, None, None];
    for dir in dirs {
        if !dir.is_dir() {
            return Err(Error::BadInput(format!(
                "{} is not a folder",
                dir.display()
            )));
        }
        for (k, role) in Role::ALL.into_iter().enumerate() {
            let p = record_path(dir, role);
            if p.exists() {
                if let Some(other) = &found[k] {
                    return Err(Error::BadInput(format!(
                        "two {role} records, {} and {}: give the folders of one run",
                        other.display(),
                        p.display()
                    )));
                }
                found[k] = Some(p);
            }
        }
    }
    if found[0].is_none() {
        let shown: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
        return Err(Error::BadInput(format!(
            "no master.rec in {}: the master's record is the spine of a report",
            shown.join(", ")
        )));
    }
    Ok(found)
}

/// The first whole `Start` of a record, read without joining (a frame of any role's
/// record decodes as a `Start` alike: the variant does not depend on the samples'
/// type). A damaged first frame costs only itself: the next segment's start is taken,
/// or none if the record holds no other.
fn first_start(path: &Path) -> Result<Option<Start>, Error> {
    let mut r = RecordReader::<tactile_records::AnyRecord>::open(path)
        .map_err(|e| Error::BadInput(e.to_string()))?;
    loop {
        match r.next_record() {
            Ok(Some(Record::Start(s))) => return Ok(Some(s)),
            Ok(Some(_)) => {}
            Ok(None) => return Ok(None),
            Err(e) => return Err(Error::BadInput(e.to_string())),
        }
    }
}

/// The first `Start` of each node's record (None where a node left no record or its
/// starts were all lost), read without joining: the master's holds the scenario, each
/// one its clock domain. A record whose start names another role than its file is
/// refused: renamed or copied files would otherwise join as nothing.
pub fn starts(found: &[Option<PathBuf>; 3]) -> Result<[Option<Start>; 3], Error> {
    let mut out: [Option<Start>; 3] = [None, None, None];
    for ((slot, path), role) in out.iter_mut().zip(found).zip(Role::ALL) {
        let Some(path) = path else { continue };
        let Some(start) = first_start(path)? else {
            continue;
        };
        if start.role != role.name() {
            return Err(Error::BadInput(format!(
                "{} holds the {}'s record, not the {role}'s: a renamed or misplaced file? \
                 (each record is read under its role's name, {role}.rec)",
                path.display(),
                start.role
            )));
        }
        *slot = Some(start);
    }
    Ok(out)
}

fn master_key(s: &MasterSample) -> Option<u64> {
    Some(match s {
        MasterSample::Sent(x) => x.n,
        MasterSample::Answer(x) => x.n,
        MasterSample::Miss(x) => x.n,
    })
}

fn passage_key(p: &Passage) -> Option<u64> {
    Some(p.n)
}

fn slave_key(s: &SlaveSample) -> Option<u64> {
    s.step().map(|x| x.n)
}

/// What the master recorded for one sample: what went out, and what came back or
/// what it did without.
#[derive(Debug, Clone, Copy)]
struct MasterPart {
    sent: Sent,
    answer: Option<Answer>,
    miss: Option<Miss>,
}

impl MasterPart {
    /// The master's entries of a sample, or None if its Sent was lost.
    fn of(items: &[MasterSample]) -> Option<MasterPart> {
        let mut part = MasterPart {
            sent: items.iter().find_map(|x| match x {
                MasterSample::Sent(s) => Some(*s),
                _ => None,
            })?,
            answer: None,
            miss: None,
        };
        for x in items {
            match x {
                MasterSample::Answer(a) if part.answer.is_none() => part.answer = Some(*a),
                MasterSample::Miss(m) if part.miss.is_none() => part.miss = Some(*m),
                _ => {}
            }
        }
        Some(part)
    }

    /// The master's columns.
    fn fill(&self, r: &mut TraceRow) {
        let sent = &self.sent;
        (r.n, r.target, r.theta_md, r.c) = (sent.n, sent.target, sent.theta_md, sent.c);
        (r.handle, r.hand_force) = (sent.handle, sent.hand_force);
        r.stamps[stage::MASTER_TICK] = sent.tick_ns;
        r.stamps[stage::MASTER_SEND] = sent.send_ns;
        if let Some(a) = &self.answer {
            r.received = true;
            (r.q, r.delay_b, r.flags_b) = (a.q.value, a.q.delay_samples, a.q.flags);
            (r.q_from, r.q_origin) = (a.q.sent_seq, a.q.origin_seq);
            (r.round_trip_ns, r.overhead_ns) = (a.round_trip_ns, a.overhead_ns);
            r.stamps = Stamps(a.stamps);
        }
        let effect = self
            .answer
            .map(|a| a.effect)
            .or(self.miss.map(|m| m.effect));
        if let Some(e) = effect {
            (r.tau, r.felt, r.flags_m, r.observer_m) = (e.tau, e.felt, e.flags, e.observer);
            (r.dissipated_m, r.port_net_m) = (e.dissipated_j, e.port_net_j);
        }
    }
}

/// The emulator's columns of a sample.
fn fill_passages(r: &mut TraceRow, passages: &[Passage]) {
    for p in passages {
        match p.dir {
            Direction::Forward => {
                r.noise_f = p.noise;
                r.delay_f = p.out.delay_samples;
            }
            Direction::Backward => r.noise_b = p.noise,
        }
    }
}

/// The slave's columns of a sample.
fn fill_step(r: &mut TraceRow, s: &Step) {
    r.stepped = true;
    (r.v, r.delay_f, r.flags_f) = (s.received.value, s.received.delay_samples, s.received.flags);
    (r.theta_ref, r.reference) = (s.theta_ref, s.reference);
    (r.observer_s, r.port_net_s, r.dissipated_s) = (s.observer, s.port_net_j, s.dissipated_j);
    (r.theta_sd, r.u, r.tool, r.surface, r.h) = (s.theta, s.torque, s.tool, s.surface, s.force);
    r.contact_object = if s.contact_object == u32::MAX {
        -1
    } else {
        i64::from(s.contact_object)
    };
}

/// Builds sample n's row from what each node recorded for it.
fn row(master: &MasterPart, passages: &[Passage], step: Option<&Step>) -> TraceRow {
    let mut r = TraceRow {
        contact_object: -1,
        ..TraceRow::default()
    };
    master.fill(&mut r);
    fill_passages(&mut r, passages);
    if let Some(s) = step {
        fill_step(&mut r, s);
    }
    r
}

/// The three records, read sample by sample.
struct Sources {
    master: Source<MasterSample, MasterTotals>,
    emulator: Source<Passage, EmulatorTotals>,
    slave: Source<SlaveSample, SlaveTotals>,
}

impl Sources {
    /// The logs so far (`whole`: read to the end, checking what remains).
    fn logs(self, whole: bool) -> Result<Logs, Error> {
        let logs = if whole {
            Logs {
                master: self.master.finish()?,
                emulator: self.emulator.finish()?,
                slave: self.slave.finish()?,
            }
        } else {
            Logs {
                master: self.master.into_log(),
                emulator: self.emulator.into_log(),
                slave: self.slave.into_log(),
            }
        };
        check_one_run(&logs)?;
        Ok(logs)
    }
}

/// Joins the records found in `dirs`, handing each sample's row to `each` in order,
/// with a URDF arm's joints where the slave is one and a 6-DoF master's orientation.
/// `each` may stop the join early (a stop request): the logs then hold what was read
/// so far.
pub fn join(
    dirs: &[PathBuf],
    mut each: impl FnMut(
        &TraceRow,
        Option<&ArmJoints>,
        Option<[f64; 4]>,
    ) -> Result<ControlFlow<()>, Error>,
) -> Result<Logs, Error> {
    let [m, e, s] = locate(dirs)?;
    let mut src = Sources {
        master: Source::open(m, master_key)?,
        emulator: Source::open(e, passage_key)?,
        slave: Source::open(s, slave_key)?,
    };
    let mut n = 0u64;
    loop {
        let Some(part) = MasterPart::of(&src.master.take(n)?) else {
            // A sample the master's record lost (a damaged stretch): skipped, the
            // rest joined; past the last one, the end.
            if src.master.has_after(n) {
                n += 1;
                continue;
            }
            return src.logs(true);
        };
        let passages = src.emulator.take(n)?;
        let steps = src.slave.take(n)?;
        let (step, joints) = steps
            .iter()
            .find_map(|x| match x {
                SlaveSample::Step(s) => Some((Some(*s), None)),
                SlaveSample::ArmStep(s, j) => Some((Some(*s), Some(&**j))),
                SlaveSample::Hold(_) | SlaveSample::ArmHold(..) => None,
            })
            .unwrap_or((None, None));
        let rotation = part.sent.rotation;
        if each(&row(&part, &passages, step.as_ref()), joints, rotation)?.is_break() {
            return src.logs(false);
        }
        n += 1;
    }
}

/// Refuses records of different runs: the nodes of one run share the master's token,
/// and each record holds one run (a node appended into another run's record).
fn check_one_run(logs: &Logs) -> Result<(), Error> {
    let Some(&token) = logs.master.runs.first() else {
        return Ok(());
    };
    for (role, runs, path) in [
        (Role::Master, &logs.master.runs, &logs.master.path),
        (Role::Emulator, &logs.emulator.runs, &logs.emulator.path),
        (Role::Slave, &logs.slave.runs, &logs.slave.path),
    ] {
        if let Some(other) = runs.iter().find(|&&t| t != token) {
            let whose = if role == Role::Master {
                "a later segment of the same record".to_string()
            } else {
                format!("the master's record {}", logs.master.path.display())
            };
            return Err(Error::BadInput(format!(
                "the {role}'s record {} holds run {other:016x}, {whose} run {token:016x}: not one run (a node started with --append into another run's record?)",
                path.display()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "join_tests.rs"]
mod tests;
