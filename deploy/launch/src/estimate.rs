//! What a run of a valid scenario takes and writes, before anything starts: its
//! length in real or simulated time, each file's size, the warnings (`tactile check`
//! says them; the Python package's `check()` returns them).

use crate::Loaded;
use tactile_scenario::shown::Num;
use tactile_scenario::Mode;

/// Bytes per sample each file takes, measured on the million-sample lockstep run
/// (`deploy/scenarios/lockstep-1e6.toml`, record format 14 as the C library's LZ4
/// writes it at acceleration 3; docs/06 and docs/10; a
/// realtime run's records differ a little, their stamps being real).
const PER_SAMPLE: [(&str, f64); 5] = [
    ("master.rec", 62.0),
    ("emulator.rec", 41.0),
    ("slave.rec", 92.0),
    ("trace.csv", 1135.0),
    ("run.mcap", 589.0),
];

/// Lockstep samples per second of the in-process trio on this project's 2-core
/// machines (the million-sample run: 72.7 s).
const LOCKSTEP_PER_S: f64 = 13_750.0;

/// Past this many bytes of output, `check` warns and names `--no-trace`.
pub const WARN_BYTES: f64 = 1e9;

/// What `tactile check` says about a valid scenario: its length, its files, its warnings
/// (the scenario's and its inputs', as `tactile run` says them and its summary
/// holds them).
pub fn report(loaded: &Loaded) -> Vec<String> {
    let s = &loaded.scenario;
    let mut v = Vec::new();
    let secs = s.samples as f64 * s.t_s();
    v.push(match s.mode {
        Mode::Realtime => format!("# runs {} samples at {} Hz: {} of real time", s.samples, Num(s.rate_hz), duration(secs)),
        Mode::Lockstep => format!(
            "# runs {} samples at {} Hz in lockstep: {} of simulated time, about {} of real time on a 2-core machine",
            s.samples,
            Num(s.rate_hz),
            duration(secs),
            duration(s.samples as f64 / LOCKSTEP_PER_S)
        ),
    });
    // Each direction's times in samples and in ms: a delay written in one unit is
    // read back in the other before anything runs.
    for (name, c) in [
        ("forward", &s.network.forward),
        ("backward", &s.network.backward),
    ] {
        v.push(format!(
            "# {}",
            tactile_scenario::units::describe(name, c, s.rate_hz)
        ));
    }
    let sizes: Vec<String> = PER_SAMPLE
        .iter()
        .map(|(f, b)| format!("{f} {}", bytes(b * s.samples as f64)))
        .collect();
    v.push(format!(
        "# writes about: {} (--no-trace: no trace.csv, no run.mcap)",
        sizes.join(", ")
    ));
    let total: f64 = PER_SAMPLE.iter().map(|(_, b)| b * s.samples as f64).sum();
    if total > WARN_BYTES {
        v.push(format!(
            "warning: the run writes about {} in all; --no-trace leaves out the trace and the recording ({} fewer)",
            bytes(total),
            bytes((PER_SAMPLE[3].1 + PER_SAMPLE[4].1) * s.samples as f64)
        ));
    }
    v.extend(loaded.warnings.iter().map(|w| format!("warning: {w}")));
    v
}

fn duration(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.1} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

fn bytes(b: f64) -> String {
    match b {
        b if b < 1e6 => format!("{:.0} kB", b / 1e3),
        b if b < 1e9 => format!("{:.1} MB", b / 1e6),
        b => format!("{:.2} GB", b / 1e9),
    }
}
