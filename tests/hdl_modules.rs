//! The f32 units and the paper's modules (FK, KFF, FBF, IK) as RTL against the hybrid
//! model (`tactile hdl`): bit for bit in the three formats, every stage tap included;
//! a wrong variant of each module caught; synthesized for Virtex-6; and in the loop,
//! simulated by Verilator (`arithmetic = "rtl"`), byte-identical to the model.

use crate::hdl::{cosim, have, synth_row};
use crate::util::{cannot, Sandbox};
use tactile_rtl::text::Block;

#[test]
fn the_f32_units_are_ieee_round_to_nearest_even_bit_for_bit() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    let sb = Sandbox::new("hdl-units");
    let args = [
        "--function",
        "add,sub,mul,div,sqrt",
        "--count",
        "40000",
        "--pipeline",
        "sample",
    ];
    let (ok, r, text) = cosim(&sb, &args);
    assert!(ok, "{text}");
    assert_eq!(r.len(), 5, "{text}");
    for (f, vectors, mismatches) in r {
        // The special values (29 of them, every pair for the binary ones), the ties and
        // the 40000 random operands.
        assert!(vectors > 40_000, "{f}: {vectors}");
        assert_eq!(mismatches, 0, "{f}:\n{text}");
    }
}

#[test]
fn the_modules_match_the_model_bit_for_bit_in_three_formats() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    let sb = Sandbox::new("hdl-modules");
    // One pipeline a format, each pipeline in one format: the registers do not depend
    // on the format, and every block in every pipeline at [s16.13] is the next test's.
    for (word, frac, pipelines, rows) in [
        ("16", "13", "unit", 4),
        ("24", "21", "sample", 4),
        ("32", "29", "module", 4),
    ] {
        let args = [
            "--function",
            "fk,kff,fbf,ik",
            "--count",
            "2000",
            "--word",
            word,
            "--frac",
            frac,
            "--pipeline",
            pipelines,
        ];
        let (ok, r, text) = cosim(&sb, &args);
        assert!(ok, "[s{word}.{frac}]:\n{text}");
        assert_eq!(r.len(), rows, "{text}");
        for (f, vectors, mismatches) in r {
            // The paper's validation run (1,200 samples) and the 2,000 others.
            assert!(vectors > 3_000, "{f}: {vectors}");
            assert_eq!(mismatches, 0, "{f} [s{word}.{frac}]:\n{text}");
        }
    }
}

/// Every block in every pipeline configuration gives the model's bits, and takes the
/// clocks its formula says (the testbenches measure them; `tactile hdl cosim` fails on
/// a difference): the deepest pipeline's docs/09 latencies, one f32 operation or TFB
/// function a clock, and one clock a module in the paper's architecture.
#[test]
fn every_pipeline_gives_the_same_bits_in_its_own_clocks() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    let sb = Sandbox::new("hdl-pipelines");
    let (ok, r, text) = cosim(&sb, &["--count", "600"]);
    assert!(ok, "{text}");
    assert_eq!(r.len(), 12 * 3, "{text}");
    assert!(r.iter().all(|(_, v, m)| *v > 600 && *m == 0), "{text}");
    let clocks = |f: &str, p: &str| -> Option<u32> {
        text.lines()
            .find(|l| l.starts_with(&format!("{f} ")) && l.contains(&format!("pipeline {p} ")))?
            .split("(latency ")
            .nth(1)?
            .split_whitespace()
            .next()?
            .parse()
            .ok()
    };
    for (f, sample, unit, module) in [
        ("fk", 35, 5, 1),
        ("kff", 43, 7, 1),
        ("fbf", 8, 2, 1),
        ("ik", 175, 14, 1),
        ("mul", 4, 1, 0),
        ("div", 28, 1, 0),
        ("acos", 51, 2, 0),
    ] {
        let got = ["sample", "unit", "module"].map(|p| clocks(f, p));
        assert_eq!(
            got,
            [Some(sample), Some(unit), Some(module)],
            "{f}:\n{text}"
        );
    }
}

#[test]
fn a_unit_that_truncates_is_caught() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    let sb = Sandbox::new("hdl-unit-mutant");
    // F32_MUTANT_ROUND: every unit truncates where it must round to nearest even.
    // In the deepest and the shallowest pipeline.
    for unit in ["add", "mul", "div", "sqrt"] {
        let args = [
            "--function",
            unit,
            "--count",
            "1000",
            "--define",
            "F32_MUTANT_ROUND",
            "--pipeline",
            "sample,module",
        ];
        let (ok, r, text) = cosim(&sb, &args);
        assert!(!ok, "{unit} passed truncating:\n{text}");
        assert_eq!(r.len(), 2, "{text}");
        for (_, vectors, mismatches) in r {
            assert!(
                mismatches > vectors / 10,
                "{unit}: only {mismatches} of {vectors}"
            );
        }
    }
}

#[test]
fn a_wrong_module_is_caught_by_the_same_test() {
    if !have("iverilog") {
        return cannot("iverilog is not installed");
    }
    let sb = Sandbox::new("hdl-kin-mutant");
    for module in ["fk", "kff", "fbf", "ik"] {
        let define = format!("KIN_MUTANT_{}", module.to_uppercase());
        let args = [
            "--function",
            module,
            "--count",
            "500",
            "--define",
            &define,
            "--pipeline",
            "sample,module",
        ];
        let (ok, r, text) = cosim(&sb, &args);
        assert!(!ok, "{define} passed:\n{text}");
        assert!(text.contains("outputs differ from the model"), "{text}");
        // Caught in the deepest and the shallowest pipeline.
        assert_eq!(r.len(), 2, "{text}");
        for (_, vectors, mismatches) in r {
            // Rounding-level mistakes: a few percent of the vectors at least.
            assert!(
                mismatches > vectors / 100,
                "{define}: only {mismatches} of {vectors}"
            );
        }
    }
}

#[test]
fn module_vectors_hold_the_papers_run_and_follow_the_seed() {
    let sb = Sandbox::new("hdl-kin-vectors");
    let run = |function: &str, seed: &str| {
        let o = sb.tactile(&[
            "hdl",
            "vectors",
            "--function",
            function,
            "--count",
            "100",
            "--seed",
            seed,
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).expect("utf-8")
    };
    let (a, b, c) = (run("ik", "3"), run("ik", "3"), run("ik", "4"));
    assert_eq!(a, b);
    assert_ne!(a, c);
    assert!(a.contains(
        "// fields: x y z status xs ys zs atan rr2 big_r r2 r cg gamma beta ca alpha t1 t2 t3"
    ));
    let lines: Vec<&str> = a.lines().filter(|l| !l.starts_with("//")).collect();
    // The ten edges, the paper's 1,200 samples, the stretched arm (40 directions, 6
    // radii), a 3 x 3 x 3 sweep and 50 random.
    assert_eq!(lines.len(), 10 + 1200 + 240 + 27 + 50);
    // Some stretched-arm targets are within clamp_unit's tolerance (reachable), some
    // beyond it (clamped).
    let status = |l: &&str| l.split_whitespace().nth(3).map(str::to_string);
    let stretched: Vec<String> = lines[1210..1450].iter().filter_map(status).collect();
    assert!(stretched.iter().any(|s| s == "0") && stretched.iter().any(|s| s == "1"));
    assert!(lines.iter().all(|l| l.split_whitespace().count() == 20));
    // A target at infinity is invalid (2) with zero angles.
    let inf = lines
        .iter()
        .find(|l| l.starts_with("00000000 7f800000 "))
        .expect("the inf edge");
    let zeros = [" 00000000"; 16].concat();
    assert!(inf.ends_with(&format!(" 2{zeros}")), "{inf}");
}

#[test]
fn yosys_synthesizes_fbf_with_its_multipliers_in_dsp48() {
    if !have("yosys") {
        return cannot("yosys is not installed");
    }
    let sb = Sandbox::new("hdl-kin-synth");
    let row = synth_row(&sb, "fbf");
    let n = |i: usize| row[i];
    // Three f32 multipliers: their 24 x 24 significand products in DSP48E1s.
    assert!(n(7) >= 3, "DSP48E1 {}", n(7));
    assert!(n(4) > 3 * 32, "registers {}", n(4));
    assert_eq!(n(9), 8, "latency");
    assert!(n(10) > 0, "depth");
}

/// The paper scenario in lockstep, through the RTL and through the model.
fn paper_run(sb: &Sandbox, arithmetic: &str, in_process: bool, out: &str) -> std::process::Output {
    let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/paper.toml");
    let out = sb.path(out);
    let mut args = vec![
        "run",
        scenario,
        "--set",
        "mode=lockstep",
        "--out",
        out.to_str().expect("utf-8"),
        "-q",
    ];
    let set = format!("arithmetic={arithmetic}");
    args.extend(["--set", &set]);
    if in_process {
        args.push("--in-process");
    } else {
        args.extend(["--prefix", &sb.prefix]);
    }
    sb.tactile(&args)
}

#[test]
fn the_rtl_in_the_loop_gives_the_hybrid_models_trace_byte_for_byte() {
    let sb = Sandbox::new("rtl-loop");
    if !tactile_rtl::AVAILABLE {
        let o = paper_run(&sb, "rtl", true, "rtl");
        assert_eq!(o.status.code(), Some(2));
        let why = if cfg!(feature = "rtl") {
            "apt-get install verilator"
        } else {
            "--features rtl"
        };
        assert!(String::from_utf8_lossy(&o.stderr).contains(why), "{o:?}");
        assert!(
            !sb.path("rtl").join("trace.csv").exists(),
            "nothing started"
        );
        return cannot("tactile was built without the RTL's simulation (feature rtl, Verilator)");
    }
    for (arith, in_process, out) in [
        ("hybrid", true, "hybrid"),
        ("rtl", true, "rtl"),
        ("rtl", false, "rtl-nodes"),
    ] {
        let o = paper_run(&sb, arith, in_process, out);
        assert!(
            o.status.success(),
            "{arith}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let trace = |d: &str| std::fs::read(sb.path(d).join("trace.csv")).expect("trace.csv");
    let hybrid = trace("hybrid");
    assert!(hybrid.len() > 100_000);
    assert!(
        trace("rtl") == hybrid,
        "the RTL in-process differs from the model"
    );
    // The node programs' trace has wall-clock columns (stamps, round trips): the rest
    // must be the model's.
    let untimed = |csv: &[u8]| -> Vec<Vec<String>> {
        let text = String::from_utf8_lossy(csv);
        let rows: Vec<Vec<String>> = text
            .lines()
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect();
        let keep: Vec<usize> = (0..rows[0].len())
            .filter(|&i| !(rows[0][i].ends_with("_ns") || rows[0][i].starts_with("t_")))
            .collect();
        rows.iter()
            .map(|r| keep.iter().map(|&i| r[i].clone()).collect())
            .collect()
    };
    let nodes = untimed(&trace("rtl-nodes"));
    assert!(nodes[0].len() > 70, "{:?}", nodes[0]);
    assert!(
        nodes == untimed(&hybrid),
        "the RTL in the node programs differs"
    );
    // The clocks each module took a sample, recorded by the nodes.
    let summary: serde_json::Value = serde_json::from_slice(
        &std::fs::read(sb.path("rtl-nodes").join("summary.json")).expect("summary"),
    )
    .expect("json");
    let m = &summary["hardware"]["modules"];
    let p = tactile_rtl::built_pipeline().expect("a build that simulates the RTL");
    let lat = |b| p.latency(b, 14);
    for (name, clocks, calls) in [
        ("FK-HMD", lat(Block::Fk), 1200),
        ("IK-HSD", lat(Block::Ik), 1200),
        ("FK-HSD", lat(Block::Fk), 1200),
        ("FBF-HSD", lat(Block::Fbf), 812),
    ] {
        assert_eq!(m[name]["min"], clocks, "{name}: {m}");
        assert_eq!(m[name]["max"], clocks, "{name}: {m}");
        assert_eq!(m[name]["calls"], calls, "{name}: {m}");
    }
    assert_eq!(m["KFF-HMD"]["min"], lat(Block::Kff));
    assert_eq!(summary["hardware"]["faults"], 0);
    let hybrid_summary =
        std::fs::read_to_string(sb.path("hybrid").join("summary.json")).expect("summary");
    assert!(
        !hybrid_summary.contains("\"hardware\""),
        "no hardware part without the RTL"
    );
}
