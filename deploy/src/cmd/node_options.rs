//! The options of the node programs a launch starts (`tactile run`, `tactile bench`),
//! described once, and the launcher's supervision they make.

use std::time::Duration;
use tactile_launch::{stall, Links, Outputs, Supervision};

/// How the node programs a launcher starts wait and are scheduled: the options of
/// `tactile run` and `tactile bench`, described once.
#[derive(Debug, Clone, clap::Args)]
pub struct NodeOptions {
    /// Run name isolating this launch's shared memory, Zenoh keys and locks (default:
    /// one per launcher).
    #[arg(long)]
    pub prefix: Option<String>,
    /// Microseconds each process polls (yielding the core between polls) before it
    /// blocks on its wake-up event. Default: twice the wake-up margin (each node
    /// sleeps until 200 us before a sample is due, at most 40 % of a period), two
    /// periods in lockstep (chosen by measurement, see docs/07-latency.md).
    #[arg(long)]
    pub spin_us: Option<u64>,
    /// Realtime: microseconds before a sample is due that each node stops sleeping
    /// and polls (default 200, at most 40 % of a period).
    #[arg(long)]
    pub wake_early_us: Option<u64>,
    /// Do not pin the processes (by default the master runs on CPU 0 and the emulator
    /// and slave on CPU 1, where the machine has two CPUs).
    #[arg(long)]
    pub no_pin: bool,
    /// Scheduling the nodes set on themselves: fifo (SCHED_FIFO at priority 70 with
    /// memory locked, where permitted; otherwise SCHED_OTHER, said in the report) or
    /// other.
    #[arg(long, value_enum, default_value_t = tactile_runtime::sched::Policy::Fifo)]
    pub sched: tactile_runtime::sched::Policy,
    /// What each node's CPU does while the node sleeps, under SCHED_FIFO: halt (the
    /// kernel's idle; the default) or poll (a SCHED_IDLE thread keeps it busy, so a
    /// halted CPU is not woken late; on these virtual machines a CPU kept busy is
    /// taken away for about 7.5 ms every 10 s instead: docs/07-latency.md).
    #[arg(long, value_enum, default_value_t = tactile_runtime::sched::IdleMode::Halt)]
    pub idle: tactile_runtime::sched::IdleMode,
}

impl NodeOptions {
    /// The supervision of a launch with these options over `link`; `tag` ends the
    /// default prefix (launches of one process stay apart).
    pub fn supervision(&self, link: Links, tag: &str) -> Supervision {
        Supervision {
            prefix: self
                .prefix
                .clone()
                .unwrap_or_else(|| format!("tactile{}{tag}", std::process::id())),
            spin: self.spin_us.map(Duration::from_micros),
            wake_early: self.wake_early_us.map(Duration::from_micros),
            progress: false,
            max_restarts: 0,
            link,
            wrap: Default::default(),
            pin: !self.no_pin,
            sched: self.sched,
            idle: self.idle,
            outputs: Outputs::default(),
            stall: Some(stall::DEFAULT_STALL),
        }
    }
}
