//! The trace as Parquet and the recording with zstd, read by independent readers:
//! `trace.parquet` equals `trace.csv` value for value (pyarrow and pandas,
//! tests/parquet_check.py), a zstd `run.mcap` reads with the `mcap` and `rosbags`
//! packages and equals the trace (tests/mcap_check.py), and a sweep's traces read as
//! one pandas table with the combinations' columns.

use crate::util::{self, cannot, Sandbox};
use std::process::Command;

/// True if python3 has Arrow, pandas and the MCAP readers.
fn python_ready() -> bool {
    util::python_has("pyarrow, pandas, mcap, rosbags")
}

/// Runs a checker script, asserts success and that it said `said`.
pub(crate) fn check(script: &str, args: &[&str], said: &str) -> String {
    let path = format!("{}/../tests/{script}", env!("CARGO_MANIFEST_DIR"));
    let mut c = Command::new("python3");
    c.arg(path).args(args);
    let o = util::output_within(c, util::LIMIT);
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{script}: {text}");
    assert!(text.contains(said), "{script}: {text}");
    text
}

#[test]
fn the_parquet_trace_equals_the_csv_and_a_zstd_recording_reads() {
    if !python_ready() {
        return cannot("python3 lacks pyarrow, pandas, mcap or rosbags");
    }
    let sb = Sandbox::new("formats");
    // The stiff wall through 50 ms: contact, NaN-free forces, TDPA observers, delays.
    let wall = sb.write(
        "wall.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 1500"),
    );
    let o = sb.tactile(&[
        "run",
        wall.to_str().expect("utf-8"),
        "--in-process",
        "--trace-format",
        "both",
        "--mcap-compression",
        "zstd",
        "--out",
        "both",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = sb.path("both");
    let said = check(
        "parquet_check.py",
        &[
            out.join("trace.csv").to_str().expect("utf-8"),
            out.join("trace.parquet").to_str().expect("utf-8"),
        ],
        "trace.parquet equals trace.csv: 1500 rows",
    );
    eprintln!("{said}");
    check(
        "mcap_check.py",
        &[out.to_str().expect("utf-8"), "--compression", "zstd"],
        "values equal the trace",
    );
    // Parquet alone: no CSV; a report from the same records writes the same Parquet
    // (the file follows the records, byte for byte).
    let o = sb.tactile(&[
        "report",
        "both",
        "--trace-format",
        "parquet",
        "--out",
        "again",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!sb.path("again").join("trace.csv").exists());
    let read = |d: &str| std::fs::read(sb.path(d).join("trace.parquet")).expect("parquet");
    assert!(
        read("again") == read("both"),
        "same records, same trace.parquet"
    );
    // A bad format is refused before anything runs.
    let o = sb.tactile(&["run", "--in-process", "--trace-format", "xml", "--out", "x"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("give csv, parquet or both"));
}

#[test]
fn a_sweeps_traces_read_as_one_table() {
    if !python_ready() {
        return cannot("python3 lacks pyarrow, pandas, mcap or rosbags");
    }
    let sb = Sandbox::new("formats-sweep");
    let wall = sb.write(
        "wall.toml",
        &util::wall_delay().replace("samples = 8000", "samples = 400"),
    );
    // An indexed key among the combination's columns.
    let sweep = |format: &str| {
        sb.tactile(&[
            "sweep",
            wall.to_str().expect("utf-8"),
            "--set",
            "control.kind=none,tdpa",
            "--set",
            "environment.objects[0].stiffness=[300.0,300.0,300.0],[600.0,600.0,600.0]",
            "--trace",
            "--trace-format",
            format,
            "--jobs",
            "2",
            "--out",
            "sw",
        ])
    };
    let o = sweep("parquet");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!sb.path("sw/run-0000/trace.csv").exists());
    check(
        "parquet_check.py",
        &[
            "--dataset",
            sb.path("sw/traces").to_str().expect("utf-8"),
            "--runs",
            "4",
            "--rows",
            "400",
            "--keys",
            "control.kind,environment.objects[0].stiffness",
        ],
        "the sweep's traces read as one table: 1600 rows, 4 runs",
    );
    // The same sweep again with CSV traces: the dataset keeps no stale Parquet trace.
    let o = sweep("csv");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let left = std::fs::read_dir(sb.path("sw/traces")).map_or(0, |d| d.count());
    assert_eq!(left, 0, "stale traces left in sw/traces");
    // A format that would change nothing is refused before anything runs.
    let o = sb.tactile(&[
        "sweep",
        wall.to_str().expect("utf-8"),
        "--set",
        "control.kind=none",
        "--trace-format",
        "parquet",
        "--out",
        "none",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--trace-format without --trace"));
    assert!(!sb.path("none").exists());
}
