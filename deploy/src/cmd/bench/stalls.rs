//! The machine's own stalls, measured beside the loops (`tactile bench --probe-s`).
//!
//! A thread per CPU at SCHED_FIFO 99, pinned, reads the monotonic clock in a tight
//! loop; a gap between two reads is time its CPU did not run it. Nothing in the guest
//! preempts a SCHED_FIFO 99 thread but interrupts, the kernel's stop-machine work and
//! (if set below 900 ms a second) the real-time throttle, and the loop touches no new
//! memory, so a gap of milliseconds is the CPU taken away (by the hypervisor, which
//! the steal counter of `/proc/stat` does not always show): a loop's deadline miss
//! that lines up with such gaps is the machine's, not the loop's. Each thread spins
//! 900 ms of every second and sleeps the rest: the kernel's default real-time
//! throttle (950 ms of every second) is never reached and the other tasks keep a
//! tenth of the CPUs (so the CPUs probed are busy 90 % of the time, not always).

use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Shortest gap counted, ns: a timer interrupt on these machines takes 5 to 50 us.
const COUNTED_NS: u64 = 100_000;
/// Gaps long enough to cost a 1 kHz loop its deadline, ns.
const LONG_NS: u64 = 1_000_000;
/// Start times kept of the long gaps, per CPU (memory stays bounded).
const KEPT: usize = 32;
/// Spin this much of every second.
const SPIN_OF_SECOND: Duration = Duration::from_millis(900);

/// What one CPU's probe saw.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CpuStalls {
    /// The CPU.
    pub cpu: usize,
    /// Time the probe spun, s (its gaps included).
    pub spun_s: f64,
    /// Gaps of 100 us or more.
    pub over_100us: u64,
    /// Gaps of 1 ms or more.
    pub over_1ms: u64,
    /// Time lost in gaps of 1 ms or more, ms.
    pub lost_ms: f64,
    /// Longest gap, us.
    pub max_us: f64,
    /// When the first gaps of 1 ms or more began, s from the probe's start.
    pub long_at_s: Vec<f64>,
}

impl CpuStalls {
    /// Counts a gap of `gap_ns` that began `at_ns` after the probe started.
    pub fn add(&mut self, at_ns: u64, gap_ns: u64) {
        if gap_ns < COUNTED_NS {
            return;
        }
        self.over_100us += 1;
        self.max_us = self.max_us.max(gap_ns as f64 / 1e3);
        if gap_ns >= LONG_NS {
            self.over_1ms += 1;
            self.lost_ms += gap_ns as f64 / 1e6;
            if self.long_at_s.len() < KEPT {
                self.long_at_s.push(at_ns as f64 / 1e9);
            }
        }
    }
}

/// The probe's result: one entry per CPU, or why it did not run.
#[derive(Debug, Clone, Default, Serialize)]
pub struct StallReport {
    /// Each CPU probed.
    pub cpus: Vec<CpuStalls>,
    /// Probed at SCHED_FIFO 99 (else at the caller's policy).
    pub fifo: bool,
    /// Why nothing (or not everything) was measured.
    pub note: Option<String>,
}

/// Probes every CPU this process may use for `seconds`, all at once, until `stop` is
/// set. `fifo`: at SCHED_FIFO 99 (else at the caller's policy, which measures the
/// scheduler too).
pub fn probe(seconds: f64, fifo: bool, stop: &Arc<AtomicBool>) -> StallReport {
    let cpus = match tactile_runtime::sched::allowed_cpus() {
        Ok(c) => c,
        Err(e) => {
            return StallReport {
                note: Some(e.to_string()),
                ..Default::default()
            }
        }
    };
    let length = Duration::from_secs_f64(seconds.max(0.0));
    let threads: Vec<_> = cpus
        .into_iter()
        .map(|cpu| {
            let stop = Arc::clone(stop);
            std::thread::spawn(move || probe_cpu(cpu, length, fifo, &stop))
        })
        .collect();
    let mut report = StallReport {
        fifo,
        ..Default::default()
    };
    let mut notes = Vec::new();
    for t in threads {
        match t.join() {
            Ok(Ok(c)) => report.cpus.push(c),
            Ok(Err(e)) => notes.push(e),
            Err(_) => notes.push("a probe thread panicked".into()),
        }
    }
    if stop.load(Ordering::Relaxed) {
        notes.push("stopped before the end".into());
    }
    notes.dedup();
    report.note = (!notes.is_empty()).then(|| notes.join("; "));
    report
}

/// One CPU's probe, in its own thread (the affinity and policy it sets die with it).
fn probe_cpu(
    cpu: usize,
    length: Duration,
    fifo: bool,
    stop: &AtomicBool,
) -> Result<CpuStalls, String> {
    tactile_runtime::sched::pin_thread(cpu)
        .map_err(|e| format!("pinning the probe to CPU {cpu}: {e}"))?;
    if fifo {
        tactile_runtime::sched::set_thread_fifo(99)
            .map_err(|e| format!("SCHED_FIFO not permitted ({e}): machine not probed"))?;
    }
    let mut s = CpuStalls {
        cpu,
        // Allocated before the spin, which then touches no new memory.
        long_at_s: Vec::with_capacity(KEPT),
        ..Default::default()
    };
    let start = Instant::now();
    let mut spun = Duration::ZERO;
    while spun < length && !stop.load(Ordering::Relaxed) {
        let burst = SPIN_OF_SECOND.min(length - spun);
        let from = Instant::now();
        let mut last = from;
        while last - from < burst && !stop.load(Ordering::Relaxed) {
            let now = Instant::now();
            let gap = (now - last).as_nanos() as u64;
            s.add((last - start).as_nanos() as u64, gap);
            last = now;
        }
        spun += last - from;
        if spun < length {
            std::thread::sleep(Duration::from_secs(1).saturating_sub(SPIN_OF_SECOND));
        }
    }
    s.spun_s = spun.as_secs_f64();
    Ok(s)
}

/// The report's lines for the bench's table.
pub fn render(r: &StallReport) -> String {
    use std::fmt::Write as _;
    let mut t = String::new();
    let how = if r.fifo {
        "at SCHED_FIFO 99"
    } else {
        "at the bench's own policy"
    };
    for c in &r.cpus {
        let every = if c.over_1ms > 0 {
            format!(", one every {:.1} s", c.spun_s / c.over_1ms as f64)
        } else {
            String::new()
        };
        let _ = writeln!(
            t,
            "CPU {}: {:.1} s spun {how}: {} gaps >= 100 us, {} >= 1 ms ({:.1} ms lost{every}), longest {:.0} us",
            c.cpu, c.spun_s, c.over_100us, c.over_1ms, c.lost_ms, c.max_us
        );
    }
    if let Some(n) = &r.note {
        let _ = writeln!(t, "machine probe: {n}");
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Whatever the gaps, each is counted in the classes it belongs to, the time
        /// lost is the sum of the long ones, and the kept start times are theirs.
        #[test]
        fn gaps_are_counted_by_class(gaps in proptest::collection::vec(0u64..20_000_000, 0..200)) {
            let mut s = CpuStalls::default();
            let mut at = 0;
            let mut long_at = Vec::new();
            for &g in &gaps {
                s.add(at, g);
                if g >= LONG_NS {
                    long_at.push(at as f64 / 1e9);
                }
                at += g + 1_000;
            }
            long_at.truncate(KEPT);
            prop_assert_eq!(&s.long_at_s, &long_at);
            let long: Vec<u64> = gaps.iter().copied().filter(|&g| g >= LONG_NS).collect();
            prop_assert_eq!(s.over_100us, gaps.iter().filter(|&&g| g >= COUNTED_NS).count() as u64);
            prop_assert_eq!(s.over_1ms, long.len() as u64);
            let lost: f64 = long.iter().map(|&g| g as f64 / 1e6).sum();
            prop_assert!((s.lost_ms - lost).abs() < 1e-6);
            prop_assert_eq!(s.long_at_s.len(), long.len().min(KEPT));
            let max = gaps.iter().copied().filter(|&g| g >= COUNTED_NS).max().unwrap_or(0);
            prop_assert!((s.max_us - max as f64 / 1e3).abs() < 1e-9);
        }
    }

    #[test]
    fn a_probe_spins_as_long_as_asked_on_every_cpu() {
        // At the caller's policy: a SCHED_FIFO 99 spinner would stall the tests
        // running beside this one.
        let r = probe(0.2, false, &Arc::new(AtomicBool::new(false)));
        assert!(r.note.is_none(), "{r:?}");
        assert_eq!(
            r.cpus.len(),
            tactile_runtime::sched::allowed_cpus().expect("cpus").len()
        );
        for c in &r.cpus {
            assert!((0.2..0.5).contains(&c.spun_s), "{c:?}");
        }
        assert!(render(&r).contains("gaps >= 100 us"));
    }

    #[test]
    fn a_stop_request_ends_the_probe_at_once() {
        let started = Instant::now();
        let r = probe(30.0, false, &Arc::new(AtomicBool::new(true)));
        assert!(started.elapsed() < Duration::from_secs(2), "{r:?}");
        assert!(
            r.note.as_deref().is_some_and(|n| n.contains("stopped")),
            "{r:?}"
        );
        assert!(r.cpus.iter().all(|c| c.spun_s < 1.0), "{r:?}");
    }
}
