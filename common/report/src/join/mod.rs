//! Joins the nodes' records into one row per sample.
//!
//! The master's record is the spine: one `Sent` per sample, then an `Answer` or a
//! `Miss`. The emulator's passages and the slave's steps for the same sample number
//! are matched to it. Every file is read front to back once, each through a look-ahead
//! window of `LATE_WINDOW` samples (the same window inside which the master matches
//! late answers; [`crate::source`] says what else it bounds), so joining a run of any
//! length, or a crafted record of any content, takes bounded memory. The records may
//! come from one folder or one folder per node, as they would from different hosts.

pub use crate::node_log::{NodeLog, MAX_EVENTS};
use crate::source::Source;
use crate::trace::{Stamps, TraceRow};
use crate::Error;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use tactile_messages::samples::stage;
use tactile_messages::Role;
use tactile_records::emulator::{Direction, EmulatorTotals, Passage};
use tactile_records::master::{Answer, MasterSample, MasterTotals, Miss, Sent};
use tactile_records::slave::{ArmJoints, SlaveSample, SlaveTotals, Step, WorldSample};
use tactile_records::{record_path, Record, RecordError, RecordReader, Start};

/// The three nodes' logs after a join.
#[derive(Debug, Clone)]
pub struct Logs {
    /// The master's.
    pub master: NodeLog<MasterTotals>,
    /// The emulator's (empty if it left no record).
    pub emulator: NodeLog<EmulatorTotals>,
    /// The slave's (empty if it left no record).
    pub slave: NodeLog<SlaveTotals>,
    /// A stop request ended the join before this sample: the logs hold what was
    /// read by then.
    pub stopped_at: Option<u64>,
    /// The run's sample count applied: rows numbered from here on were counted
    /// `invalid` (u64::MAX: no start known, none refused).
    pub limit: u64,
    /// Nodes whose start claims another sample count than the one applied.
    pub disagree: Vec<(Role, u64)>,
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

/// The `Start` a record opens with, read without joining (a frame of any role's
/// record decodes as a `Start` alike: the variant does not depend on the samples'
/// type). Only the first whole frame is looked at: nothing precedes a start, and
/// reading on for a later segment's would read a whole crafted file. A damaged start
/// frame leaves the node's start unknown. Damage before the first whole frame is read
/// through looking at `stop`, a stop request.
fn first_start(path: &Path, stop: &dyn Fn() -> bool) -> Result<Option<Start>, Error> {
    let mut r = RecordReader::<tactile_records::AnyRecord>::open(path)
        .map_err(|e| Error::BadInput(e.to_string()))?;
    match r.next_record_until(stop) {
        Ok(Some(Record::Start(s))) => Ok(Some(s)),
        Ok(_) => Ok(None),
        Err(e @ RecordError::Stopped { .. }) => Err(Error::Stopped(format!(
            "{e} before its start was read: no report written"
        ))),
        Err(e) => Err(Error::BadInput(e.to_string())),
    }
}

/// The first `Start` of each node's record (None where a node left no record or its
/// starts were all lost), read without joining: the master's holds the scenario, each
/// one its clock domain. A record whose start names another role than its file is
/// refused: renamed or copied files would otherwise join as nothing.
pub fn starts(
    found: &[Option<PathBuf>; 3],
    stop: &dyn Fn() -> bool,
) -> Result<[Option<Start>; 3], Error> {
    let mut out: [Option<Start>; 3] = [None, None, None];
    for ((slot, path), role) in out.iter_mut().zip(found).zip(Role::ALL) {
        let Some(path) = path else { continue };
        let Some(start) = first_start(path, stop)? else {
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

/// A sample's rows of the master are all in: its `Sent`, and its answer or miss.
fn master_whole(rows: &mut dyn Iterator<Item = &MasterSample>) -> bool {
    let (mut sent, mut answered) = (false, false);
    for r in rows {
        match r {
            MasterSample::Sent(_) => sent = true,
            MasterSample::Answer(_) | MasterSample::Miss(_) => answered = true,
        }
    }
    sent && answered
}

/// A sample's passages are all in: one each way.
fn passages_whole(rows: &mut dyn Iterator<Item = &Passage>) -> bool {
    let (mut forward, mut backward) = (false, false);
    for p in rows {
        match p.dir {
            Direction::Forward => forward = true,
            Direction::Backward => backward = true,
        }
    }
    forward && backward
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
    /// The master's entries of a sample, or None if its Sent was lost; a second
    /// `Sent` of one sample, or more than an answer and a miss, is counted in
    /// `duplicates`, the first kept.
    fn of(items: &[MasterSample], duplicates: &mut u64) -> Option<MasterPart> {
        let sents = items
            .iter()
            .filter(|x| matches!(x, MasterSample::Sent(_)))
            .count();
        let answers = items.len() - sents;
        *duplicates += (sents.saturating_sub(1) + answers.saturating_sub(2)) as u64;
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
            r.model_injected_m = e.model_injected_j;
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
    (r.stepped, r.flags_s) = (true, s.flags);
    (r.v, r.delay_f, r.flags_f) = (s.received.value, s.received.delay_samples, s.received.flags);
    r.reference = s.reference;
    (r.observer_s, r.port_net_s, r.dissipated_s) = (s.observer, s.port_net_j, s.dissipated_j);
    (r.tool, r.surface, r.h) = (s.tool, s.surface, s.force);
    let m = &s.model;
    (r.model_seq, r.model_normal, r.model_offset, r.model_k) =
        (m.seq, m.normal, m.offset, m.stiffness);
    r.contact_object = if s.contact_object == u32::MAX {
        -1
    } else {
        i64::from(s.contact_object)
    };
}

/// The paper arm's columns of a sample: its three angles, their reference and FCS's
/// torques (a URDF arm's joints go to joints.csv, and these stay zero).
fn fill_paper_arm(r: &mut TraceRow, j: &ArmJoints) {
    (r.theta_ref, r.theta_sd, r.u) = (j.q_ref.to_array3(), j.q.to_array3(), j.tau.to_array3());
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
    /// The sample count applied, and the starts that claim another.
    limit: (u64, Vec<(Role, u64)>),
}

impl Sources {
    /// Opens the records found; sample numbers from `limit` on are no sample of the
    /// run.
    fn open(found: [Option<PathBuf>; 3], limit: (u64, Vec<(Role, u64)>)) -> Result<Sources, Error> {
        let [m, e, s] = found;
        let n = limit.0;
        Ok(Sources {
            limit,
            master: Source::open(m, n, (master_key, master_whole))?,
            emulator: Source::open(e, n, (passage_key, passages_whole))?,
            slave: Source::open(s, n, (slave_key, |rows| rows.next().is_some()))?,
        })
    }

    /// True once a stop request came while a record was read.
    fn stopped(&self) -> bool {
        self.master.stopped || self.emulator.stopped || self.slave.stopped
    }

    /// The logs so far (`whole`: read to the end, checking what remains; a stop
    /// request then still ends the reading, and the logs say where the join was).
    fn logs(self, at: u64, whole: bool, stop: &dyn Fn() -> bool) -> Result<Logs, Error> {
        let (limit, disagree) = self.limit;
        let mut logs = if whole {
            Logs {
                master: self.master.finish(stop)?,
                emulator: self.emulator.finish(stop)?,
                slave: self.slave.finish(stop)?,
                stopped_at: None,
                limit,
                disagree,
            }
        } else {
            Logs {
                master: self.master.into_log(),
                emulator: self.emulator.into_log(),
                slave: self.slave.into_log(),
                stopped_at: Some(at),
                limit,
                disagree,
            }
        };
        if whole && stop() {
            logs.stopped_at = Some(at);
        }
        check_one_run(&logs)?;
        Ok(logs)
    }
}

/// The run's sample count: the master's start's (the master sets how many samples
/// the run has; no node's start may lift it for the others), or where the master's
/// start was lost the smallest another node claims; without a start none is known and
/// no number is refused. With it, the nodes whose start claims another count.
fn sample_count(
    found: &[Option<PathBuf>; 3],
    stop: &dyn Fn() -> bool,
) -> Result<(u64, Vec<(Role, u64)>), Error> {
    let starts = starts(found, stop)?;
    let claims: Vec<(Role, u64)> = Role::ALL
        .into_iter()
        .zip(&starts)
        .filter_map(|(role, s)| s.as_ref().map(|s| (role, s.samples)))
        .collect();
    let limit = match &starts[0] {
        Some(m) => m.samples,
        None => claims.iter().map(|c| c.1).min().unwrap_or(u64::MAX),
    };
    let disagree = claims.into_iter().filter(|c| c.1 != limit).collect();
    Ok((limit, disagree))
}

/// The slave's step of a sample, with the arm's joints; further steps of the same
/// sample are counted in `duplicates`.
fn step_of<'a>(
    steps: &'a [SlaveSample],
    duplicates: &mut u64,
) -> (Option<Step>, Option<&'a ArmJoints>, Option<&'a WorldSample>) {
    let mut all = steps.iter().filter_map(|x| match x {
        SlaveSample::Step(s, j, w) => Some((Some(*s), Some(j), w.as_ref())),
        SlaveSample::Hold(..) => None,
    });
    let first = all.next().unwrap_or((None, None, None));
    *duplicates += all.count() as u64;
    first
}

/// Samples joined between two looks at the stop request.
const STOP_EVERY: u64 = 1024;

/// Which arm the slave's joints are: the paper's (in the trace's three-angle columns)
/// or a URDF arm's (handed over for joints.csv and the task space).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Arm {
    /// No `[slave.arm]`: the paper's three joints.
    Paper,
    /// `[slave.arm]`: a chain from its URDF.
    Urdf,
}

impl Arm {
    /// The scenario's arm.
    pub fn of(scenario: &tactile_scenario::Scenario) -> Arm {
        match scenario.slave.arm {
            Some(_) => Arm::Urdf,
            None => Arm::Paper,
        }
    }
}

/// What a sample joins besides its trace row: the slave's arm where it is a URDF arm,
/// a 6-DoF master's orientation, and a physics world's state after the slave's step.
#[derive(Debug, Clone, Copy, Default)]
pub struct Joined<'a> {
    /// A URDF arm's joints (the paper arm's are in the row).
    pub joints: Option<&'a ArmJoints>,
    /// A 6-DoF master's orientation, `[x, y, z, w]`.
    pub rotation: Option<[f64; 4]>,
    /// A physics world after the slave's step (`engine = "physics"`).
    pub world: Option<&'a WorldSample>,
}

/// Joins the records found in `dirs`, handing each sample's row to `each` in order,
/// with a URDF arm's joints where the slave is one (`arm`) and a 6-DoF master's
/// orientation. `each` may stop the join early: the logs then hold what was read so
/// far.
pub fn join(
    dirs: &[PathBuf],
    arm: Arm,
    each: impl FnMut(&TraceRow, &Joined) -> Result<ControlFlow<()>, Error>,
) -> Result<Logs, Error> {
    join_until(dirs, &|| false, arm, each)
}

/// [`join`], looking at `stop` (a stop request) as it reads, however long a record
/// makes it read: once it says so, the join ends with what it has, and the logs say
/// at which sample ([`Logs::stopped_at`]).
pub fn join_until(
    dirs: &[PathBuf],
    stop: &dyn Fn() -> bool,
    arm: Arm,
    mut each: impl FnMut(&TraceRow, &Joined) -> Result<ControlFlow<()>, Error>,
) -> Result<Logs, Error> {
    let found = locate(dirs)?;
    let limit = sample_count(&found, stop)?;
    let mut src = Sources::open(found, limit)?;
    let (mut n, mut turn) = (0u64, 0u64);
    loop {
        turn += 1;
        let items = src.master.take(n, stop)?;
        if src.stopped() || (turn % STOP_EVERY == 0 && stop()) {
            return src.logs(n, false, stop);
        }
        let Some(part) = MasterPart::of(&items, &mut src.master.log.duplicates) else {
            // A sample the master's record lost (a damaged stretch): skipped, the
            // rest joined from the next sample it holds; past the last one, the end.
            match src.master.next_after(n) {
                Some(next) => n = next,
                None => return src.logs(n, true, stop),
            }
            continue;
        };
        let passages = src.emulator.take(n, stop)?;
        let steps = src.slave.take(n, stop)?;
        if src.stopped() {
            return src.logs(n, false, stop);
        }
        let (step, joints, world) = step_of(&steps, &mut src.slave.log.duplicates);
        let rotation = part.sent.rotation;
        let mut r = row(&part, &passages, step.as_ref());
        let joints = match (arm, joints) {
            (Arm::Paper, Some(j)) => {
                fill_paper_arm(&mut r, j);
                None
            }
            (_, j) => j,
        };
        let of = Joined {
            joints,
            rotation,
            world,
        };
        if each(&r, &of)?.is_break() {
            return src.logs(n, false, stop);
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
mod tests;
