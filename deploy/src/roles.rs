//! The three process roles of the `tactile` executable.
//!
//! `tactile run` starts this same executable three times, as `tactile role master`,
//! `tactile role emulator` and `tactile role slave`, so a fresh checkout needs only one
//! binary built. Each role runs its library's loop and writes its result as JSON into
//! the run's output folder; the master also writes the trace, the histograms and the
//! plots, since it holds the rows.

use crate::error::Error;
use crate::report::{self, Percentiles, RowReport, STAGES};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tactile_common::ipc::WaitPolicy;
use tactile_common::scenario::Scenario;
use tactile_common::trace::{self, TraceRow};
use tactile_master::hmd::MasterCounters;
use tactile_master::process::{MasterOptions, MasterRun};

/// How long before each realtime tick the master wakes and spins: covers the ~100 us
/// lateness of timer wake-ups measured on these machines (see README, "Waiting").
pub const WAKE_EARLY_NS: u64 = 200_000;

/// Options every role gets from the launcher.
#[derive(Debug, Clone)]
pub struct RoleOptions {
    /// The scenario (already validated by the launcher).
    pub scenario: Scenario,
    /// Folder relative paths in the scenario are resolved against.
    pub base_dir: PathBuf,
    /// iceoryx2 prefix of the run.
    pub prefix: String,
    /// Output folder.
    pub out: PathBuf,
    /// Busy-poll budget before blocking.
    pub spin: Duration,
    /// The transport between the processes.
    pub transport: Transport,
}

/// What carries the samples between the three processes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transport {
    /// iceoryx2 zero-copy shared memory: the product.
    Iceoryx2,
    /// UDP on loopback at these ports: the reference.
    Udp(crate::udp::UdpPorts),
}

/// The master's part of the summary.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct MasterSummary {
    /// Round trip, ns.
    pub round_trip_ns: Percentiles,
    /// Round trip minus injected delay, ns.
    pub overhead_ns: Percentiles,
    /// Overheads below zero (tick jitter), clamped to zero in the histogram.
    pub overhead_negative: u64,
    /// Per-stage times, ns.
    pub stages_ns: BTreeMap<String, Percentiles>,
    /// Tracking and forces.
    pub motion: report::Motion,
    /// Forward samples sent.
    pub samples_sent: u64,
    /// Backward samples received (on time or late).
    pub samples_received: u64,
    /// Samples whose answer never came.
    pub samples_lost: u64,
    /// Answers not back by the next tick.
    pub deadline_misses: u64,
    /// Answers that came after their deadline.
    pub late: u64,
    /// Backward samples that matched no sample sent.
    pub unexpected: u64,
    /// State-machine counters.
    pub counters: MasterCounters,
    /// True if a stop request cut the run short.
    pub interrupted: bool,
    /// What happened to the loop (breaks, resumes), in order.
    pub events: Vec<tactile_master::process::Event>,
    /// c(n) as published.
    pub c_out: tactile_common::ipc::OutboxStats,
    /// q(n) as received.
    pub q_in: tactile_common::ipc::InboxStats,
    /// Samples sent per second of wall-clock time (the lockstep throughput).
    pub samples_per_s: f64,
}

fn write(path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(Error::io(format!("writing {}", path.display())))
}

/// Writes `value` as pretty JSON to `path`.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<(), Error> {
    let mut text = serde_json::to_string_pretty(value)
        .map_err(|e| Error::Failed(format!("encoding {}: {e}", path.display())))?;
    text.push('\n');
    write(path, &text)
}

/// The trace as CSV text.
pub fn trace_csv(rows: &[TraceRow], t0: u64) -> String {
    let mut text = trace::header();
    text.push('\n');
    for row in rows {
        row.write_csv(&mut text, t0);
    }
    text
}

/// Writes trace, histograms and plots for `rows` into `out`; returns the row report.
pub fn write_artifacts(
    rows: &[TraceRow],
    t0: u64,
    t_s: f64,
    with_stages: bool,
    out: &Path,
) -> Result<RowReport, Error> {
    write(&out.join("trace.csv"), &trace_csv(rows, t0))?;
    let r = report::analyse(rows, with_stages);
    write(&out.join("round_trip.hgrm"), &r.round_trip.hgrm())?;
    write(&out.join("overhead.hgrm"), &r.overhead.hgrm())?;
    let plot = |name: &str, res: Result<(), String>| {
        res.map_err(|e| Error::Failed(format!("plotting {name}: {e}")))
    };
    plot(
        "latency",
        crate::plots::overhead_histogram(rows, &out.join("latency.svg")),
    )?;
    plot(
        "positions",
        crate::plots::positions(rows, t_s, &out.join("positions.svg")),
    )?;
    plot(
        "forces",
        crate::plots::forces(rows, t_s, &out.join("forces.svg")),
    )?;
    Ok(r)
}

fn master_summary(run: &MasterRun, r: &RowReport) -> MasterSummary {
    MasterSummary {
        round_trip_ns: r.round_trip.percentiles(),
        overhead_ns: r.overhead.percentiles(),
        overhead_negative: r.overhead.negative,
        stages_ns: STAGES
            .iter()
            .zip(&r.stages)
            .map(|((name, _, _), l)| ((*name).to_string(), l.percentiles()))
            .collect(),
        motion: r.motion,
        samples_sent: r.rows,
        samples_received: r.received,
        samples_lost: run.missing,
        deadline_misses: run.deadline_misses,
        late: run.late,
        unexpected: run.unexpected,
        counters: run.counters,
        interrupted: run.interrupted,
        events: run.events.clone(),
        c_out: run.c_out,
        q_in: run.q_in,
        samples_per_s: if run.elapsed_ns > 0 {
            r.rows as f64 * 1e9 / run.elapsed_ns as f64
        } else {
            0.0
        },
    }
}

/// The master part of the summary for an in-process simulation.
pub fn master_summary_from(sim: &crate::sim::SimRun, r: &RowReport) -> MasterSummary {
    let run = MasterRun {
        rows: Vec::new(),
        counters: sim.master,
        deadline_misses: 0,
        late: 0,
        missing: sim.rows.iter().filter(|r| r.backward.is_none()).count() as u64,
        unexpected: 0,
        t0_ns: 0,
        interrupted: false,
        events: Vec::new(),
        c_out: Default::default(),
        q_in: Default::default(),
        elapsed_ns: 0,
    };
    master_summary(&run, r)
}

/// `tactile role ROLE ...`: runs one process of a run (or the bench's echo).
pub fn dispatch(args: crate::cli::RoleArgs) -> Result<(), Error> {
    use crate::cli::RoleName;
    let spin = Duration::from_micros(args.spin_us);
    let run: fn(&RoleOptions) -> Result<(), Error> = match args.role {
        RoleName::Echo => {
            return crate::bench_cmd::echo(&args.prefix, WaitPolicy { spin })
                .map_err(|e| Error::Failed(e.to_string()))
        }
        RoleName::Master => master,
        RoleName::Emulator => emulator,
        RoleName::Slave => slave,
    };
    let (scenario, _) = crate::run_cmd::load_scenario(Some(&args.scenario))?;
    let transport = match &args.udp_ports {
        None => Transport::Iceoryx2,
        Some(p) => Transport::Udp(crate::udp::UdpPorts::parse(p).ok_or_else(|| {
            Error::BadInput(format!("--udp-ports {p:?}: expected three ports m,e,s"))
        })?),
    };
    run(&RoleOptions {
        scenario,
        base_dir: args.base_dir,
        prefix: args.prefix,
        out: args.out,
        spin,
        transport,
    })
}

/// `tactile role master`.
pub fn master(o: &RoleOptions) -> Result<(), Error> {
    let opts = MasterOptions {
        scenario: o.scenario.clone(),
        base_dir: o.base_dir.clone(),
        prefix: o.prefix.clone(),
        wait: WaitPolicy { spin: o.spin },
        startup_timeout: Duration::from_secs(10),
        answer_timeout: Duration::from_millis(100),
        progress_every: 0,
        wake_early_ns: WAKE_EARLY_NS,
    };
    let run = match o.transport {
        Transport::Iceoryx2 => tactile_master::process::run(&opts),
        Transport::Udp(ports) => crate::udp::UdpMaster::open(ports)
            .map_err(Into::into)
            .and_then(|link| tactile_master::process::run_with(&opts, &link)),
    }
    .map_err(|e| Error::Failed(e.to_string()))?;
    let r = write_artifacts(&run.rows, run.t0_ns, o.scenario.t_s(), true, &o.out)?;
    write_json(&o.out.join("master.json"), &master_summary(&run, &r))
}

/// `tactile role emulator`.
pub fn emulator(o: &RoleOptions) -> Result<(), Error> {
    let opts = tactile_network_emulator::process::EmulatorOptions {
        scenario: o.scenario.clone(),
        prefix: o.prefix.clone(),
        wait: WaitPolicy { spin: o.spin },
    };
    let run = match o.transport {
        Transport::Iceoryx2 => tactile_network_emulator::process::run(&opts),
        Transport::Udp(ports) => crate::udp::UdpEmulator::open(ports)
            .and_then(|link| tactile_network_emulator::process::run_with(&opts, &link)),
    }
    .map_err(|e| Error::Failed(e.to_string()))?;
    write_json(&o.out.join("emulator.json"), &run)
}

/// `tactile role slave`.
pub fn slave(o: &RoleOptions) -> Result<(), Error> {
    let opts = tactile_slave::process::SlaveOptions {
        scenario: o.scenario.clone(),
        prefix: o.prefix.clone(),
        wait: WaitPolicy { spin: o.spin },
    };
    let run = match o.transport {
        Transport::Iceoryx2 => tactile_slave::process::run(&opts),
        Transport::Udp(ports) => crate::udp::UdpSlave::open(ports)
            .map_err(Into::into)
            .and_then(|link| tactile_slave::process::run_with(&opts, &link)),
    }
    .map_err(|e| Error::Failed(e.to_string()))?;
    write_json(&o.out.join("slave.json"), &run)
}
