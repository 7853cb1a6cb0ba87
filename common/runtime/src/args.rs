//! A node program's command line and outcome: the options every node takes
//! ([`NodeArgs`], with its links' [`LinkArgs`]), why a node stops ([`NodeError`]), and
//! the mapping of its outcome to an exit status and one line on stderr.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use tactile_messages::Role;
pub use tactile_transport::{LinkArgs, LinkKind};

use crate::exit::{EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_OK};

/// The command line every node takes.
#[derive(Debug, Clone, PartialEq, Args)]
pub struct NodeArgs {
    /// Scenario file (TOML); its relative paths are resolved against its own folder.
    #[arg(long)]
    pub scenario: PathBuf,
    /// Folder for this node's record (`ROLE.rec`) and log (`ROLE.log`).
    #[arg(long)]
    pub out: PathBuf,
    /// The links: transport, ports, endpoints, TLS.
    #[command(flatten)]
    pub link: LinkArgs,
    /// Microseconds to poll (yielding the CPU) before blocking on the wake-up event.
    /// Default: twice --wake-early-us in realtime (the node wakes that long before a
    /// sample is due), two sampling periods in lockstep; 0 blocks at once.
    #[arg(long)]
    pub spin_us: Option<u64>,
    /// Realtime: stop sleeping this long before a sample is due, then poll. Default
    /// 200 us, at most 40 % of a sampling period (measured, docs/07-latency.md, "Waiting").
    #[arg(long)]
    pub wake_early_us: Option<u64>,
    /// Scheduling: fifo (SCHED_FIFO with memory locked, where permitted; otherwise
    /// SCHED_OTHER, said in the log and the report) or other. Lockstep runs always
    /// SCHED_OTHER: its loop never sleeps.
    #[arg(long, value_enum, default_value_t = crate::sched::Policy::Fifo)]
    pub sched: crate::sched::Policy,
    /// What the node's CPU does while a realtime node under SCHED_FIFO sleeps: halt
    /// (the kernel's idle; the default) or poll (a SCHED_IDLE thread keeps it busy, so
    /// a halted CPU is not woken late; on these virtual machines a CPU kept busy is
    /// taken away for about 7.5 ms every 10 s instead: docs/07-latency.md, "What the CPUs do while the nodes
    /// sleep").
    #[arg(long, value_enum, default_value_t = crate::sched::IdleMode::Halt)]
    pub idle: crate::sched::IdleMode,
    /// SCHED_FIFO priority, 1 to 98.
    #[arg(long, default_value_t = crate::sched::DEFAULT_PRIORITY, value_parser = clap::value_parser!(u8).range(1..=98))]
    pub priority: u8,
    /// Pin this node to one CPU.
    #[arg(long)]
    pub cpu: Option<usize>,
    /// Continue this node's record in --out instead of starting it afresh (a node
    /// restarted into a run that is still going).
    #[arg(long)]
    pub append: bool,
    /// Started by `tactile run` (process id of the launcher): stop when it dies, log
    /// to the file only.
    #[arg(long, hide = true)]
    pub supervised: Option<u32>,
}

/// `--flag value` for an option that is set.
fn opt(v: &mut Vec<String>, flag: &str, value: Option<String>) {
    if let Some(x) = value {
        v.push(flag.to_string());
        v.push(x);
    }
}

impl NodeArgs {
    /// The command line that parses back to these arguments: how a launcher starts a
    /// node, written next to the options so a flag is named once.
    pub fn argv(&self) -> Vec<String> {
        let mut v = Vec::new();
        let path = |p: &PathBuf| Some(p.display().to_string());
        opt(&mut v, "--scenario", path(&self.scenario));
        opt(&mut v, "--out", path(&self.out));
        v.extend(self.link.argv());
        opt(&mut v, "--spin-us", self.spin_us.map(|x| x.to_string()));
        opt(
            &mut v,
            "--wake-early-us",
            self.wake_early_us.map(|x| x.to_string()),
        );
        opt(&mut v, "--sched", Some(self.sched.name().into()));
        opt(&mut v, "--idle", Some(self.idle.name().into()));
        opt(&mut v, "--priority", Some(self.priority.to_string()));
        opt(&mut v, "--cpu", self.cpu.map(|x| x.to_string()));
        if self.append {
            v.push("--append".into());
        }
        opt(
            &mut v,
            "--supervised",
            self.supervised.map(|x| x.to_string()),
        );
        v
    }
}

/// Why a node stopped without completing.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// Bad input; nothing was started (exit 2).
    #[error("{0}")]
    BadInput(String),
    /// The scenario or a file it names cannot be read (exit 2).
    #[error(transparent)]
    File(#[from] crate::files::FileError),
    /// The prefix is malformed or held (exit 2).
    #[error(transparent)]
    Lock(#[from] crate::lock::LockError),
    /// `--cpu` cannot be honoured (exit 2).
    #[error(transparent)]
    Sched(#[from] crate::sched::SchedError),
    /// The log file cannot be opened (exit 2).
    #[error(transparent)]
    Log(#[from] crate::logging::LogError),
    /// A failure while running (exit 1).
    #[error("{0}")]
    Failed(String),
}

impl NodeError {
    /// The exit status.
    pub fn code(&self) -> u8 {
        match self {
            NodeError::Failed(_) => EXIT_FAILURE,
            _ => EXIT_BAD_INPUT,
        }
    }
}

/// Maps a node's outcome to its exit status and one line on stderr.
pub fn exit(role: Role, outcome: Result<bool, NodeError>) -> ExitCode {
    match outcome {
        Ok(true) => ExitCode::from(EXIT_OK),
        Ok(false) => ExitCode::from(EXIT_INTERRUPTED),
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("tactile-{role}: {e}");
            ExitCode::from(e.code())
        }
    }
}

/// Parses a node's command line; on an error prints clap's message and returns the
/// exit status (2 for bad arguments, 0 for --help and --version).
pub fn parse<T: clap::Parser>() -> Result<T, ExitCode> {
    // First thing, while the node has one thread.
    #[cfg(feature = "zenoh")]
    tactile_transport::zenoh_link::default_runtime();
    T::try_parse().map_err(|e| {
        let _ = e.print();
        ExitCode::from(if e.use_stderr() {
            EXIT_BAD_INPUT
        } else {
            EXIT_OK
        })
    })
}

/// Node arguments as the tests write them.
#[cfg(test)]
pub(crate) mod testing {
    use super::NodeArgs;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Cli {
        #[command(flatten)]
        node: NodeArgs,
    }

    /// A node's arguments with `--scenario s.toml --out o` and `extra`.
    pub fn args(extra: &[&str]) -> NodeArgs {
        let mut v = vec!["node", "--scenario", "s.toml", "--out", "o"];
        v.extend_from_slice(extra);
        Cli::parse_from(v).node
    }

    /// Arguments parsed from a whole command line, or clap's error.
    pub fn parse(argv: &[String]) -> Result<NodeArgs, clap::Error> {
        let mut v = vec!["node".to_string()];
        v.extend_from_slice(argv);
        Cli::try_parse_from(v).map(|c| c.node)
    }
}

#[cfg(test)]
mod tests {
    use super::testing::{args, parse};
    use proptest::prelude::*;

    proptest! {
        /// Whatever a launcher sets, the command line it writes parses back to it.
        #[test]
        fn a_command_line_parses_back_to_its_arguments(
            spin in proptest::option::of(0u64..5000),
            early in proptest::option::of(0u64..900),
            cpu in proptest::option::of(0usize..4),
            priority in 1u8..=98,
            append: bool,
            supervised in proptest::option::of(1u32..99999),
            link in 0usize..3,
            tls: bool,
        ) {
            let kind = ["iceoryx2", "udp", "zenoh"][link];
            let mut extra = vec!["--link", kind, "--prefix", "p_1", "--udp-ports", "1,2,3"];
            extra.extend(["--listen", "tcp/127.0.0.1:1", "--connect", "tcp/127.0.0.1:2"]);
            if tls {
                extra.extend(["--tls-ca", "ca.pem", "--tls-cert", "n.pem", "--tls-key", "n.key"]);
            }
            let mut a = args(&extra);
            a.spin_us = spin;
            a.wake_early_us = early;
            a.cpu = cpu;
            a.priority = priority;
            a.append = append;
            a.supervised = supervised;
            let back = parse(&a.argv()).expect("parses");
            prop_assert_eq!(back, a);
        }
    }
}
