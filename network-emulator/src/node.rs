//! The `tactile-emulator` program (NW): its command line and its run.

use crate::emulator::Emulator;
use crate::handler::EmulatorHandler;
use clap::Parser;
use std::process::ExitCode;
use tactile_messages::Role;
use tactile_runtime::args::{exit, parse, LinkKind, NodeArgs, NodeError};
use tactile_runtime::exit::EXIT_CODES_HELP;
use tactile_runtime::program::{Opened, Program};
use tactile_runtime::start::Links;

/// tactile-emulator: the network between master and slave. Delays, perturbs, drops
/// and corrupts c(n) and h(n) as the scenario says (seeded), and records every sample.
#[derive(Debug, Parser)]
#[command(name = "tactile-emulator", version, about, after_help = EXIT_CODES_HELP)]
pub struct Cli {
    /// Options every node takes.
    #[command(flatten)]
    pub node: NodeArgs,
    /// The link towards the master (default: --link), so the emulator can sit on the
    /// slave's host (--master-link zenoh --slave-link iceoryx2) or the master's.
    #[arg(long, value_enum)]
    pub master_link: Option<LinkKind>,
    /// The link towards the slave (default: --link).
    #[arg(long, value_enum)]
    pub slave_link: Option<LinkKind>,
}

/// The program: parse, run, exit status.
pub fn main() -> ExitCode {
    match parse::<Cli>() {
        Ok(cli) => exit(Role::Emulator, run(&cli)),
        Err(code) => code,
    }
}

/// Runs the emulator until the master's end-of-run sample (`Ok(true)`) or a stop
/// request (`Ok(false)`).
pub fn run(cli: &Cli) -> Result<bool, NodeError> {
    let a = &cli.node;
    let links = Links {
        master_side: cli.master_link.unwrap_or(a.link.link),
        slave_side: cli.slave_link.unwrap_or(a.link.link),
        direct: false,
    };
    let program = Program::prepare(Role::Emulator, a, links)?;
    let replays = crate::replay::load(program.scenario(), &program.prepared().base_dir)
        .map_err(|e| NodeError::BadInput(format!("{}: {e}", a.scenario.display())))?;
    let histograms = crate::histogram::load(program.scenario(), &program.prepared().base_dir)
        .map_err(|e| NodeError::BadInput(format!("{}: {e}", a.scenario.display())))?;
    program.follow(Box::new(move |p| {
        Ok(Opened::alone(EmulatorHandler::new(
            Emulator::with_replays(&p.scenario, replays)
                .with_histograms(p.scenario.seed, histograms),
        )))
    }))
}
