//! The `tactile-slave` program (HSD): its command line and its run.

use crate::process::run_with;
use clap::Parser;
use std::process::ExitCode;
use tactile_messages::Role;
use tactile_node::args::{exit, parse, NodeArgs, NodeError};
use tactile_node::exit::EXIT_CODES_HELP;
use tactile_node::open::slave_link;
use tactile_node::recorder::Recorder;
use tactile_node::runtime::{prepare, start_record};

/// tactile-slave: the remote side (HSD, SD, ENV). Follows v(n) with the slave arm,
/// senses contact, sends the force h(n) back, and records every step.
///
/// The arm and its environment are simulated, or a real robot under ros2_control over
/// rmw_zenoh (`slave.backend = "ros2"` and `[slave.ros2]` in the scenario: joint
/// references out as Float64MultiArray, JointState and an optional force-torque
/// WrenchStamped in); it waits for the robot's first message before it answers the
/// master. `[ros.live]` publishes the slave's state as ROS 2 topics while it runs.
/// Both need a build with the `zenoh` feature; every option is in
/// docs/11-real-devices-and-ros2.md.
#[derive(Debug, Parser)]
#[command(name = "tactile-slave", version, about, after_help = EXIT_CODES_HELP)]
pub struct Cli {
    /// Options every node takes.
    #[command(flatten)]
    pub node: NodeArgs,
}

/// The program: parse, run, exit status.
pub fn main() -> ExitCode {
    match parse::<Cli>() {
        Ok(cli) => exit(Role::Slave, run(&cli)),
        Err(code) => code,
    }
}

/// Runs the emulator until the master's end-of-run sample (`Ok(true)`) or a stop
/// request (`Ok(false)`).
pub fn run(cli: &Cli) -> Result<bool, NodeError> {
    let a = &cli.node;
    let p = prepare(Role::Slave, a)?;
    if crate::outside::needs_ros(&p.scenario) && !cfg!(feature = "zenoh") {
        return Err(NodeError::BadInput(tactile_node::args::NO_ROS.into()));
    }
    let mut rec = Recorder::open(&a.out, Role::Slave, a.append)?;
    rec.start(start_record(Role::Slave, a, &p))?;
    tracing::info!("waiting for the master");
    let ended = slave_link(a, p.spin).and_then(|link| {
        let mut ros = crate::outside::RosParts::open(&p.scenario)?;
        run_with(
            &p.scenario,
            link.as_ref(),
            &mut rec,
            p.wake_early,
            ros.outside(),
        )
        .map_err(|e| NodeError::Failed(e.to_string()))
    });
    ended.inspect_err(|e| {
        let _ = rec.event(0, format!("failed: {e}"));
    })
}
