//! `summary.json` and the terminal summary: a view of the nodes' records, with each
//! stream's accounting.

use crate::analysis::{ClockOffset, Motion, Percentiles};
use crate::metrics::{Contact, Packets, Passivity, Tracking};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use tactile_records::emulator::EmulatorTotals;
use tactile_records::master::MasterTotals;
use tactile_records::slave::SlaveTotals;
use tactile_scenario::Mode;

/// A URDF arm's joints, one row a sample: `n`, then the IK's references, the joint
/// values and the servo's efforts, each `_1` to `_<dof>` in the chain's order
/// (written only when the slave is a URDF arm, `[slave.arm]`).
pub const JOINTS_FILE: &str = "joints.csv";

/// Files a report writes into its folder.
pub const REPORT_FILES: [&str; 15] = [
    "summary.json",
    "trace.csv",
    "trace.parquet",
    JOINTS_FILE,
    crate::bodies::BODIES_FILE,
    "run.mcap",
    "round_trip.hgrm",
    "overhead.hgrm",
    "latency.svg",
    "percentiles.svg",
    "positions.svg",
    "forces.svg",
    "passivity.svg",
    crate::bodies::TASK_PLOT,
    "scenario.toml",
];

/// Accounting of one stream: every sample offered is received or lost, and every
/// loss has a cause.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ChannelCount {
    /// Samples the sender had for this stream.
    pub offered: u64,
    /// Published (offered minus dropped on purpose).
    pub sent: u64,
    /// Taken by the receiver.
    pub received: u64,
    /// offered - received = dropped + overwritten + dead_peer.
    pub lost: u64,
    /// Dropped by the emulator on purpose (loss model).
    pub lost_dropped: u64,
    /// Overwritten in the receiver's full buffer (safe overflow, 64 samples).
    pub lost_overwritten: u64,
    /// Lost to a dead peer: published with no receiver connected, or taken by a
    /// receiver that was killed before it could report (its counts die with it).
    pub lost_dead_peer: u64,
}

impl ChannelCount {
    /// The accounting of a stream from its sender's and receiver's counts.
    pub fn new(
        out: tactile_messages::stream::OutboxStats,
        dropped: u64,
        inn: tactile_messages::stream::InboxStats,
    ) -> Self {
        let offered = out.published + dropped;
        let received = inn.received;
        let lost = offered.saturating_sub(received);
        let overwritten = inn.overwritten.min(lost.saturating_sub(dropped));
        ChannelCount {
            offered,
            sent: out.published,
            received,
            lost,
            lost_dropped: dropped,
            lost_overwritten: overwritten,
            lost_dead_peer: lost - dropped.min(lost) - overwritten,
        }
    }
}

/// The master's part of the summary.
#[derive(Debug, Clone, Serialize)]
pub struct MasterPart {
    /// The master's counters (its last record of them).
    #[serde(flatten)]
    pub totals: MasterTotals,
    /// Tracking and forces.
    pub motion: Motion,
    /// Samples sent per second of the master's running time (the lockstep throughput).
    pub samples_per_s: f64,
}

/// One node as its record describes it.
#[derive(Debug, Clone, Serialize)]
pub struct NodeSummary {
    /// The record file.
    pub record: String,
    /// Host each segment ran on.
    pub hosts: Vec<String>,
    /// Process id of each segment (more than one: the node was restarted).
    pub pids: Vec<u32>,
    /// The record's length and CRC-32 as reported (`BYTES:CRC`): what ties a summary
    /// to its records ([`of_these_records`]; a simulation's starts carry no time, so
    /// the bytes themselves say which run they are).
    pub digest: String,
    /// The link it used.
    pub link: String,
    /// Peak resident set size, kB (the largest over its segments).
    pub peak_rss_kb: u64,
    /// The last sample number in its record.
    pub last_sample: Option<u64>,
    /// How its record ends: `completed`, `interrupted`, or where a killed node's
    /// record stops.
    pub ended: String,
    /// Sample records that matched no sample of the master.
    pub unjoined: u64,
    /// Sample records numbered at or past the run's sample count, dropped.
    pub invalid: u64,
    /// Sample records repeating a sample the record already gave, dropped.
    pub duplicates: u64,
    /// Bytes of its record that held no whole frame (a torn tail, corruption),
    /// skipped; every whole frame around them was read.
    pub damaged_bytes: u64,
    /// Damaged stretches skipped, with the first few as `[offset, bytes]`.
    pub damaged_stretches: u64,
    /// Where the first damaged stretches are: `[byte offset, length]`.
    pub damage: Vec<[u64; 2]>,
    /// Its scheduling (policy, priority, CPU, wake-up margin, poll budget) as its
    /// last start recorded it; `note` says what the kernel refused.
    pub sched: tactile_records::Sched,
}

/// The nodes' clocks.
#[derive(Debug, Clone, Serialize)]
pub struct Clocks {
    /// True if every node stamps with one clock (one host, or one kernel): every stage
    /// and hop time is then a true time.
    pub shared: bool,
    /// Each node's clock domain (its kernel's boot id).
    pub domains: BTreeMap<&'static str, String>,
    /// Between nodes on different clocks: the offset, an estimate; the round trip, on
    /// the master's clock alone, is exact either way.
    pub offsets: Vec<ClockOffset>,
}

/// `summary.json`: a view of the nodes' records.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// `realtime` or `lockstep`.
    pub mode: Mode,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Kernel arithmetic.
    pub arithmetic: String,
    /// `processes` or `in-process`.
    pub runner: &'static str,
    /// The run token the master chose.
    pub run: Option<String>,
    /// Round trip on the master's clock, ns; null when nothing came back.
    pub round_trip_ns: Option<Percentiles>,
    /// Round trip in samples (n minus the oldest sample q(n) started from); in
    /// lockstep this is the round trip, `round_trip_ms_nominal` its time.
    pub round_trip_samples: Option<Percentiles>,
    /// Lockstep: the round trip's p50 in samples times t_s, ms; null in real time.
    pub round_trip_ms_nominal: Option<f64>,
    /// Round trip minus the injected delay, ns; null when nothing came back, and in
    /// lockstep (see `overhead_na`).
    pub overhead_ns: Option<Percentiles>,
    /// Why `overhead_ns` is null when samples did come back.
    pub overhead_na: Option<&'static str>,
    /// Overheads below zero (tick jitter), clamped to zero in the histogram.
    pub overhead_negative: u64,
    /// Per-stage times, ns (stages with no data, and stages between two nodes on
    /// different clocks, are left out).
    pub stages_ns: BTreeMap<String, Percentiles>,
    /// Which nodes share a clock, and the offset estimates between those that do not.
    pub clocks: Clocks,
    /// Forward samples the master sent.
    pub samples_sent: u64,
    /// Backward samples the master received.
    pub samples_received: u64,
    /// Samples whose round trip never completed.
    pub samples_lost: u64,
    /// Answers not back by the next tick.
    pub deadline_misses: u64,
    /// RMS distance of the slave's tool from the position it was asked to reach, m: a
    /// URDF arm's against its target after the master's map (`task_space`'s
    /// `position_rms_m`), the paper's arm's against v(n) (`master.motion`'s).
    pub tracking_rms_m: Option<f64>,
    /// The operator's hand: `position` (ideal) or `impedance`.
    pub hand: tactile_scenario::HandMode,
    /// The channel's control: `none`, `tdpa`, `wave` or `mmt`.
    pub control: &'static str,
    /// The slave against the master's delay-shifted handle, the felt force against the
    /// environment's.
    pub tracking: Tracking,
    /// How deep the tool went.
    pub contact: Contact,
    /// The stiffness the operator felt against the environment's.
    pub transparency: crate::transparency::Transparency,
    /// A URDF arm: the tool against its target after the master's workspace map, in
    /// the arm's base frame, the clutch's releases, the robot's force before
    /// `force_scale`; absent for the paper's arm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub task_space: Option<crate::task_space::TaskSpace>,
    /// A physics scene's `[task]` (docs/16): whether and when it succeeded, the
    /// contact force, the tool's path and the operator's work; absent without a task.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub task: Option<crate::task::TaskSummary>,
    /// The channel's passivity observers, the energy the control dissipated, and the
    /// drift of the slave's reference.
    pub passivity: Passivity,
    /// Samples put on the network per direction.
    pub packets: Packets,
    /// `control.kind = "mmt"`: the models sent and taken, and the energy their changes
    /// added at the handle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mmt: Option<ModelCounts>,
    /// Everything the master reported.
    pub master: MasterPart,
    /// Per stream: c (master to emulator), v (emulator to slave), h, q.
    pub channels: BTreeMap<&'static str, ChannelCount>,
    /// The emulator's counters (summed over its segments).
    pub emulator: Option<EmulatorTotals>,
    /// The slave's counters (summed over its segments).
    pub slave: Option<SlaveTotals>,
    /// `arithmetic = "rtl"`: the clocks each module took, and their time where the
    /// module was placed and routed in the pipeline the nodes simulated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hardware: Option<crate::hardware::HardwareSummary>,
    /// Each node: where it ran, its memory, how its record ends.
    pub nodes: BTreeMap<&'static str, NodeSummary>,
    /// What the scenario's check said before the run (a setting that does nothing,
    /// a change after the end, a channel that lets nothing through, a trajectory
    /// shorter than the run: `tactile check` says the same), then what the figures
    /// leave out: a part of the run they are not computed from (rows left out of the
    /// join, damaged), or counts of the trace and a node's own that disagree. Empty
    /// when the scenario deserves no word and the figures cover the whole run.
    pub warnings: Vec<String>,
    /// What happened: processes that died and were restarted, loop breaks, resumes.
    pub events: Vec<String>,
    /// Events left out of `events` (a node keeps at most 200).
    pub events_omitted: u64,
    /// True if a process died during the run.
    pub failed: bool,
    /// True if SIGINT/SIGTERM cut the run short.
    pub interrupted: bool,
}

/// A record's length and CRC-32, `BYTES:CRC` (empty if it cannot be read).
pub fn digest(path: &Path) -> String {
    use std::io::Read;
    let Ok(mut f) = std::fs::File::open(path) else {
        return String::new();
    };
    let (mut h, mut bytes, mut buf) = (crc32fast::Hasher::new(), 0u64, vec![0u8; 1 << 16]);
    loop {
        match f.read(&mut buf) {
            Ok(0) => return format!("{bytes}:{:08x}", h.finalize()),
            Ok(k) => {
                h.update(&buf[..k]);
                bytes += k as u64;
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return String::new(),
        }
    }
}

/// True if `summary` (a `summary.json` read back) is the report of the master's
/// record in `dir` as it is: its length and CRC-32 are those the summary recorded.
/// A summary copied from another run, or one older than the record (a node appended
/// to it since), or written before summaries recorded digests, is not.
pub fn of_these_records(dir: &Path, summary: &serde_json::Value) -> bool {
    let Ok([Some(master), _, _]) = crate::join::locate(&[dir.to_path_buf()]) else {
        return false;
    };
    let ours = digest(&master);
    !ours.is_empty() && summary["nodes"]["master"]["digest"].as_str() == Some(ours.as_str())
}

/// `mmt` in summary.json: model-mediated teleoperation's traffic and energy.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ModelCounts {
    /// Models the slave sent (each a changed estimate).
    pub models_sent: u64,
    /// New models the master took and rendered.
    pub models_taken: u64,
    /// New models the master refused (not a valid plane).
    pub models_refused: u64,
    /// Energy the rendered model's changes added at the handle, J.
    pub injected_j: f64,
}
