//! One row of `trace.csv` per master sample: every signal of the loop and every stamp.
//!
//! Signal columns come first and timing columns last, so a comparison of two runs'
//! signals (the determinism test, lockstep against the in-process simulation) can cut
//! the timing columns off by name. Floats are written in shortest round-trip form, so
//! equal values give equal text and the file reads back exactly.

use crate::samples::{stage, Backward, Forward};
use std::fmt::Write;

/// Three-valued signal columns, in order, with their prefix.
pub const SIGNALS: [&str; 17] = [
    "target",
    "theta_md",
    "c",
    "v",
    "noise_f",
    "delay_f",
    "theta_ref",
    "theta_sd",
    "u",
    "tool",
    "surface",
    "h",
    "q",
    "noise_b",
    "delay_b",
    "tau",
    "felt",
];

/// Name of the first timing column; everything from here on is wall-clock dependent.
pub const FIRST_TIMING_COLUMN: &str = "round_trip_ns";

/// The header line (without newline).
pub fn header() -> String {
    let mut h = String::from("n,received");
    for s in SIGNALS {
        for axis in ["1", "2", "3"] {
            let _ = write!(h, ",{s}_{axis}");
        }
    }
    h.push_str(",flags_f,flags_b,flags_m,contact_object,round_trip_ns,overhead_ns");
    for name in stage::NAMES {
        let _ = write!(h, ",t_{name}");
    }
    h
}

/// What the master knows about sample n once it is done with it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TraceRow {
    /// Sample number.
    pub n: u64,
    /// The operator's target a(n), m.
    pub target: [f64; 3],
    /// Master joint angles b(n), rad.
    pub theta_md: [f64; 3],
    /// The forward sample c(n) as sent.
    pub forward: Forward,
    /// The backward sample q(n) as received, if it came.
    pub backward: Option<Backward>,
    /// KFF-HMD torques p(n), N m.
    pub tau: [f64; 3],
    /// The force the operator feels (q after the master's limits), N.
    pub felt: [f64; 3],
    /// Round trip, ns (0 if no backward sample).
    pub round_trip_ns: u64,
    /// Round trip minus injected delay, ns.
    pub overhead_ns: i64,
    /// The master's `FLAG_*` bits for this sample (held, peer lost, clamped, rejected).
    pub master_flags: u32,
}

fn push3(line: &mut String, v: [f64; 3]) {
    for x in v {
        let _ = write!(line, ",{x:?}");
    }
}

fn push3u(line: &mut String, v: [u32; 3]) {
    for x in v {
        let _ = write!(line, ",{x}");
    }
}

impl TraceRow {
    /// Appends this row as one CSV line (with newline); `t0` is subtracted from stamps.
    pub fn write_csv(&self, line: &mut String, t0: u64) {
        let b = self.backward.unwrap_or_default();
        let s = &b.slave;
        let _ = write!(line, "{},{}", self.n, u8::from(self.backward.is_some()));
        push3(line, self.target);
        push3(line, self.theta_md);
        push3(line, self.forward.signal.value);
        push3(line, s.received.value);
        push3(line, s.received.noise);
        push3u(line, s.received.delay_samples);
        push3(line, s.theta_ref);
        push3(line, s.theta);
        push3(line, s.torque);
        push3(line, s.tool);
        push3(line, s.surface);
        push3(line, s.force);
        push3(line, b.signal.value);
        push3(line, b.signal.noise);
        push3u(line, b.signal.delay_samples);
        push3(line, self.tau);
        push3(line, self.felt);
        let contact = if s.contact_object == u32::MAX || self.backward.is_none() {
            -1
        } else {
            i64::from(s.contact_object)
        };
        let _ = write!(
            line,
            ",{},{},{},{contact},{},{}",
            s.received.flags,
            b.signal.flags,
            self.master_flags,
            self.round_trip_ns,
            self.overhead_ns
        );
        for k in 0..stage::COUNT {
            let t = if self.backward.is_some() {
                b.stamps[k]
            } else {
                self.forward.stamps[k]
            };
            let _ = write!(line, ",{}", t.saturating_sub(t0));
        }
        line.push('\n');
    }
}

/// Keeps only the columns before [`FIRST_TIMING_COLUMN`] of a trace's text.
pub fn signal_columns(trace: &str) -> String {
    let Some(header) = trace.lines().next() else {
        return String::new();
    };
    let keep = header
        .split(',')
        .position(|c| c == FIRST_TIMING_COLUMN)
        .unwrap_or(usize::MAX);
    trace
        .lines()
        .map(|l| l.split(',').take(keep).collect::<Vec<_>>().join(","))
        .collect::<Vec<_>>()
        .join("\n")
}
