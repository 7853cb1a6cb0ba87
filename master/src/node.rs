//! The `tactile-master` program (HMD): its command line and its run, as a library so
//! that `tactile run` and the tests can also call it.

use crate::operator::OperatorSource;
use crate::process::{run_with, Ending, MasterOptions};
use clap::Parser;
use std::process::ExitCode;
use std::time::Duration;
use tactile_messages::Role;
use tactile_node::args::{exit, parse, NodeArgs, NodeError};
use tactile_node::exit::EXIT_CODES_HELP;
use tactile_node::open::master_link;
use tactile_node::recorder::Recorder;
use tactile_node::runtime::{new_run_token, prepare, start_record};

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
    if cli.direct && a.link != tactile_node::args::LinkKind::Zenoh {
        return Err(NodeError::BadInput(
            "--direct (no emulator) needs --link zenoh".into(),
        ));
    }
    let p = prepare(Role::Master, a)?;
    if crate::outside::needs_ros(&p.scenario) && !cfg!(feature = "zenoh") {
        return Err(NodeError::BadInput(tactile_node::args::NO_ROS.into()));
    }
    let source = OperatorSource::load(&p.scenario.operator, &p.base_dir)
        .map_err(|e| NodeError::BadInput(format!("{}: operator: {e}", a.scenario.display())))?;
    for w in source.warnings(p.scenario.samples, p.scenario.t_s()) {
        tracing::warn!("{w}");
    }
    let mut rec = Recorder::open(&a.out, Role::Master, a.append)?;
    rec.start(start_record(Role::Master, a, &p))?;
    let opts = MasterOptions {
        scenario: p.scenario.clone(),
        base_dir: p.base_dir.clone(),
        startup_timeout: Duration::from_secs_f64(cli.startup_timeout_s.min(1e6)),
        answer_timeout: Duration::from_millis(100),
        wake_early_ns: p.wake_early.as_nanos() as u64,
        run: new_run_token(),
    };
    let ended = master_link(a, p.spin, cli.direct).and_then(|link| {
        let mut ros = crate::outside::RosParts::open(&opts.scenario)?;
        run_with(&opts, link.as_ref(), &mut rec, ros.outside())
            .map_err(|e| NodeError::Failed(e.to_string()))
    });
    match ended {
        Ok(e) => Ok(e == Ending::Completed),
        Err(e) => {
            let _ = rec.event(0, format!("failed: {e}"));
            Err(e)
        }
    }
}
