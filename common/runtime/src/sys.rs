//! The system calls that neither std nor rustix offer, each in a function of its own:
//! calls with plain values whose results are checked. The workspace's other unsafe
//! code: the Verilated modules' FFI (`tactile-rtl`'s `sim.rs`) and the fused
//! multiply-add kernel called after the CPU is checked for it (`tactile-chain`'s
//! `matmul.rs`).
#![allow(unsafe_code)]

use std::io::{Error, Result};

fn check(r: libc::c_int) -> Result<()> {
    if r == 0 {
        Ok(())
    } else {
        Err(Error::last_os_error())
    }
}

/// SCHED_FIFO at `priority` for the calling thread.
pub fn set_fifo(priority: i32) -> Result<()> {
    let p = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: the kernel reads `p`, which lives across the call; pid 0 is the
    // calling thread.
    check(unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &p) })
}

/// SCHED_OTHER (the time-sharing scheduler) for the calling thread.
pub fn set_other() -> Result<()> {
    let p = libc::sched_param { sched_priority: 0 };
    // SAFETY: as in `set_fifo`.
    check(unsafe { libc::sched_setscheduler(0, libc::SCHED_OTHER, &p) })
}

/// SCHED_IDLE for the calling thread: it runs only when nothing else on its CPU wants
/// to, and any other thread's wake-up preempts it.
pub fn set_idle() -> Result<()> {
    let p = libc::sched_param { sched_priority: 0 };
    // SAFETY: as in `set_fifo`.
    check(unsafe { libc::sched_setscheduler(0, libc::SCHED_IDLE, &p) })
}

/// Locks what is mapped now and every page as it is first touched (MCL_ONFAULT:
/// thread stacks and arenas are not faulted in whole, so memory stays as small
/// as it was).
pub fn lock_memory() -> Result<()> {
    // SAFETY: flags only, no pointers.
    check(unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE | libc::MCL_ONFAULT) })
}

/// PR_SET_TIMERSLACK for the calling thread.
pub fn set_timer_slack(ns: libc::c_ulong) -> Result<()> {
    let zero: libc::c_ulong = 0;
    // SAFETY: PR_SET_TIMERSLACK takes integer arguments (unsigned long); no pointers.
    check(unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, ns, zero, zero, zero) })
}

/// Peak resident set size of this process, kB (getrusage: a system call, where
/// reading /proc/self/status took 60 to 75 us, which a loop at 1 kHz feels).
pub fn max_rss_kb() -> u64 {
    let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: the kernel fills the struct `u` points to; it is read only on success.
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, u.as_mut_ptr()) } == 0 {
        // SAFETY: getrusage succeeded, so the struct is initialised.
        let u = unsafe { u.assume_init() };
        u64::try_from(u.ru_maxrss).unwrap_or(0)
    } else {
        0
    }
}
