//! The `tactile-emulator` program (NW): its command line and its run.

use crate::process::run_with;
use clap::Parser;
use std::process::ExitCode;
use tactile_messages::Role;
use tactile_node::args::{exit, parse, LinkKind, NodeArgs, NodeError};
use tactile_node::exit::EXIT_CODES_HELP;
use tactile_node::open::{check_link_args, emulator_link};
use tactile_node::recorder::Recorder;
use tactile_node::runtime::{prepare, start_record};

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
    let towards_master = cli.master_link.unwrap_or(a.link);
    let towards_slave = cli.slave_link.unwrap_or(a.link);
    let p = prepare(Role::Emulator, a)?;
    check_link_args(a, &[towards_master, towards_slave])?;
    let replays = crate::replay::load(&p.scenario, &p.base_dir)
        .map_err(|e| NodeError::BadInput(format!("{}: {e}", a.scenario.display())))?;
    let mut rec = Recorder::open(&a.out, Role::Emulator, a.append)?;
    let mut start = start_record(Role::Emulator, a, &p);
    if towards_master != towards_slave {
        start.link = format!(
            "towards the master {}, towards the slave {}; {}",
            towards_master.name(),
            towards_slave.name(),
            start.link
        );
    }
    rec.start(start)?;
    tracing::info!("waiting for the master");
    let ended = emulator_link(a, p.spin, towards_master, towards_slave).and_then(|link| {
        run_with(&p.scenario, replays, link.as_ref(), &mut rec, p.wake_early)
            .map_err(|e| NodeError::Failed(e.to_string()))
    });
    ended.inspect_err(|e| {
        let _ = rec.event(0, format!("failed: {e}"));
    })
}
