//! The in-process simulation: the same master, emulator and slave code as the three
//! node programs, called in sequence with no shared memory and no clock, each writing
//! its record through the same recorder as its program does.
//!
//! It is the reference the process tests compare against: a lockstep run of the nodes
//! must produce the same signals, bit for bit. Time stamps here are synthetic
//! (n * t_s), so round trips equal the injected delay and overheads are zero.

use crate::error::Error;
use std::path::Path;
use std::sync::atomic::Ordering;
use tactile_master::hmd::Master;
use tactile_master::operator::OperatorSource;
use tactile_master::process::MasterRecorder;
use tactile_master::record::{MasterSample, MasterTotals};
use tactile_messages::clock::now_ns;
use tactile_messages::samples::stage;
use tactile_messages::Role;
use tactile_network_emulator::emulator::Emulator;
use tactile_network_emulator::process::{EmulatorRecorder, EmulatorTotals};
use tactile_node::args::NodeError;
use tactile_node::record::Start;
use tactile_node::recorder::Recorder;
use tactile_report::write::IN_PROCESS;
use tactile_scenario::Scenario;
use tactile_slave::hsd::Slave;
use tactile_slave::process::SlaveRecorder;
use tactile_slave::record::{SlaveSample, SlaveTotals};

/// The run token of a simulation (there is no master process to choose one).
pub const SIM_RUN: u64 = 1;

fn start(role: Role, scenario: &Scenario, base_dir: &Path) -> Start {
    Start {
        role: role.name().into(),
        version: env!("CARGO_PKG_VERSION").into(),
        pid: std::process::id(),
        host: "in-process".into(),
        clock: "in-process".into(),
        prefix: String::new(),
        link: IN_PROCESS.into(),
        scenario: scenario.name.clone(),
        scenario_toml: scenario.resolved(base_dir).to_toml(),
        samples: scenario.samples,
        rate_hz: scenario.rate_hz,
        sched: tactile_node::sched::Sched {
            policy: "in-process".into(),
            ..Default::default()
        },
        unix_ms: 0,
        mono_ns: 0,
    }
}

fn failed(e: NodeError) -> Error {
    Error::Failed(e.to_string())
}

/// Runs `scenario` in-process, writing the three records into `out`; `base_dir`
/// resolves a trajectory file's path. A stop request (SIGINT, SIGTERM) ends it after
/// the sample in hand, its records closed as `interrupted`; returns whether it ran
/// to the end.
pub fn simulate(scenario: &Scenario, base_dir: &Path, out: &Path) -> Result<bool, Error> {
    let stop =
        tactile_node::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    let source = OperatorSource::load(&scenario.operator, base_dir)
        .map_err(|e| Error::BadInput(e.to_string()))?;
    let bad = |e: tactile_scenario::ScenarioError| Error::BadInput(e.to_string());
    let mut master = Master::new(scenario, source).map_err(bad)?;
    let replays =
        tactile_network_emulator::replay::load(scenario, base_dir).map_err(Error::BadInput)?;
    let mut emulator = Emulator::with_replays(scenario, replays);
    let mut slave = Slave::new(scenario).map_err(bad)?;
    let mut mrec: MasterRecorder = Recorder::open(out, Role::Master, false).map_err(failed)?;
    let mut erec: EmulatorRecorder = Recorder::open(out, Role::Emulator, false).map_err(failed)?;
    let mut srec: SlaveRecorder = Recorder::open(out, Role::Slave, false).map_err(failed)?;
    mrec.start(start(Role::Master, scenario, base_dir))
        .map_err(failed)?;
    erec.start(start(Role::Emulator, scenario, base_dir))
        .map_err(failed)?;
    srec.start(start(Role::Slave, scenario, base_dir))
        .map_err(failed)?;
    mrec.run(SIM_RUN).map_err(failed)?;
    erec.run(SIM_RUN).map_err(failed)?;
    srec.run(SIM_RUN).map_err(failed)?;
    let t_s_ns = scenario.t_s_ns();
    let began = now_ns();
    let mut reason = "completed";
    for n in 0..scenario.samples {
        if stop.load(Ordering::Relaxed) {
            reason = "interrupted";
            break;
        }
        let now = n * t_s_ns;
        let (c, sent) = master.forward(n, now);
        mrec.sample(MasterSample::Sent(sent)).map_err(failed)?;
        let (v, passage) = emulator.forward(&c);
        erec.sample(passage).map_err(failed)?;
        let mut q = None;
        if let Some(v) = v {
            let (h, step) = slave.step(&v);
            srec.sample(SlaveSample::Step(step)).map_err(failed)?;
            let (out, passage) = emulator.backward(&h);
            erec.sample(passage).map_err(failed)?;
            q = out;
        }
        let record = match q {
            Some(mut q) => {
                q.stamps[stage::MASTER_DONE] = now;
                let mut a = master.backward(&q);
                master.account(&mut a);
                MasterSample::Answer(a)
            }
            None => MasterSample::Miss(master.missing(n)),
        };
        mrec.sample(record).map_err(failed)?;
    }
    let totals = MasterTotals {
        counters: master.counters(),
        elapsed_ns: now_ns().saturating_sub(began),
        ..MasterTotals::default()
    };
    mrec.stop(totals, reason).map_err(failed)?;
    let et = EmulatorTotals {
        counters: emulator.counters(),
        ..EmulatorTotals::default()
    };
    erec.stop(et, reason).map_err(failed)?;
    let st = SlaveTotals {
        counters: slave.counters(),
        ..SlaveTotals::default()
    };
    srec.stop(st, reason).map_err(failed)?;
    Ok(reason == "completed")
}

/// A run in-process into `out`, as `tactile run --in-process` and each run of a sweep
/// do it: the folder made ready (inputs copied in), the simulation, its report (cut
/// short and marked so if a stop request ended the simulation).
pub fn run_in_process(
    loaded: &super::Loaded,
    out: &Path,
    no_trace: bool,
) -> Result<tactile_report::summary::Summary, Error> {
    if loaded.scenario.uses_ros() {
        return Err(Error::BadInput(
            "an in-process run simulates both devices and has no live view: a ros2 backend or ros.live needs the node programs (tactile run without --in-process)".into(),
        ));
    }
    let bundled = super::prepare_out(out, loaded)?;
    let completed = simulate(&bundled.scenario, &bundled.base_dir, out)?;
    let launch = tactile_report::write::Launch {
        no_trace,
        stop: tactile_node::signals::stop_flag().ok(),
        ..Default::default()
    };
    let launch = if completed {
        launch
    } else {
        launch.interrupted()
    };
    Ok(tactile_report::write::write_report(
        std::slice::from_ref(&out.to_path_buf()),
        out,
        &launch,
    )?)
}
