//! The run's report from the nodes' records, and the files it writes: `tactile report`
//! and `tactile run` (when its nodes have stopped) both call [`write_report`].

use crate::analysis::{Analysis, STAGES};
use crate::join::{self, Logs, NodeLog};
use crate::metrics::Packets;
use crate::plots::Series;
use crate::run_mcap;
use crate::streams::Streams;
pub use crate::streams::{Outputs, TraceFormat, PARQUET_FILE};
use crate::summary::{ChannelCount, Clocks, MasterPart, ModelCounts, NodeSummary, Summary};
pub use crate::summary::{JOINTS_FILE, REPORT_FILES};
use crate::Error;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactile_messages::Role;
use tactile_records::emulator::EmulatorTotals;
use tactile_records::master::MasterTotals;
use tactile_records::slave::SlaveTotals;
use tactile_records::Start;
use tactile_scenario::Scenario;

/// The link name an in-process simulation records.
pub const IN_PROCESS: &str = "in-process";

/// What the launcher adds to a report (nothing, for `tactile report`).
#[derive(Debug, Clone, Default)]
pub struct Launch {
    /// The launcher's own events (deaths, restarts, stop requests), first in the list.
    pub events: Vec<String>,
    /// What the launcher said of the run before it started (the scenario's warnings
    /// and its inputs', a trajectory shorter than the run): first in the summary's
    /// warnings. The scenario's own are added however the report is made.
    pub warnings: Vec<String>,
    /// A node died during the run.
    pub failed: bool,
    /// A stop request cut the run short.
    pub interrupted: bool,
    /// The trace's and the recording's files.
    pub outputs: Outputs,
    /// A stop request (SIGINT, SIGTERM): set, the report is written from the samples
    /// joined so far and says it was interrupted.
    pub stop: Option<Arc<AtomicBool>>,
    /// Past this instant the report stops joining and is written from what it has
    /// (a run stopped by a signal must end within a second; its records keep every
    /// sample for `tactile report`).
    pub until: Option<Instant>,
}

impl Launch {
    /// Whether the report is to stop joining: a stop request came, or its deadline
    /// passed.
    fn stopped(&self) -> bool {
        self.stop.as_ref().is_some_and(|f| f.load(Ordering::SeqCst))
            || self.until.is_some_and(|u| Instant::now() >= u)
    }

    /// The report of a run a stop request cut short: interrupted, and written within
    /// a moment from what can be joined by then.
    pub fn interrupted(mut self) -> Launch {
        self.interrupted = true;
        self.until = Some(Instant::now() + Duration::from_millis(700));
        // The request that cut the run is in the flag already: the deadline bounds
        // this report instead.
        self.stop = None;
        self
    }
}

pub fn write_file(path: &Path, text: &str) -> Result<(), Error> {
    crate::out::write_file(path, text)
}

/// Removes what a failed report had started (its temporary files).
fn discard(out: &Path) {
    run_mcap::discard(out);
    let _ = std::fs::remove_file(crate::out::partial(&out.join("trace.csv")));
    let _ = std::fs::remove_file(crate::out::partial(&out.join(PARQUET_FILE)));
    let _ = std::fs::remove_file(crate::out::partial(&out.join(JOINTS_FILE)));
}

pub use crate::out::make_out_dir;

/// Writes `value` as pretty JSON to `path`.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<(), Error> {
    let mut text = serde_json::to_string_pretty(value)
        .map_err(|e| Error::Failed(format!("encoding {}: {e}", path.display())))?;
    text.push('\n');
    write_file(path, &text)
}

/// Adds the counters of a later segment to `acc`: every number is summed, arrays
/// element by element, except the maxima (a key with `max` in its name), which take
/// the larger value, and the minima (`min`), the smaller one that is not zero (no
/// sample).
fn add_json(acc: &mut serde_json::Value, more: &serde_json::Value, key: &str) {
    use serde_json::Value;
    match (acc, more) {
        (Value::Object(a), Value::Object(b)) => {
            for (k, v) in b {
                if let Some(x) = a.get_mut(k) {
                    add_json(x, v, k);
                }
            }
        }
        (Value::Array(a), Value::Array(b)) => {
            for (x, y) in a.iter_mut().zip(b) {
                add_json(x, y, key);
            }
        }
        (x @ Value::Number(_), Value::Number(b)) => {
            let sum = if let (Some(p), Some(q)) = (x.as_u64(), b.as_u64()) {
                if key == "min" {
                    Value::from(if p == 0 || q == 0 { p.max(q) } else { p.min(q) })
                } else if key.contains("max") {
                    Value::from(p.max(q))
                } else {
                    Value::from(p.saturating_add(q))
                }
            } else {
                let (p, q) = (x.as_f64().unwrap_or(0.0), b.as_f64().unwrap_or(0.0));
                Value::from(if key.contains("max") { p.max(q) } else { p + q })
            };
            *x = sum;
        }
        _ => {}
    }
}

/// A node's counters summed over its segments (a restarted node has several).
fn summed<C: Serialize + DeserializeOwned + Clone>(log: &NodeLog<C>) -> Option<C> {
    let mut it = log.counters.iter();
    let first = it.next()?.counters.clone();
    let mut acc = serde_json::to_value(&first).ok()?;
    for c in it {
        let v = serde_json::to_value(&c.counters).ok()?;
        add_json(&mut acc, &v, "");
    }
    serde_json::from_value(acc).ok().or(Some(first))
}

/// A node's line of the summary; `cut_short`: a stop request ended the join at that
/// sample, so a record may hold more than was read.
fn node_summary<C>(log: &NodeLog<C>, cut_short: Option<u64>) -> Option<NodeSummary>
where
    C: Clone,
{
    if log.segments() == 0 {
        return None;
    }
    Some(NodeSummary {
        record: log.path.display().to_string(),
        hosts: log.starts.iter().map(|s| s.host.clone()).collect(),
        pids: log.starts.iter().map(|s| s.pid).collect(),
        digest: crate::summary::digest(&log.path),
        link: log
            .starts
            .first()
            .map_or_else(|| "unknown (start lost)".into(), |s| s.link.clone()),
        peak_rss_kb: log.peak_rss_kb(),
        last_sample: log.last_sample,
        ended: log.ending(cut_short),
        unjoined: log.unjoined,
        invalid: log.invalid,
        duplicates: log.duplicates,
        damaged_bytes: log.damaged.0,
        damaged_stretches: log.damaged.1,
        damage: log.damage.iter().map(|d| [d.offset, d.bytes]).collect(),
        sched: log
            .starts
            .last()
            .map(|s| s.sched.clone())
            .unwrap_or_default(),
    })
}

/// The node's events, after what the report itself saw of its record: none at all, or
/// a start lost to damage.
fn events<C: Clone>(role: Role, log: &NodeLog<C>, out: &mut Vec<String>) -> u64 {
    if log.path.as_os_str().is_empty() {
        out.push(format!(
            "{role}: no {role}.rec among the records reported: its columns are empty"
        ));
    } else if log.starts_lost > 0 {
        out.push(format!(
            "{role}: {} segment start(s) lost to damage in {}; the segment's records are kept",
            log.starts_lost,
            log.path.display()
        ));
    }
    out.extend(
        log.events
            .iter()
            .map(|(n, what)| format!("{role}, sample {n}: {what}")),
    );
    log.events_omitted
}

/// True if node `k` (0 master, 1 emulator, 2 slave) left no record.
fn logs_missing(logs: &Logs, k: usize) -> bool {
    match k {
        0 => logs.master.segments() == 0,
        1 => logs.emulator.segments() == 0,
        _ => logs.slave.segments() == 0,
    }
}

/// Why a lockstep run has no system overhead.
pub const LOCKSTEP_OVERHEAD: &str = "lockstep: each sample starts when the last is done, so the \
     wall-clock time of a round trip holds the other samples computed meanwhile, not the \
     injected delay; the round trip is in samples";

/// Each stream's count from the totals of its two ends.
fn channels(
    m: &MasterTotals,
    emulator: Option<&EmulatorTotals>,
    slave: Option<&SlaveTotals>,
) -> BTreeMap<&'static str, ChannelCount> {
    let mut channels = BTreeMap::new();
    let Some(e) = emulator else {
        return channels;
    };
    let k = &e.counters;
    channels.insert("c", ChannelCount::new(m.c_out, 0, e.links.c_in));
    let q = ChannelCount::new(e.links.q_out, k.backward_dropped, m.q_in);
    channels.insert("q", q);
    if let Some(s) = slave {
        let v = ChannelCount::new(e.links.v_out, k.forward_dropped, s.v_in);
        channels.insert("v", v);
        channels.insert("h", ChannelCount::new(s.h_out, 0, e.links.h_in));
    }
    channels
}

/// Each node that left a record, summarised.
fn nodes(logs: &Logs) -> BTreeMap<&'static str, NodeSummary> {
    [
        (Role::Master, node_summary(&logs.master, logs.stopped_at)),
        (
            Role::Emulator,
            node_summary(&logs.emulator, logs.stopped_at),
        ),
        (Role::Slave, node_summary(&logs.slave, logs.stopped_at)),
    ]
    .into_iter()
    .filter_map(|(role, n)| Some((role.name(), n?)))
    .collect()
}

/// Whether the nodes share a clock, their domains, and the offsets estimated.
fn clocks(a: &Analysis, logs: &Logs) -> Clocks {
    Clocks {
        shared: (0..3).all(|k| a.same_clock(0, k) || logs_missing(logs, k)),
        domains: Role::ALL
            .iter()
            .zip(a.domains())
            .filter(|(_, d)| !d.is_empty())
            .map(|(r, d)| (r.name(), d.clone()))
            .collect(),
        offsets: a.clock_offsets(),
    }
}

/// The summary from the joined statistics and the nodes' logs.
/// The headline tracking error: the tool against its target after the master's map
/// (a URDF arm's task space, where the clutch's offsets and the workspace box are
/// known), else the tool against v(n) (the paper's arm, whose map is the identity).
/// One meaning for every arm and device: the trace's figure against v(n) read 80.5 mm
/// on `panda-reach.toml` for a robot within 0.7 mm of its target (it stays in
/// `master.motion`).
fn headline_tracking(s: &Summary) -> Option<f64> {
    match &s.task_space {
        Some(ts) => ts.position_rms_m,
        None => s.master.motion.tracking_rms_m,
    }
}

fn summarise(
    scenario: &Scenario,
    runner: &'static str,
    a: &Analysis,
    logs: &Logs,
    launch: &Launch,
) -> Summary {
    let master_totals = summed(&logs.master).unwrap_or_default();
    let emulator = summed(&logs.emulator);
    let slave = summed(&logs.slave);
    let mut ev = launch.events.clone();
    let omitted = events(Role::Master, &logs.master, &mut ev)
        + events(Role::Emulator, &logs.emulator, &mut ev)
        + events(Role::Slave, &logs.slave, &mut ev);
    let elapsed = master_totals.elapsed_ns;
    let lockstep = scenario.mode == tactile_scenario::Mode::Lockstep;
    let samples = a.round_trip_samples.percentiles();
    let hardware = crate::hardware::summary(
        &master_totals.counters.rtl,
        &slave.as_ref().map(|s| s.counters.rtl).unwrap_or_default(),
        scenario
            .cordic
            .config()
            .ok()
            .zip(scenario.device.geometry().ok()),
    );
    let mut warnings = launch.warnings.clone();
    for w in scenario.warnings() {
        if !warnings.contains(&w) {
            warnings.push(w);
        }
    }
    warnings.extend(crate::warnings::warnings(
        a,
        logs,
        master_totals.counters.sent,
        slave.as_ref().map(|s| &s.counters),
    ));
    warnings.extend(crate::warnings::devices_rejected(
        &master_totals.device,
        slave.as_ref().map(|s| &s.device),
    ));
    warnings.extend(
        slave
            .as_ref()
            .and_then(|s| crate::warnings::world_faults(&s.world)),
    );
    Summary {
        scenario: scenario.name.clone(),
        mode: scenario.mode,
        rate_hz: scenario.rate_hz,
        arithmetic: scenario.arithmetic.to_string(),
        runner,
        run: logs.master.runs.first().map(|t| format!("{t:016x}")),
        round_trip_ns: a.round_trip.percentiles(),
        round_trip_ms_nominal: samples
            .filter(|_| lockstep)
            .map(|p| p.p50 as f64 * scenario.t_s() * 1e3),
        round_trip_samples: samples,
        overhead_ns: a.overhead.percentiles().filter(|_| !lockstep),
        overhead_na: (lockstep && a.received > 0).then_some(LOCKSTEP_OVERHEAD),
        overhead_negative: a.overhead.negative,
        clocks: clocks(a, logs),
        stages_ns: STAGES
            .iter()
            .zip(&a.stages)
            .filter_map(|((name, _, _), l)| Some(((*name).to_string(), l.percentiles()?)))
            .collect(),
        samples_sent: a.rows,
        samples_received: a.received,
        samples_lost: a.rows - a.received,
        deadline_misses: master_totals.deadline_misses,
        tracking_rms_m: a.motion.tracking_rms_m,
        hand: scenario.master.hand.mode,
        control: scenario.control.kind.name(),
        tracking: a.bilateral.tracking,
        contact: a.bilateral.contact,
        transparency: a.bilateral.felt.finish(scenario.t_s()),
        task_space: None,
        task: slave
            .as_ref()
            .and_then(|s| s.world.task)
            .map(|t| crate::task::TaskSummary::new(&t, &a.task)),
        passivity: a.bilateral.passivity,
        mmt: (scenario.control.kind == tactile_scenario::ControlKind::Mmt).then(|| ModelCounts {
            models_sent: slave.as_ref().map_or(0, |s| s.counters.models_sent),
            models_taken: master_totals.counters.models_received,
            models_refused: master_totals.counters.models_refused,
            injected_j: a.bilateral.model_injected_j,
        }),
        packets: Packets {
            forward: master_totals.counters.packets_sent,
            backward: slave.as_ref().map_or(0, |s| s.counters.packets_sent),
        },
        channels: channels(&master_totals, emulator.as_ref(), slave.as_ref()),
        master: MasterPart {
            totals: master_totals,
            motion: a.motion,
            samples_per_s: if elapsed > 0 {
                a.rows as f64 * 1e9 / elapsed as f64
            } else {
                0.0
            },
        },
        hardware,
        emulator,
        slave,
        nodes: nodes(logs),
        warnings,
        events: ev,
        events_omitted: omitted,
        failed: launch.failed,
        interrupted: launch.interrupted,
    }
}

/// The nodes' start records and the scenario the master recorded (or, where the
/// master's start frame was damaged, the one another node recorded: every node records
/// the scenario it runs).
pub(crate) fn recorded(
    dirs: &[PathBuf],
    stop: &dyn Fn() -> bool,
) -> Result<([Option<Start>; 3], Scenario), Error> {
    let found = join::locate(dirs)?;
    let starts = join::starts(&found, stop)?;
    let Some((k, start)) = starts
        .iter()
        .enumerate()
        .find_map(|(k, s)| s.as_ref().map(|s| (k, s)))
    else {
        let shown: Vec<String> = found
            .iter()
            .flatten()
            .map(|p| p.display().to_string())
            .collect();
        return Err(Error::BadInput(format!(
            "no whole start frame in {}: the scenario run is not known",
            shown.join(", ")
        )));
    };
    let from = found[k].clone().unwrap_or_default();
    let scenario = Scenario::from_recorded_toml(&start.scenario_toml).map_err(|e| {
        Error::BadInput(format!(
            "{}: the scenario recorded is not valid: {e}",
            from.display()
        ))
    })?;
    Ok((starts, scenario))
}

/// The run's runner and the analysis that fits it: the in-process simulation's
/// stamps are synthetic, so no stage times come from them.
fn analysis_for(starts: &[Option<Start>; 3]) -> Result<(&'static str, Analysis), Error> {
    let domains = starts
        .clone()
        .map(|s| s.map_or_else(String::new, |s| s.clock));
    let start = starts
        .iter()
        .flatten()
        .next()
        .ok_or_else(|| Error::BadInput("no whole start frame in the records".into()))?;
    let runner = if start.link == IN_PROCESS {
        IN_PROCESS
    } else {
        "processes"
    };
    Ok((runner, Analysis::new(runner != IN_PROCESS, domains)))
}

/// Joins the records in `dirs` and writes the report into `out`: summary, trace,
/// histograms, plots and the scenario as run. Returns the summary. On any error the
/// files begun (their partial names) are removed: a folder holds whole files only.
pub fn write_report(dirs: &[PathBuf], out: &Path, launch: &Launch) -> Result<Summary, Error> {
    let (starts, scenario) = recorded(dirs, &|| launch.stopped())?;
    let (runner, analysis) = analysis_for(&starts)?;
    make_out_dir(out)?;
    // Written last: until then the folder holds no summary, so no older one sits beside
    // this report's files if it is cut short.
    crate::out::remove_if_there(&out.join("summary.json"))?;
    report_into(dirs, out, launch, &scenario, (runner, analysis)).inspect_err(|_| discard(out))
}

/// [`write_report`] once the scenario is known and the folder made.
fn report_into(
    dirs: &[PathBuf],
    out: &Path,
    launch: &Launch,
    scenario: &Scenario,
    (runner, mut analysis): (&'static str, Analysis),
) -> Result<Summary, Error> {
    let t_s = scenario.t_s();
    let mut series = Series::default();
    let mut streams = Streams::create(out, scenario, &launch.outputs)?;
    let warning = streams.warning.clone();
    let stopped = || launch.stopped();
    let mut task = crate::task_space::TaskSpaceSums::of(scenario);
    let mut progress = crate::bodies::TaskSeries::of(scenario);
    let arm = join::Arm::of(scenario);
    let logs = join::join_until(dirs, &stopped, arm, |row, j| {
        let joints = j.joints;
        // The clutch's offset, from the arm's base frame into the master's.
        if let (Some(arm), Some(j)) = (&scenario.slave.arm, joints) {
            let shift = arm.shift_to_master(j.offset);
            analysis.bilateral.clutch(shift, j.released);
        }
        analysis.add(row);
        if let (Some(t), Some(j)) = (task.as_mut(), joints) {
            t.add(row, j);
        }
        series.add(row, t_s);
        if let Some(p) = progress.as_mut() {
            p.add(row.n as f64 * t_s, j.world);
        }
        streams.add(row, j)?;
        Ok(ControlFlow::Continue(()))
    })?;
    streams.finish(out)?;
    analysis.finish();
    let lockstep = scenario.mode == tactile_scenario::Mode::Lockstep;
    crate::figures::write(out, &analysis, &series, lockstep)?;

    // Inputs copied into the folder are referred to relatively, so it reruns anywhere.
    let here = std::fs::canonicalize(out).unwrap_or_else(|_| out.to_path_buf());
    write_file(
        &out.join("scenario.toml"),
        &scenario.relative_to(&here).to_toml(),
    )?;
    let mut summary = summarise(scenario, runner, &analysis, &logs, launch);
    // The moment of success as the slave's task monitor counted it.
    let completion = summary.task.as_ref().and_then(|t| t.completion_s);
    match &progress {
        Some(p) => p
            .write(out, scenario, completion)
            .map_err(|source| Error::Plot {
                what: format!("plotting {}", crate::bodies::TASK_PLOT),
                source,
            })?,
        None => crate::bodies::remove_task_plot(out)?,
    }
    summary.task_space = task.map(|t| t.finish());
    summary.tracking_rms_m = headline_tracking(&summary);
    summary.events.extend(warning);
    if let Some(n) = logs.stopped_at {
        summary.interrupted = true;
        let dirs: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
        summary.events.push(format!(
            "report cut short at sample {n} by a stop request: `tactile report {}` reports every sample the records hold",
            dirs.join(" ")
        ));
    }
    write_json(&out.join("summary.json"), &summary)?;
    Ok(summary)
}

/// What [`write_mcap`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct McapWritten {
    /// Samples recorded (joined, where a stop request came).
    pub samples: u64,
    /// What the recording leaves out, if anything (an arm whose URDF cannot be read).
    pub warning: Option<String>,
    /// A stop request ended the join before this sample: no run.mcap was written (its
    /// partial file removed; one written before is left as it was).
    pub stopped_at: Option<u64>,
}

/// Joins the records in `dirs` and writes only `out/run.mcap` (old records converted
/// without redoing the report), looking at `stop` (a stop request) as it reads: a
/// conversion that stops writes nothing, since a recording of part of the run under
/// the run's name would pass for all of it.
pub fn write_mcap(
    dirs: &[PathBuf],
    out: &Path,
    compression: crate::mcap::Compression,
    stop: &dyn Fn() -> bool,
) -> Result<McapWritten, Error> {
    let (_, scenario) = recorded(dirs, stop)?;
    make_out_dir(out)?;
    let (mut rec, warning) =
        run_mcap::create(out, &scenario, compression).map_err(Error::io("writing run.mcap"))?;

    let mut samples = 0;
    let arm = join::Arm::of(&scenario);
    let logs = join::join_until(dirs, stop, arm, |row, j| {
        samples += 1;
        rec.add(row, j).map_err(Error::io("writing run.mcap"))?;
        Ok(ControlFlow::Continue(()))
    })
    .inspect_err(|_| run_mcap::discard(out))?;
    if logs.stopped_at.is_some() {
        // Dropped first: its writer would finish the file it is about to lose.
        drop(rec);
        run_mcap::discard(out);
    } else {
        run_mcap::commit(rec, out)
            .inspect_err(|_| run_mcap::discard(out))
            .map_err(Error::io("writing run.mcap"))?;
    }
    Ok(McapWritten {
        samples,
        warning,
        stopped_at: logs.stopped_at,
    })
}
