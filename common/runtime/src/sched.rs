//! Real-time scheduling, set by each node on itself (no `chrt` or `taskset` around it).
//!
//! Under SCHED_FIFO a node that wakes for its sample runs at once instead of waiting
//! out another task's time slice (the 4 ms stalls of the loop's old tail). It must not
//! poll all the time, or the kernel's real-time throttle stops it for tens of
//! milliseconds: the nodes sleep between samples ([`crate::pace`]) and bound every
//! poll. Memory is locked as it is touched (a page fault in the loop costs
//! microseconds to milliseconds) and the stack prefaulted. Where the kernel refuses
//! (no privilege), the node runs SCHED_OTHER and says so once, in its log and in the
//! run's report.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The scheduling a node asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Policy {
    /// SCHED_FIFO where permitted, else SCHED_OTHER with a note.
    Fifo,
    /// The default time-sharing scheduler.
    Other,
}

impl Policy {
    /// The policy's name on the nodes' command line.
    pub fn name(self) -> &'static str {
        match self {
            Policy::Fifo => "fifo",
            Policy::Other => "other",
        }
    }
}

/// What a CPU does while the realtime node on it sleeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IdleMode {
    /// A SCHED_IDLE thread keeps the CPU busy, so the virtual machine never halts it.
    // (KeepAwake does it; no link here: clap prints this comment as the value's help.)
    Poll,
    /// The kernel's idle: the CPU halts until its next interrupt (the default).
    Halt,
}

impl IdleMode {
    /// The choice's name on the nodes' command line.
    pub fn name(self) -> &'static str {
        match self {
            IdleMode::Poll => "poll",
            IdleMode::Halt => "halt",
        }
    }
}

/// Default SCHED_FIFO priority of the nodes: above everything an ordinary system
/// runs real-time (none on these machines), below the kernel's own (99).
pub const DEFAULT_PRIORITY: u8 = 70;

pub use tactile_records::Sched;

/// SCHED_FIFO at `priority` (1 to 99) for the calling thread only.
pub fn set_thread_fifo(priority: u8) -> std::io::Result<()> {
    crate::sys::set_fifo(i32::from(priority))
}

/// SCHED_OTHER for the calling thread only: a helper thread of a SCHED_FIFO node
/// (which it would otherwise inherit) that must never take the CPU from the loop.
pub fn set_thread_other() -> std::io::Result<()> {
    crate::sys::set_other()
}

/// Bytes of stack touched at start, so the loop never faults a stack page in.
const STACK_PREFAULT: usize = 256 * 1024;

/// Applies `policy` to the calling thread (threads it starts later inherit it) and
/// locks memory; returns the policy in force, the priority, whether memory is locked,
/// and a note for each thing the kernel refused.
pub fn apply(policy: Policy, priority: u8) -> (bool, bool, Vec<String>) {
    let mut notes = Vec::new();
    set_timer_slack();
    let fifo = match policy {
        Policy::Other => false,
        Policy::Fifo => match crate::sys::set_fifo(i32::from(priority)) {
            Ok(()) => true,
            Err(e) => {
                notes.push(format!(
                    "SCHED_FIFO not permitted ({e}): running SCHED_OTHER"
                ));
                false
            }
        },
    };
    let locked = match policy {
        Policy::Other => false,
        Policy::Fifo if !may_lock_everything() => {
            notes.push(
                "memory not locked (no CAP_IPC_LOCK and a finite RLIMIT_MEMLOCK: locking \
                 future pages could make the links' later mappings fail)"
                    .into(),
            );
            false
        }
        Policy::Fifo => match crate::sys::lock_memory() {
            Ok(()) => true,
            Err(e) => {
                notes.push(format!("memory not locked ({e})"));
                false
            }
        },
    };
    if locked {
        prefault_stack();
    }
    (fifo, locked, notes)
}

/// True if locking every future page cannot run into a limit: the process holds
/// CAP_IPC_LOCK, or its RLIMIT_MEMLOCK is unlimited. (With a finite limit, mlockall
/// may succeed now and make a later mmap, such as a shared-memory segment, fail.)
fn may_lock_everything() -> bool {
    use rustix::process::{getrlimit, Resource};
    let cap = rustix::thread::capabilities(None).is_ok_and(|c| {
        c.effective
            .contains(rustix::thread::CapabilitySet::IPC_LOCK)
    });
    cap || getrlimit(Resource::Memlock).current.is_none()
}

/// Timer slack of 1 ns: an ordinary thread's sleeps end up to 50 us late by default
/// (real-time threads have none).
fn set_timer_slack() {
    let _ = crate::sys::set_timer_slack(1);
}

#[inline(never)]
fn prefault_stack() {
    let mut buf = [0u8; STACK_PREFAULT];
    std::hint::black_box(&mut buf);
}

/// Threads at SCHED_IDLE, one per CPU the node may run on, that spin while the node
/// sleeps; stopped and joined when dropped.
///
/// Why: on a virtual machine a CPU with nothing to run halts, and the hypervisor wakes
/// it late for the node's timer. A SCHED_FIFO thread sleeping to each 1 ms tick on
/// these machines woke 39 us late at p50, 304 to 428 us at p99.9 and up to 1.7 ms;
/// with a SCHED_IDLE thread spinning on its CPU, 16 us, 23 to 64 us and 31 to 227 us.
/// Any thread's wake-up preempts a SCHED_IDLE thread at once, so it takes nothing from
/// the loop. But it is not the default: here the hypervisor takes a CPU that never
/// idles away for about 7.5 ms every 10 s, and the loop misses 11 to 12 deadlines in
/// 20 s where with halting CPUs it missed none (docs/07-latency.md, "What the CPUs do while the
/// nodes sleep"). On a machine whose cores are the loop's own it is what the kernel's
/// `idle=poll` does, for these CPUs only. The spin has no `pause` hint: on these machines a
/// pause loop makes the hypervisor take the CPU away (pause-loop exiting), which
/// measured worse. Only under SCHED_FIFO: a SCHED_OTHER node that yields while it polls
/// would hand its CPU to the spinning thread until the next scheduler tick.
#[derive(Debug)]
pub struct KeepAwake {
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

/// Why a CPU could not be asked about, pinned or kept awake.
#[derive(Debug, thiserror::Error)]
pub enum SchedError {
    /// The CPUs this thread may use could not be read.
    #[error("reading CPU affinity: {0}")]
    Affinity(#[source] rustix::io::Errno),
    /// `--cpu` names a CPU this process may not use.
    #[error("--cpu {0}: not a CPU this process may use")]
    NotAllowed(usize),
    /// Pinning to the CPU failed.
    #[error("pinning {who}to CPU {cpu}: {source}")]
    Pin {
        /// Whose pinning (`the idle-poll thread `, or empty for the node).
        who: &'static str,
        /// The CPU.
        cpu: usize,
        /// The kernel's reason.
        source: rustix::io::Errno,
    },
    /// The spinning thread could not lower itself to SCHED_IDLE.
    #[error("SCHED_IDLE for the idle-poll thread: {0}")]
    Idle(#[source] std::io::Error),
    /// The spinning thread could not be started.
    #[error("starting the idle-poll thread: {0}")]
    Spawn(#[source] std::io::Error),
    /// The spinning thread ended before it said whether it could lower itself.
    #[error("the idle-poll thread ended at start")]
    Ended(#[source] std::sync::mpsc::RecvError),
}

impl KeepAwake {
    /// Starts one spinning thread on each CPU the calling thread may run on; each
    /// lowers itself to SCHED_IDLE before it spins.
    pub fn start() -> Result<KeepAwake, SchedError> {
        let cpus = allowed_cpus()?;
        let stop = Arc::new(AtomicBool::new(false));
        let mut awake = KeepAwake {
            stop: stop.clone(),
            threads: Vec::new(),
        };
        for cpu in cpus {
            let stop = stop.clone();
            // The thread's only sender: if it dies before it says, the receive fails.
            let (tx, rx) = std::sync::mpsc::sync_channel(1);
            let t = std::thread::Builder::new()
                .name(format!("idle-poll-{cpu}"))
                .stack_size(64 * 1024)
                .spawn(move || {
                    let ready = spinner_setup(cpu);
                    let ok = ready.is_ok();
                    let _ = tx.send(ready);
                    while ok && !stop.load(Ordering::Relaxed) {}
                })
                .map_err(SchedError::Spawn)?;
            awake.threads.push(t);
            // Each thread says whether it could lower itself before it spins: a thread
            // left at the node's SCHED_FIFO must never spin.
            rx.recv().map_err(SchedError::Ended)??;
        }
        Ok(awake)
    }
}

/// The CPUs the calling thread may run on.
pub fn allowed_cpus() -> Result<Vec<usize>, SchedError> {
    use rustix::thread::{sched_getaffinity, CpuSet};
    let set = sched_getaffinity(None).map_err(SchedError::Affinity)?;
    Ok((0..CpuSet::MAX_CPU).filter(|&c| set.is_set(c)).collect())
}

/// Pins the calling thread to `cpu` alone (threads it starts later inherit it).
pub fn pin_thread(cpu: usize) -> rustix::io::Result<()> {
    let mut set = rustix::thread::CpuSet::new();
    set.set(cpu);
    rustix::thread::sched_setaffinity(None, &set)
}

/// Pins the calling thread to `cpu` and lowers it to SCHED_IDLE.
fn spinner_setup(cpu: usize) -> Result<(), SchedError> {
    pin_thread(cpu).map_err(|source| SchedError::Pin {
        who: "the idle-poll thread ",
        cpu,
        source,
    })?;
    crate::sys::set_idle().map_err(SchedError::Idle)
}

impl Drop for KeepAwake {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn other_asks_nothing_of_the_kernel() {
        let (fifo, locked, notes) = apply(Policy::Other, DEFAULT_PRIORITY);
        assert!(!fifo && !locked && notes.is_empty());
    }

    #[test]
    fn keep_awake_spins_at_sched_idle_and_stops() {
        // Where permitted (root), from a SCHED_FIFO thread as in a node: the spinners
        // inherit SCHED_FIFO and must lower themselves. (This test's thread ends with
        // the test.)
        let _ = set_thread_fifo(10);
        let awake = KeepAwake::start().expect("start");
        assert!(!awake.threads.is_empty());
        let me = std::process::id();
        let mut idle = 0;
        for t in std::fs::read_dir(format!("/proc/{me}/task"))
            .expect("tasks")
            .flatten()
        {
            let stat = std::fs::read_to_string(t.path().join("stat")).unwrap_or_default();
            let comm = std::fs::read_to_string(t.path().join("comm")).unwrap_or_default();
            // Field 41 of stat is the policy; SCHED_IDLE is 5.
            let after = stat.rsplit(')').next().unwrap_or_default();
            let policy = after.split_whitespace().nth(38).unwrap_or_default();
            if comm.starts_with("idle-poll-") {
                assert_eq!(policy, "5", "{comm}: {stat}");
                idle += 1;
            }
        }
        assert_eq!(idle, awake.threads.len());
        drop(awake);
    }
}
