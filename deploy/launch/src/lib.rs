//! The launcher: runs a scenario's three node programs on this host (or across
//! network namespaces) and supervises them, or simulates the loop in this process, and
//! runs sweeps of them. `tactile run`, `sweep` and `bench` and the Python package all
//! start runs through here, with plain values (the command's arguments are the
//! command's: this crate parses no command line).

pub mod error;
pub mod estimate;
pub mod links;
pub mod netns;
pub mod nodes;
pub mod pki;
mod proc;
pub mod recordable;
pub mod say;
pub mod scenario;
pub mod sim;
pub mod stall;
pub mod stop;
pub mod supervise;
pub mod sweep;

pub use links::Links;
pub use scenario::{
    load_scenario, load_source, parse_sets, prepare_out, Loaded, Source, PAPER_SCENARIO,
};
pub use supervise::run_processes;

use std::time::Duration;
use tactile_runtime::args::LinkKind;
use tactile_scenario::Scenario;

pub use tactile_report::write::Outputs;

/// How `tactile run` supervises its processes.
#[derive(Debug, Clone)]
pub struct Supervision {
    /// iceoryx2 prefix of the run.
    pub prefix: String,
    /// Poll budget of every process (None: each node's default, docs/07-latency.md, "Waiting").
    pub spin: Option<Duration>,
    /// How long before a sample is due each node wakes (None: each node's default).
    pub wake_early: Option<Duration>,
    /// Progress line on a terminal.
    pub progress: bool,
    /// Restarts allowed per process (emulator, slave) when one dies mid-run.
    pub max_restarts: u32,
    /// What carries the samples, and the link options of each node.
    pub link: Links,
    /// Command prefix of the master, the emulator and the slave (e.g. `ip netns exec
    /// A` to put a node on another host); empty: run the program directly.
    pub wrap: [Vec<String>; 3],
    /// Pin master to CPU 0, emulator and slave to CPU 1.
    pub pin: bool,
    /// Scheduling of the three processes, which each node sets on itself.
    pub sched: tactile_runtime::sched::Policy,
    /// What each node's CPU does while the node sleeps (realtime, SCHED_FIFO).
    pub idle: tactile_runtime::sched::IdleMode,
    /// What the report writes besides the summary.
    pub outputs: Outputs,
    /// How long a node's record may stand still before the node counts as frozen
    /// (None: never).
    pub stall: Option<Duration>,
}

/// How `tactile sweep --processes` runs each combination: as `tactile run` does by
/// default, no restarts, no progress line.
pub fn sweep_supervision(outputs: Outputs) -> Supervision {
    Supervision {
        prefix: format!("tactile{}s", std::process::id()),
        spin: None,
        wake_early: None,
        progress: false,
        max_restarts: 0,
        link: Links::plain(LinkKind::Iceoryx2),
        wrap: Default::default(),
        pin: true,
        sched: tactile_runtime::sched::Policy::Fifo,
        idle: tactile_runtime::sched::IdleMode::Halt,
        outputs,
        stall: Some(stall::DEFAULT_STALL),
    }
}

/// True if this machine lets the process use CPUs 0 and 1.
pub fn two_cpus() -> bool {
    rustix::thread::sched_getaffinity(None).is_ok_and(|s| s.is_set(0) && s.is_set(1))
}

/// Removes what runs that have ended left behind: lock files nobody holds, and the
/// shared memory and iceoryx2 folders of every prefix no live process holds a lock of
/// (a crashed or killed run leaves them; iceoryx2 would clean them only for the same
/// prefix). A live run's are never touched: each of its processes holds its lock.
pub fn clean_stale_runs() {
    tactile_runtime::lock::clean_stale();
    let Ok(dir) = std::fs::read_dir(tactile_transport::ipc::ROOT) else {
        return;
    };
    for entry in dir.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        let is_prefix = tactile_runtime::lock::check_prefix(&name).is_ok() && entry.path().is_dir();
        if !is_prefix {
            continue;
        }
        // Every lock of the prefix held while its files go, so no node of it starts
        // meanwhile (one that tries finds its prefix in use).
        if let Some(_locks) = tactile_runtime::lock::take_all(&name, "tactile cleaning a dead run")
        {
            tactile_transport::ipc::remove_run_files(&name);
        }
    }
}

/// How long the launcher lets the emulator and slave run on after the master died:
/// long enough for the slave to notice and hold (its peer timeout) and to be seen.
pub fn survivor_grace(scenario: &Scenario) -> Duration {
    tactile_slave::handler::hold_timeout(scenario) + Duration::from_millis(500)
}

/// Where a report of the records in `dirs` goes without `--out`: beside the master's
/// record (the run's folder; with one folder per node, the master's).
pub fn report_out(dirs: &[std::path::PathBuf]) -> Result<std::path::PathBuf, error::Error> {
    let [master, _, _] = tactile_report::join::locate(dirs)?;
    Ok(master
        .as_deref()
        .and_then(std::path::Path::parent)
        .map_or_else(
            || std::path::PathBuf::from("."),
            std::path::Path::to_path_buf,
        ))
}
