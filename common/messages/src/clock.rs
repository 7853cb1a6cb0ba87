//! CLOCK_MONOTONIC in nanoseconds, shared by every process on a host.
//!
//! `std::time::Instant` is opaque and cannot be compared across processes; the
//! monotonic clock can, so a sample stamped by one process and read by another gives
//! a meaningful difference. Across hosts only differences on one clock are meaningful,
//! which is why the round trip is measured on the master's clock alone.

use rustix::time::{clock_gettime, ClockId, Timespec};

/// Nanoseconds since an arbitrary fixed point (boot), CLOCK_MONOTONIC.
pub fn now_ns() -> u64 {
    let t = clock_gettime(ClockId::Monotonic);
    (t.tv_sec as u64)
        .wrapping_mul(1_000_000_000)
        .wrapping_add(t.tv_nsec as u64)
}

/// Sleeps until CLOCK_MONOTONIC reaches `deadline_ns` (absolute, so no drift builds up
/// over a run); returns at once if it has passed. Interrupted sleeps resume.
pub fn sleep_until_ns(deadline_ns: u64) {
    let ts = Timespec {
        tv_sec: (deadline_ns / 1_000_000_000) as _,
        tv_nsec: (deadline_ns % 1_000_000_000) as _,
    };
    while now_ns() < deadline_ns {
        if rustix::thread::clock_nanosleep_absolute(rustix::thread::ClockId::Monotonic, &ts).is_ok()
        {
            break;
        }
    }
}
