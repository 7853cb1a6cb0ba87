//! The `tactile-slave` program (HSD): its command line and its run.

use crate::handler::SlaveHandler;
use crate::hsd::Slave;
use crate::peripherals;
use crate::urdf_arm::UrdfArm;
use crate::world::SlaveWorld;
use clap::Parser;
use std::process::ExitCode;
use tactile_messages::Role;
use tactile_runtime::args::{exit, parse, NodeArgs, NodeError};
use tactile_runtime::exit::EXIT_CODES_HELP;
use tactile_runtime::program::{Opened, Program};
use tactile_runtime::start::Links;

/// tactile-slave: the remote side (HSD, SD, ENV). Follows v(n) with the slave arm,
/// senses contact, sends the force h(n) back, and records every step.
///
/// The arm and its environment are simulated, or a real robot under ros2_control over
/// rmw_zenoh (`slave.backend = "ros2"` and `[slave.ros2]` in the scenario: joint
/// references out as Float64MultiArray, or JointTrajectory for an arm from its URDF,
/// JointState and an optional force-torque WrenchStamped in); it waits for the robot's
/// first message before it answers the master. `[ros.live]` publishes the slave's state as ROS 2 topics while it runs.
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

/// Runs the slave until the master's end-of-run sample (`Ok(true)`) or a stop request
/// (`Ok(false)`).
pub fn run(cli: &Cli) -> Result<bool, NodeError> {
    let a = &cli.node;
    let program = Program::prepare(Role::Slave, a, Links::all(a.link.link))?;
    // Read and checked before anything starts: a bad URDF is bad input (exit 2). Read
    // and parsed once: the simulated arm, the robot over ROS 2 and the live view take
    // its model.
    let (sc, base_dir) = (program.scenario(), &program.prepared().base_dir);
    let urdf = UrdfArm::read_urdf(sc, base_dir).map_err(NodeError::BadInput)?;
    let arm = peripherals::of_scenario(sc, urdf.as_ref()).map_err(NodeError::BadInput)?;
    // A physics world's meshes and start are checked here too: bad input, exit 2.
    let world =
        SlaveWorld::of_scenario(sc, base_dir).map_err(|e| NodeError::BadInput(e.to_string()))?;
    program.follow(Box::new(move |p| {
        let opened = peripherals::open(&p.scenario, &p.base_dir, urdf.as_ref())?;
        let slave =
            Slave::new(&p.scenario, arm, world).map_err(|e| NodeError::Failed(e.to_string()))?;
        Ok(Opened {
            handler: SlaveHandler::new(slave, &p.scenario, opened.robot),
            live: opened.live,
        })
    }))
}
