//! The `tactile kernels` and `tactile paper` interfaces, as users script them.

use crate::util;

use std::io::Write;
use std::process::{Command, Output, Stdio};
use util::Sandbox;

fn kernels(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tactile"))
        .arg("kernels")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start tactile");
    // A command that fails on its arguments exits without reading stdin: a broken
    // pipe here is expected then.
    let written = child
        .stdin
        .take()
        .expect("stdin")
        .write_all(stdin.as_bytes());
    if let Err(e) = written {
        assert_eq!(e.kind(), std::io::ErrorKind::BrokenPipe, "write stdin: {e}");
    }
    util::wait_within(child, util::LIMIT)
}

fn ok_stdout(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout.clone()).expect("utf-8")
}

#[test]
fn fk_of_the_paper_waypoint_in_each_arithmetic() {
    let input = "theta1,theta2,theta3\n1.5707963267948966,0,0\n";
    let f64_out = ok_stdout(&kernels(&["fk"], input));
    assert_eq!(f64_out, "x,y,z\n-0.132,-0.10700000000000001,-0.167\n");
    for arith in ["f32", "hybrid"] {
        let out = ok_stdout(&kernels(&["fk", "--arith", arith], input));
        let row: Vec<f64> = out
            .lines()
            .nth(1)
            .expect("row")
            .split(',')
            .map(|v| v.parse().expect("num"))
            .collect();
        assert!(
            (row[0] + 0.132).abs() < 1e-3 && (row[2] + 0.167).abs() < 1e-3,
            "{arith}: {out}"
        );
    }
}

#[test]
fn outputs_read_back_to_the_same_value() {
    let input = "theta1,theta2,theta3\n0.1,0.2,0.3\n-1.2,0.9,0.05\n";
    for arith in ["f64", "f32", "hybrid"] {
        let out = ok_stdout(&kernels(&["fk", "--arith", arith], input));
        let again = ok_stdout(&kernels(&["fk", "--arith", arith], input));
        assert_eq!(out, again);
        for line in out.lines().skip(1) {
            for cell in line.split(',') {
                if arith == "f64" {
                    let v: f64 = cell.parse().expect("f64");
                    assert_eq!(format!("{v:?}"), cell);
                } else {
                    let v: f32 = cell.parse().expect("f32");
                    assert_eq!(format!("{v:?}"), cell);
                }
            }
        }
    }
}

#[test]
fn ik_flags_unreachable_rows() {
    let out = ok_stdout(&kernels(
        &["ik"],
        "x,y,z\n-0.132,-0.107,-0.167\n0,0.025,0.6\n",
    ));
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "theta1,theta2,theta3,reachable");
    assert!(lines[1].ends_with(",1"), "{out}");
    assert!(lines[2].ends_with(",0"), "{out}");
    assert!(!out.contains("NaN"));
}

#[test]
fn kff_and_fbf_columns() {
    let out = ok_stdout(&kernels(
        &["kff"],
        "theta1,theta2,theta3,fx,fy,fz\n0,0,0,0,1,0\n",
    ));
    // At rest J22 = L1 and J23 = L2 sin 0 = 0, so tau = (0, 0.132, 0).
    assert_eq!(out, "tau1,tau2,tau3\n0.0,0.132,0.0\n");
    let out = ok_stdout(&kernels(
        &["fbf", "--arith", "f32"],
        "x_obj,y_obj,z_obj,x_env,y_env,z_env,hx,hy,hz\n0,0,-0.16,0,0,-0.17,300,300,300\n",
    ));
    let fz: f32 = out
        .lines()
        .nth(1)
        .expect("row")
        .split(',')
        .nth(2)
        .expect("fz")
        .parse()
        .expect("num");
    assert!((fz - 3.0).abs() < 1e-5, "{out}");
}

#[test]
fn bad_rows_name_line_and_column_and_print_nothing() {
    let cases = [
        (
            "theta1,theta2,theta3\n0,0,0\n0,abc,0\n",
            "line 3, column 2 (theta2): \"abc\" is not a number",
        ),
        (
            "theta1,theta2,theta3\n0,0,0\n0,0\n",
            "line 3: expected 3 columns",
        ),
        (
            "theta1,theta2,theta3\n0,0,0,0\n",
            "line 2: expected 3 columns",
        ),
        (
            "theta1,theta2,theta3\nNaN,0,0\n",
            "line 2, column 1 (theta1): \"NaN\" is not a finite number",
        ),
        (
            "x,y,z\n0,0,0\n",
            "line 1: header is \"x,y,z\", expected theta1,theta2,theta3",
        ),
        ("", "empty input"),
    ];
    for (input, message) in cases {
        let o = kernels(&["fk"], input);
        assert_eq!(o.status.code(), Some(2), "{input:?}");
        assert!(o.stdout.is_empty(), "partial output for {input:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(message), "{input:?}: {err}");
        assert_eq!(err.lines().count(), 1, "one readable line: {err}");
    }
}

#[test]
fn bad_options_and_device_files_exit_2() {
    let sb = Sandbox::new("device");
    let input = "theta1,theta2,theta3\n0,0,0\n";
    let o = kernels(
        &["fk", "--arith", "hybrid", "--word", "16", "--frac", "14"],
        input,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("integer bits"));
    let o = kernels(&["fk", "--arith", "quad"], input);
    assert_eq!(o.status.code(), Some(2));
    let missing = sb.path("missing.toml");
    let o = kernels(&["fk", "--device", missing.to_str().expect("utf-8")], input);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing.toml"));
    let mm = sb.write("mm.toml", "l1 = 132\nl2 = 132\nl3 = 25\na = 35\n");
    let o = kernels(&["fk", "--device", mm.to_str().expect("utf-8")], input);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("`l1`"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let good = sb.write("d.toml", "l1 = 0.135\nl2 = 0.135\nl3 = 0.025\na = 0.035\n");
    let out = ok_stdout(&kernels(
        &["fk", "--device", good.to_str().expect("utf-8")],
        "theta1,theta2,theta3\n1.5707963267948966,0,0\n",
    ));
    assert!(out.contains("-0.135"), "{out}");
}

#[test]
fn paper_table_as_json() {
    let o = Command::new(env!("CARGO_BIN_EXE_tactile"))
        .args(["paper", "--json"])
        .output()
        .expect("run");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["samples"], 1200);
    assert_eq!(v["all_within_paper"], true);
    let rows = v["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 15);
    assert_eq!(rows[9]["module"], "IK-HSD");
    let table = Command::new(env!("CARGO_BIN_EXE_tactile"))
        .arg("paper")
        .output()
        .expect("run");
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        text.contains("FK-HMD") && text.contains("paper MSE"),
        "{text}"
    );
}

#[test]
fn a_line_without_end_an_endless_cell_and_an_overflow_are_refused_briefly() {
    // A megabyte without a newline: refused at 4096 bytes, not read into memory.
    let endless = format!("theta1,theta2,theta3\n{}", "1".repeat(1 << 20));
    let o = kernels(&["fk"], &endless);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("line 2: longer than 4096 bytes"), "{err}");
    assert!(o.stdout.is_empty());
    // A bad cell is quoted short.
    let cell = format!("theta1,theta2,theta3\n0,{},0\n", "x".repeat(3000));
    let o = kernels(&["fk"], &cell);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.len() < 200 && err.contains("xxx..."), "{err}");
    // A result past f64 is an error naming the line, never a NaN or infinity printed.
    let huge = "x_obj,y_obj,z_obj,x_env,y_env,z_env,hx,hy,hz\n0,0,0,0,0,0,1,1,1\n1e308,0,0,-1e308,0,0,10,10,10\n";
    let o = kernels(&["fbf"], huge);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("line 3") && err.contains("overflows"), "{err}");
    assert!(o.stdout.is_empty());
}

/// The long options a help text lists: the `--name` at the head of each option line
/// (`-q, --quiet`, `--out <OUT>`), before the words that describe it.
fn listed_options(help: &str) -> Vec<String> {
    help.lines()
        .flat_map(|l| {
            l.split_whitespace()
                .take_while(|w| w.starts_with(['-', '<', '[']))
                .filter(|w| w.starts_with("--") && w.len() > 2)
                .map(|w| w.trim_end_matches(',').to_string())
        })
        .collect()
}

/// Every `--name` a help text mentions, in its prose as in its option lines.
fn mentioned_options(help: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (at, _) in help.match_indices("--") {
        let before = help[..at].chars().next_back();
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '-') {
            continue;
        }
        let name: String = help[at + 2..]
            .chars()
            .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '-')
            .collect();
        if name.starts_with(|c: char| c.is_ascii_lowercase()) {
            out.push(format!("--{name}"));
        }
    }
    out
}

/// clap prints doc comments as help: no rustdoc link syntax may reach the user, and
/// no option of another program (the nodes' --udp-hosts) may be named as if it were
/// the command's own.
#[test]
fn help_texts_name_only_their_own_options_and_no_rustdoc_links() {
    for cmd in ["run", "sweep", "report", "kernels", "paper"] {
        let o = Command::new(env!("CARGO_BIN_EXE_tactile"))
            .args([cmd, "--help"])
            .output()
            .expect("run");
        assert!(o.status.success(), "tactile {cmd} --help");
        let help = String::from_utf8(o.stdout).expect("utf-8");
        for bad in ["udp-hosts", "](", "[`", "`crate::"] {
            assert!(
                !help.contains(bad),
                "tactile {cmd} --help says {bad:?}:\n{help}"
            );
        }
        let listed = listed_options(&help);
        assert!(listed.contains(&"--help".to_string()), "{listed:?}");
        for name in mentioned_options(&help) {
            assert!(
                listed.contains(&name),
                "tactile {cmd} --help names {name}, not one of its options {listed:?}:\n{help}"
            );
        }
    }
}

/// The short fuzz campaign CI runs: every decoder of outside bytes, no panic.
#[test]
fn a_short_fuzz_campaign_finds_no_panic() {
    let sb = Sandbox::new("fuzz");
    let o = sb.tactile(&["fuzz", "--seconds", "0.4", "--out", "crashes"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for t in [
        "records",
        "blocks",
        "cdr",
        "wire",
        "attachment",
        "scenario",
        "trajectory",
        "kernels",
        "urdf",
        "map",
        "trajectory6",
        "meshes",
    ] {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(t))
            .unwrap_or_else(|| panic!("{t} not fuzzed:\n{text}"));
        let cells: Vec<&str> = line.split_whitespace().collect();
        assert!(cells[1].parse::<u64>().is_ok_and(|n| n > 10), "{line}");
        assert_eq!(cells.last(), Some(&"0"), "{line}");
    }
    assert!(!sb.path("crashes").exists());
    let bad = sb.tactile(&["fuzz", "--target", "nothing"]);
    assert_eq!(bad.status.code(), Some(2));
}

/// The targets of a URDF arm, its map and a 6-DoF trajectory, a fixed number of
/// inputs from a fixed seed (the same inputs on every machine): none panics, and none
/// yields a value it should have refused (the targets check what they accept).
#[test]
fn a_fixed_fuzz_run_of_the_urdf_map_and_trajectory6_targets_finds_no_panic() {
    let sb = Sandbox::new("fuzz-arm");
    let args = ["fuzz", "--runs", "400", "--seed", "51", "--seconds", "600"];
    let targets = ["urdf", "map", "trajectory6"];
    let mut cmd: Vec<&str> = args.to_vec();
    for t in targets {
        cmd.extend(["--target", t]);
    }
    cmd.extend(["--out", "crashes"]);
    let o = sb.tactile(&cmd);
    let text = String::from_utf8_lossy(&o.stdout);
    let crashes: Vec<String> = std::fs::read_dir(sb.path("crashes"))
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "txt"))
        .map(|e| std::fs::read_to_string(e.path()).unwrap_or_default())
        .collect();
    assert!(o.status.success(), "{text}{crashes:#?}");
    for t in targets {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(t))
            .unwrap_or_else(|| panic!("{t} not fuzzed:\n{text}"));
        let cells: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(cells[1], "400", "{line}");
        assert!(
            cells[3].parse::<u64>().is_ok_and(|n| n > 3),
            "few paths: {line}"
        );
        assert_eq!(cells.last(), Some(&"0"), "{line}");
    }
}

/// Every shipped scenario (`deploy/scenarios/*.toml`, those for a real robot too) is
/// valid as shipped: `tactile check` reads it, its trajectory and its URDF, exit 0.
#[test]
fn every_shipped_scenario_checks() {
    let sb = Sandbox::new("shipped");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut checked = 0;
    for e in std::fs::read_dir(&dir).expect("scenarios") {
        let p = e.expect("entry").path();
        if p.extension().is_some_and(|x| x == "toml") {
            let o = sb.tactile(&["check", p.to_str().expect("utf-8")]);
            assert!(
                o.status.success(),
                "{}: {}",
                p.display(),
                String::from_utf8_lossy(&o.stderr)
            );
            checked += 1;
        }
    }
    assert!(checked >= 8, "{checked} scenarios");
}

/// No shipped scenario steps the operator's hand: run in-process, the felt force's
/// largest step is within what the device's force rate allows in a sample
/// (`master.ros2.max_force_rate`, 1000 N/s by default: 1 N a sample at 1 kHz). The
/// scenarios for a real robot need the node programs and the million-sample run is
/// long: the master's rendering they share is the same code.
#[test]
fn no_shipped_scenario_steps_the_operators_hand() {
    let sb = Sandbox::new("felt-steps");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut ran = 0;
    for e in std::fs::read_dir(&dir).expect("scenarios") {
        let p = e.expect("entry").path();
        let name = p
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        if p.extension().is_none_or(|x| x != "toml")
            || name.contains("ros2")
            || name.contains("1e6")
        {
            continue;
        }
        let o = sb.tactile(&[
            "run",
            p.to_str().expect("utf-8"),
            "--in-process",
            "-q",
            "--out",
            &name,
        ]);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let s = sb.json(&name, "summary.json");
        let step = s["contact"]["felt_step_max_n"].as_f64().expect("felt step");
        let rate_hz = s["rate_hz"].as_f64().expect("rate");
        assert!(
            step <= 1000.0 / rate_hz,
            "{name}: the felt force steps {step} N in a sample"
        );
        ran += 1;
    }
    assert!(ran >= 7, "{ran} scenarios");
}
