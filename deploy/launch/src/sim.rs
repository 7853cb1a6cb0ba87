//! The in-process simulation: the same master, emulator and slave handlers as the
//! three node programs, driven by the same loop driver over in-memory streams with
//! simulated timing (`tactile_runtime::driver::in_process`), each writing its record
//! through the same recorder as its program does.
//!
//! It is the reference the process tests compare against: a lockstep run of the nodes
//! must produce the same signals, bit for bit. Time stamps here are synthetic (sample
//! n's instant is n t_s; the stages between are not timed), so round trips equal the
//! injected delay and overheads are zero.

use crate::error::Error;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use tactile_control::codec::Guess;
use tactile_master::handler::MasterHandler;
use tactile_master::hmd::Master;
use tactile_master::operator::{Operate, OperatorSource};
use tactile_messages::Role;
use tactile_network_emulator::emulator::Emulator;
use tactile_network_emulator::handler::EmulatorHandler;
use tactile_records::{Recorder, Start};
use tactile_report::write::IN_PROCESS;
use tactile_runtime::driver::follow::Follow;
use tactile_runtime::driver::lead::{Lead, LeadOptions};
use tactile_runtime::driver::{in_process, Link, Timing};
use tactile_scenario::Scenario;
use tactile_slave::handler::SlaveHandler;
use tactile_slave::hsd::Slave;

/// Code from outside the scenario in the loop of an in-process run (the Python API's
/// callables): each in place of its part of the scenario. Only in-process: a callable
/// lives in the caller's process, and its time is not the loop's.
#[derive(Default)]
pub struct Hooks {
    /// The simulated hand's targets, in place of `[operator]`'s.
    pub operator: Option<Box<dyn Operate>>,
    /// The master's guess of h(n) for a sample missing or late, in place of
    /// `[master.predictor]`'s kind.
    pub backward_predictor: Option<Box<dyn Guess>>,
    /// The slave's guess of v(n), in place of `[slave.predictor]`'s kind.
    pub forward_predictor: Option<Box<dyn Guess>>,
    /// Set by a hook that failed: the run stops after the sample in hand, its report
    /// marked interrupted. The run's own, not the process's stop request, so other
    /// runs of the process go on and this run's report is written whole.
    pub halt: Arc<AtomicBool>,
    /// Asked between samples, on the loop's thread, whether a stop was asked for
    /// (`Lead::watch_with`): the Python package looks at Python's signals there.
    pub watch: Option<Box<dyn FnMut() -> bool + Send>>,
}

impl Hooks {
    /// What the report says of the hooks in the loop (`summary.json`'s events), so
    /// the run's folder does not pass them off as its scenario's parts.
    fn events(&self) -> Vec<String> {
        [
            (self.operator.is_some(), "the operator", "[operator]"),
            (self.backward_predictor.is_some(), "the master's predictor", "[master.predictor]'s kind"),
            (self.forward_predictor.is_some(), "the slave's predictor", "[slave.predictor]'s kind"),
        ]
        .into_iter()
        .filter(|(set, _, _)| *set)
        .map(|(_, what, instead)| {
            format!("{what} was a hook from outside the scenario (the Python API) in place of {instead}: scenario.toml alone does not repeat this run")
        })
        .collect()
    }

    /// A hook the scenario cannot take, refused before anything is made: an operator
    /// hook gives positions, so the scenario's operator must be 3-DoF.
    fn check(&self, loaded: &super::Loaded) -> Result<(), Error> {
        if self.operator.is_none() {
            return Ok(());
        }
        let source = OperatorSource::load(&loaded.scenario.operator, &loaded.base_dir)
            .map_err(|e| Error::BadInput(e.to_string()))?;
        if source.six_dof() {
            return Err(Error::BadInput(
                "operator: its trajectory has an orientation or a clutch (6-DoF), but a scripted operator gives positions only: give a 3-DoF operator".into(),
            ));
        }
        Ok(())
    }
}

impl std::fmt::Debug for Hooks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hooks")
            .field("operator", &self.operator.is_some())
            .field("backward_predictor", &self.backward_predictor.is_some())
            .field("forward_predictor", &self.forward_predictor.is_some())
            .field("halt", &self.halt)
            .field("watch", &self.watch.is_some())
            .finish()
    }
}

/// The run token of a simulation (there is no master process to choose one): the
/// FNV-1a hash of the resolved scenario, never zero (zero means "unknown"). Two runs of
/// one scenario give the same records byte for byte; records of runs of different
/// scenarios (another seed, another delay) carry different tokens, so the report
/// refuses to join them as it refuses the node programs' records of different runs.
pub fn sim_run(resolved_toml: &str) -> u64 {
    fnv1a64(resolved_toml.as_bytes()).max(1)
}

/// FNV-1a, 64 bits: a hash that is the same on every build and machine (std's hasher
/// is seeded per process), for identities written into files.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

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
        sched: tactile_records::Sched {
            policy: "in-process".into(),
            ..Default::default()
        },
        unix_ms: 0,
        mono_ns: 0,
    }
}

/// `role`'s record in `out`, started.
fn record<S: serde::Serialize, C: serde::Serialize>(
    role: Role,
    scenario: &Scenario,
    base_dir: &Path,
    out: &Path,
) -> Result<Recorder<S, C>, Error> {
    let failed = |e: tactile_records::WriteError| Error::Failed(e.to_string());
    let mut rec = Recorder::open(out, role, false).map_err(failed)?;
    rec.start(start(role, scenario, base_dir)).map_err(failed)?;
    Ok(rec)
}

/// Runs `scenario` in-process, writing the three records into `out`; `base_dir`
/// resolves a trajectory file's path. A stop request (SIGINT, SIGTERM) ends it after
/// the sample in hand, its records closed as `interrupted`; returns whether it ran
/// to the end.
pub fn simulate(
    scenario: &Scenario,
    base_dir: &Path,
    out: &Path,
    hooks: Hooks,
) -> Result<bool, Error> {
    tactile_runtime::signals::stop_flag().map_err(Error::io("installing signal handlers"))?;
    let source = OperatorSource::load(&scenario.operator, base_dir)
        .map_err(|e| Error::BadInput(e.to_string()))?;
    let bad = |e: tactile_scenario::ScenarioError| Error::BadInput(e.to_string());
    let halt = Arc::clone(&hooks.halt);
    let mut master = Master::new(scenario, source).map_err(bad)?;
    if let Some(op) = hooks.operator {
        master.set_operator(op).map_err(bad)?;
    }
    if let Some(g) = hooks.backward_predictor {
        master.set_predictor(g);
    }
    let master = MasterHandler::new(master, None, scenario.faults.peer_timeout_samples);
    let replays = tactile_network_emulator::replay::load(scenario, base_dir)?;
    let histograms = tactile_network_emulator::histogram::load(scenario, base_dir)?;
    let emulator = EmulatorHandler::new(
        Emulator::with_replays(scenario, replays).with_histograms(scenario.seed, histograms),
    );
    let arm = tactile_slave::peripherals::read_arm(scenario, base_dir).map_err(Error::BadInput)?;
    let world = tactile_slave::world::SlaveWorld::of_scenario(scenario, base_dir)
        .map_err(|e| Error::BadInput(e.to_string()))?;
    let mut slave = Slave::new(scenario, arm, world).map_err(bad)?;
    if let Some(g) = hooks.forward_predictor {
        slave.set_predictor(g);
    }
    let slave = SlaveHandler::new(slave, scenario, None);
    let timing = Timing::Simulated {
        t_s_ns: scenario.t_s_ns(),
    };
    let [mp, ep, sp] = tactile_transport::ports::in_memory();
    let link = |p| Link::new(p, std::time::Duration::ZERO);
    let opts = LeadOptions {
        run: sim_run(&scenario.resolved(base_dir).to_toml()),
        samples: scenario.samples,
        startup_timeout: std::time::Duration::from_secs(10),
        answer_timeout: std::time::Duration::ZERO,
        timing,
    };
    let lead = Lead::new(
        master,
        link(mp),
        record(Role::Master, scenario, base_dir, out)?,
        opts,
        None,
    )
    .halt_on(halt);
    let lead = match hooks.watch {
        Some(w) => lead.watch_with(w),
        None => lead,
    };
    let emu = Follow::new(
        emulator,
        link(ep),
        record(Role::Emulator, scenario, base_dir, out)?,
        timing,
        None,
    );
    let sla = Follow::new(
        slave,
        link(sp),
        record(Role::Slave, scenario, base_dir, out)?,
        timing,
        None,
    );
    in_process::run(lead, emu, sla).map_err(|e| Error::Failed(e.to_string()))
}

/// A run in-process into `out`, as `tactile run --in-process` and each run of a sweep
/// do it: the folder made ready (inputs copied in), the simulation (with `hooks` in
/// its loop), its report (cut short and marked so if a stop request ended the
/// simulation).
pub fn run_in_process(
    loaded: &super::Loaded,
    out: &Path,
    outputs: &super::Outputs,
    hooks: Hooks,
) -> Result<tactile_report::summary::Summary, Error> {
    simulate_into(loaded, out, hooks)?.report(outputs)
}

/// An in-process run whose loop has ended, its report not yet written: the two
/// halves of [`run_in_process`], so a caller may run them on different threads (the
/// Python package runs the loop on the caller's thread, where its callables can take
/// a Ctrl-C, and waits for the report on another, looking at the signals meanwhile).
#[derive(Debug)]
pub struct Simulated {
    out: std::path::PathBuf,
    events: Vec<String>,
    /// What the launcher found to warn of (the scenario's inputs), for the summary.
    warnings: Vec<String>,
    /// The loop ran to its end.
    completed: bool,
    /// A hook asked this run alone to stop.
    halted: bool,
    /// The output folder, held until the report is written.
    _held: tactile_report::out::OutLock,
}

/// The first half of [`run_in_process`]: the folder made ready and the simulation run.
pub fn simulate_into(loaded: &super::Loaded, out: &Path, hooks: Hooks) -> Result<Simulated, Error> {
    if tactile_runtime::outside::ros_in_run(&loaded.scenario) {
        return Err(Error::BadInput(
            "an in-process run simulates both devices and has no live view: a ros2 backend or ros.live needs the node programs (tactile run without --in-process)".into(),
        ));
    }
    hooks.check(loaded)?;
    let (bundled, held) = super::prepare_out(out, loaded)?;
    let halt = Arc::clone(&hooks.halt);
    let events = hooks.events();
    // A hook that failed at the last sample stopped nothing, but the master's loop
    // says the run did not complete (`Lead::halt_on`).
    let completed = simulate(&bundled.scenario, &bundled.base_dir, out, hooks)?;
    Ok(Simulated {
        out: out.to_path_buf(),
        events,
        warnings: loaded.warnings.clone(),
        completed,
        halted: halt.load(Ordering::SeqCst),
        _held: held,
    })
}

impl Simulated {
    /// The second half of [`run_in_process`]: the report, with `outputs`.
    pub fn report(
        self,
        outputs: &super::Outputs,
    ) -> Result<tactile_report::summary::Summary, Error> {
        let launch = tactile_report::write::Launch {
            stop: tactile_runtime::signals::stop_flag().ok(),
            outputs: outputs.clone(),
            events: self.events,
            warnings: self.warnings,
            ..Default::default()
        };
        let launch = match (self.completed, self.halted) {
            (true, _) => launch,
            // The run's own stop: no signal hurries the report, which is written whole.
            (false, true) => {
                let mut launch = tactile_report::write::Launch {
                    interrupted: true,
                    ..launch
                };
                launch
                    .events
                    .push("stopped after the sample in hand: a hook from outside the scenario (the Python API) failed".into());
                launch
            }
            (false, false) => launch.interrupted(),
        };
        Ok(tactile_report::write::write_report(
            std::slice::from_ref(&self.out),
            &self.out,
            &launch,
        )?)
    }
}
