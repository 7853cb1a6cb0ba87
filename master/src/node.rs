//! The `tactile-master` program (HMD): its command line and its run, as a library so
//! that `tactile run` and the tests can also call it.

use crate::handler::MasterHandler;
use crate::hmd::Master;
use crate::operator::OperatorSource;
use crate::peripherals;
use clap::Parser;
use std::process::ExitCode;
use std::time::Duration;
use tactile_messages::Role;
use tactile_runtime::args::{exit, parse, LinkKind, NodeArgs, NodeError};
use tactile_runtime::exit::EXIT_CODES_HELP;
use tactile_runtime::program::{Opened, Program};
use tactile_runtime::start::Links;
use tactile_scenario::Backend;

/// tactile-master: the operator's side (OP, MD, HMD). Sends c(n), takes q(n) back,
/// commands the master device's torques, and records every sample.
///
/// The master device is simulated, or a real one through its ROS 2 driver over
/// rmw_zenoh (`master.backend = "ros2"` and `[master.ros2]` in the scenario: topics,
/// joint names, signs, offsets, units, staleness); `[ros.live]` publishes the
/// master's state as ROS 2 topics while it runs. Both need a build with the `zenoh`
/// feature; every option is in docs/11-real-devices-and-ros2.md.
#[derive(Debug, Parser)]
#[command(name = "tactile-master", version, about, after_help = EXIT_CODES_HELP)]
pub struct Cli {
    /// Options every node takes.
    #[command(flatten)]
    pub node: NodeArgs,
    /// Seconds to wait for the emulator and slave to answer (and, with a ROS 2 device,
    /// for the device's first good message) before giving up.
    #[arg(long, default_value_t = 60.0)]
    pub startup_timeout_s: f64,
    /// No emulator: talk to the slave directly, the real network being the delay
    /// (with --link zenoh).
    #[arg(long)]
    pub direct: bool,
}

/// The program: parse, run, exit status.
pub fn main() -> ExitCode {
    match parse::<Cli>() {
        Ok(cli) => exit(Role::Master, run(&cli)),
        Err(code) => code,
    }
}

/// Runs the master; `Ok(true)` when every sample was sent, `Ok(false)` when a stop
/// request ended it early.
pub fn run(cli: &Cli) -> Result<bool, NodeError> {
    let a = &cli.node;
    if !(cli.startup_timeout_s.is_finite() && cli.startup_timeout_s > 0.0) {
        return Err(NodeError::BadInput(format!(
            "--startup-timeout-s {}: must be a positive number of seconds",
            cli.startup_timeout_s
        )));
    }
    if cli.direct && a.link.link != LinkKind::Zenoh {
        return Err(NodeError::BadInput(
            "--direct (no emulator) needs --link zenoh".into(),
        ));
    }
    let links = Links {
        direct: cli.direct,
        ..Links::all(a.link.link)
    };
    let program = Program::prepare(Role::Master, a, links)?;
    let sc = program.scenario();
    let source = OperatorSource::load(&sc.operator, &program.prepared().base_dir)
        .map_err(|e| NodeError::BadInput(format!("{}: operator: {e}", a.scenario.display())))?;
    for w in source.warnings(sc.samples, sc.t_s()) {
        tracing::warn!("{w}");
    }
    // The gimbal's URDF read and checked before anything starts: bad input (exit 2).
    let gimbal = match sc.master.backend {
        Backend::Ros2 => peripherals::gimbal(sc, &program.prepared().base_dir)
            .map_err(|e| NodeError::BadInput(format!("{}: {e}", a.scenario.display())))?,
        Backend::Simulated => None,
    };
    let timeout = Duration::from_secs_f64(cli.startup_timeout_s.min(1e6));
    program.lead(
        timeout,
        Box::new(move |p| {
            let opened = peripherals::open(&p.scenario, &p.base_dir, gimbal)?;
            let master =
                Master::new(&p.scenario, source).map_err(|e| NodeError::Failed(e.to_string()))?;
            let timeout = p.scenario.faults.peer_timeout_samples;
            Ok(Opened {
                handler: MasterHandler::new(master, opened.device, timeout),
                live: opened.live,
            })
        }),
    )
}
