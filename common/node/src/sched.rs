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

use serde::{Deserialize, Serialize};

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

/// Default SCHED_FIFO priority of the nodes: above everything an ordinary system
/// runs real-time (none on these machines), below the kernel's own (99).
pub const DEFAULT_PRIORITY: u8 = 70;

/// What a node runs with, recorded in its record's start and in the run's summary.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Sched {
    /// `SCHED_FIFO` or `SCHED_OTHER`.
    pub policy: String,
    /// SCHED_FIFO priority (0 under SCHED_OTHER).
    pub priority: u8,
    /// CPU the node is pinned to, if any.
    pub cpu: Option<usize>,
    /// How long before a sample is due the node stops sleeping, us (0: it never
    /// sleeps, as in lockstep).
    pub wake_early_us: u64,
    /// How long it polls before it blocks, us.
    pub poll_us: u64,
    /// Memory locked (mlockall, pages locked as they are touched).
    pub memory_locked: bool,
    /// Why the node does not run as asked, if it does not.
    pub note: Option<String>,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn other_asks_nothing_of_the_kernel() {
        let (fifo, locked, notes) = apply(Policy::Other, DEFAULT_PRIORITY);
        assert!(!fifo && !locked && notes.is_empty());
    }
}
