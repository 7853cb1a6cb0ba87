//! One row of `trace.csv` per master sample: every signal of the loop and every stamp.
//!
//! Signal columns come first and timing columns last, so a comparison of two runs'
//! signals (the determinism test, lockstep against the in-process simulation) can cut
//! the timing columns off by name. Floats are written in shortest round-trip form, so
//! equal values give equal text and the file reads back exactly.

use std::fmt::Write;
use tactile_messages::samples::stage;

/// Three-valued signal columns, in order, with their prefix.
pub const SIGNALS: [&str; 23] = [
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
    "handle",
    "hand_force",
    "reference",
    "observer_m",
    "observer_s",
    "q_from",
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
    h.push_str(",flags_f,flags_b,flags_m,contact_object,dissipated_m,dissipated_s");
    h.push_str(",port_net_m,port_net_s");
    h.push_str(",round_trip_ns,overhead_ns");
    for name in stage::NAMES {
        let _ = write!(h, ",t_{name}");
    }
    h
}

/// Sample n as the report joins it from the nodes' records: the master's part (target,
/// encoders, c, q, torques, round trip), the emulator's (noise injected) and the
/// slave's (what it received and did). A part whose node recorded nothing for n stays
/// zero, and `received` says whether the answer came back.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TraceRow {
    /// Sample number.
    pub n: u64,
    /// True if q(n) came back to the master.
    pub received: bool,
    /// The operator's target a(n), m.
    pub target: [f64; 3],
    /// Master joint angles b(n), rad.
    pub theta_md: [f64; 3],
    /// c(n) as sent, m.
    pub c: [f64; 3],
    /// v(n) as the slave received it, m.
    pub v: [f64; 3],
    /// Noise the emulator added to v(n).
    pub noise_f: [f64; 3],
    /// Delay injected into v(n), samples.
    pub delay_f: [u32; 3],
    /// IK-HSD reference angles, rad.
    pub theta_ref: [f64; 3],
    /// Slave joint angles after the step, rad.
    pub theta_sd: [f64; 3],
    /// Slave controller torques, N m.
    pub u: [f64; 3],
    /// FK-HSD tool position l(n), m.
    pub tool: [f64; 3],
    /// Nearest surface point, m (zero without contact).
    pub surface: [f64; 3],
    /// h(n), N.
    pub h: [f64; 3],
    /// q(n) as the master received it, N.
    pub q: [f64; 3],
    /// Noise the emulator added to q(n).
    pub noise_b: [f64; 3],
    /// Delay injected into q(n), samples.
    pub delay_b: [u32; 3],
    /// KFF-HMD torques p(n), N m.
    pub tau: [f64; 3],
    /// The force the operator feels, N.
    pub felt: [f64; 3],
    /// The handle's true position, m.
    pub handle: [f64; 3],
    /// The impedance hand's force on the handle, N.
    pub hand_force: [f64; 3],
    /// The slave's Cartesian reference from the channel's control, m.
    pub reference: [f64; 3],
    /// The master's passivity observer per axis, J.
    pub observer_m: [f64; 3],
    /// The slave's passivity observer per axis, J.
    pub observer_s: [f64; 3],
    /// The slave step each value of q(n) was produced at.
    pub q_from: [u64; 3],
    /// Energy the master's control dissipated this sample, J.
    pub dissipated_m: f64,
    /// The master port's net energy into the channel so far, J.
    pub port_net_m: f64,
    /// The slave port's net energy into the channel so far, J.
    pub port_net_s: f64,
    /// Energy the slave's control dissipated this step, J.
    pub dissipated_s: f64,
    /// Flags of v(n) as received.
    pub flags_f: u32,
    /// Flags of q(n) as received.
    pub flags_b: u32,
    /// The master's flags for this sample (held, peer lost, clamped, rejected).
    pub flags_m: u32,
    /// Object in contact, or -1.
    pub contact_object: i64,
    /// Round trip, ns (0 if no answer).
    pub round_trip_ns: u64,
    /// Round trip minus injected delay, ns.
    pub overhead_ns: i64,
    /// Stamps per stage, ns (zero where not passed).
    pub stamps: [u64; stage::COUNT],
    /// True if the slave recorded a step on v(n) (not a trace column: it says whether
    /// the slave's columns hold data).
    pub stepped: bool,
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
        let _ = write!(line, "{},{}", self.n, u8::from(self.received));
        for v in [self.target, self.theta_md, self.c, self.v, self.noise_f] {
            push3(line, v);
        }
        push3u(line, self.delay_f);
        for v in [
            self.theta_ref,
            self.theta_sd,
            self.u,
            self.tool,
            self.surface,
            self.h,
            self.q,
            self.noise_b,
        ] {
            push3(line, v);
        }
        push3u(line, self.delay_b);
        for v in [
            self.tau,
            self.felt,
            self.handle,
            self.hand_force,
            self.reference,
            self.observer_m,
            self.observer_s,
        ] {
            push3(line, v);
        }
        for x in self.q_from {
            let _ = write!(line, ",{x}");
        }
        let _ = write!(
            line,
            ",{},{},{},{},{:?},{:?},{:?},{:?},{},{}",
            self.flags_f,
            self.flags_b,
            self.flags_m,
            self.contact_object,
            self.dissipated_m,
            self.dissipated_s,
            self.port_net_m,
            self.port_net_s,
            self.round_trip_ns,
            self.overhead_ns
        );
        for t in self.stamps {
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
