//! `summary.json` and the terminal summary: the three processes' results merged, with
//! each stream's accounting.

use crate::report::{us_header, us_line, Percentiles};
use crate::roles::MasterSummary;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use tactile_common::scenario::{Mode, Scenario};
use tactile_network_emulator::process::EmulatorRun;
use tactile_slave::process::SlaveRun;

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
    fn new(
        out: tactile_common::ipc::OutboxStats,
        dropped: u64,
        inn: tactile_common::ipc::InboxStats,
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

/// `summary.json`.
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
    /// Round trip on the master's clock, ns.
    pub round_trip_ns: Percentiles,
    /// Round trip minus the injected delay, ns.
    pub overhead_ns: Percentiles,
    /// Per-stage times, ns.
    pub stages_ns: BTreeMap<String, Percentiles>,
    /// Forward samples the master sent.
    pub samples_sent: u64,
    /// Backward samples the master received.
    pub samples_received: u64,
    /// Samples whose round trip never completed.
    pub samples_lost: u64,
    /// Answers not back by the next tick.
    pub deadline_misses: u64,
    /// RMS distance of slave tool from operator target, m.
    pub tracking_rms_m: f64,
    /// Everything the master reported.
    pub master: MasterSummary,
    /// Per stream: c (master to emulator), v (emulator to slave), h, q.
    pub channels: BTreeMap<&'static str, ChannelCount>,
    /// The emulator's counters.
    pub emulator: Option<EmulatorRun>,
    /// The slave's counters.
    pub slave: Option<SlaveRun>,
    /// What happened: processes that died and were restarted, loop breaks, resumes.
    pub events: Vec<String>,
    /// True if a process died during the run.
    pub failed: bool,
    /// True if SIGINT/SIGTERM cut the run short.
    pub interrupted: bool,
}

/// Merges the three roles' results.
pub fn summarise(
    scenario: &Scenario,
    runner: &'static str,
    master: MasterSummary,
    emulator: Option<EmulatorRun>,
    slave: Option<SlaveRun>,
) -> Summary {
    let mut channels = BTreeMap::new();
    if let (Some(e), Some(s)) = (&emulator, &slave) {
        let c = &e.counters;
        channels.insert("c", ChannelCount::new(master.c_out, 0, e.c_in));
        channels.insert("v", ChannelCount::new(e.v_out, c.forward_dropped, s.v_in));
        channels.insert("h", ChannelCount::new(s.h_out, 0, e.h_in));
        channels.insert(
            "q",
            ChannelCount::new(e.q_out, c.backward_dropped, master.q_in),
        );
    }
    Summary {
        scenario: scenario.name.clone(),
        mode: scenario.mode,
        rate_hz: scenario.rate_hz,
        arithmetic: scenario.arithmetic.to_string(),
        runner,
        round_trip_ns: master.round_trip_ns,
        overhead_ns: master.overhead_ns,
        stages_ns: master.stages_ns.clone(),
        samples_sent: master.samples_sent,
        samples_received: master.samples_received,
        samples_lost: master.samples_lost,
        deadline_misses: master.deadline_misses,
        tracking_rms_m: master.motion.tracking_rms_m,
        master,
        channels,
        emulator,
        slave,
        events: Vec::new(),
        failed: false,
        interrupted: false,
    }
}

/// The summary as the terminal shows it.
pub fn render(s: &Summary, out: &Path) -> String {
    use std::fmt::Write as _;
    let mut t = String::new();
    let m = &s.master;
    let _ = writeln!(
        t,
        "Tactile run {:?}: {:?} at {} Hz, {} arithmetic, {}",
        s.scenario, s.mode, s.rate_hz, s.arithmetic, s.runner
    );
    let _ = writeln!(t, "{}", us_header());
    let _ = writeln!(t, "{}", us_line("round trip", &s.round_trip_ns));
    let _ = writeln!(t, "{}", us_line("system overhead", &s.overhead_ns));
    for (name, p) in &s.stages_ns {
        if p.count > 0 {
            let _ = writeln!(t, "{}", us_line(&format!("  {name}"), p));
        }
    }
    let _ = writeln!(
        t,
        "samples: sent {}, received {}, lost {}; deadline misses {}, late {}",
        s.samples_sent, s.samples_received, s.samples_lost, s.deadline_misses, m.late
    );
    for (name, c) in &s.channels {
        let _ = writeln!(
            t,
            "  stream {name}: sent {}, received {}, lost {} (dropped {}, overwritten {}, dead peer {})",
            c.offered, c.received, c.lost, c.lost_dropped, c.lost_overwritten, c.lost_dead_peer
        );
    }
    let mo = &m.motion;
    let _ = writeln!(
        t,
        "tracking error: rms {:.2} mm, max {:.2} mm",
        mo.tracking_rms_m * 1e3,
        mo.tracking_max_m * 1e3
    );
    let _ = writeln!(
        t,
        "forces: {} samples in contact, slave max {:.3} N, felt rms {:.3} N max {:.3} N, master torque max {:.4} N m",
        mo.contact_samples, mo.force_max_n, mo.felt_rms_n, mo.felt_max_n, mo.tau_max_nm
    );
    let mc = &m.counters;
    let _ = writeln!(
        t,
        "master: {} force clamps, {} torque clamps, {} rejected, {} held, {} peer-lost samples",
        mc.force_clamps, mc.torque_clamps, mc.rejected, mc.held_samples, mc.peer_lost_samples
    );
    if let Some(sl) = &s.slave {
        let c = &sl.counters;
        let _ = writeln!(
            t,
            "slave: {} IK targets clamped, {} samples rejected, {} torque clamps, {} holds",
            c.ik_clamped, c.rejected, c.torque_clamps, c.holds
        );
    }
    for e in &s.events {
        let _ = writeln!(t, "event: {e}");
    }
    let _ = writeln!(
        t,
        "wrote {}: summary.json trace.csv round_trip.hgrm overhead.hgrm latency.svg positions.svg forces.svg",
        out.display()
    );
    t
}

/// Reads a JSON report a process wrote; `None` if it is missing or unreadable (a
/// killed process writes none).
pub fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Option<T> {
    let text = std::fs::read_to_string(path).ok()?;
    serde_json::from_str(&text).ok()
}
