//! Bad scenario input, as users get it wrong: an unknown key, a wrong type, an absurd
//! value, a broken trajectory file or a missing file. Each must give one readable line
//! on stderr naming the file and the field (dotted path) or the line, exit status 2, no
//! panic, and start nothing: no output folder, nothing on stdout, no role process.

use crate::util;

use std::path::Path;
use std::process::Output;
use tactile_launch::PAPER_SCENARIO;
use util::Sandbox;

/// A minimal valid scenario: top-level keys only, so more keys or tables can follow.
const BASE: &str = "name = \"t\"\nmode = \"lockstep\"\nsamples = 10\n";

/// An operator reading `traj.csv` next to the scenario.
const CSV_OPERATOR: &str = "[operator]\nkind = \"csv\"\npath = \"traj.csv\"\n";

/// A wall as in the paper scenario with the given stiffness per axis.
fn wall(stiffness: &str) -> String {
    format!(
        "[[environment.objects]]\nkind = \"plane\"\npoint = [0.0, 0.0, -0.16]\n\
         normal = [0.0, 0.0, 1.0]\nstiffness = {stiffness}\n"
    )
}

fn text(o: &[u8]) -> String {
    String::from_utf8_lossy(o).into_owned()
}

/// Runs `tactile run SCENARIO --out <sandbox>/out`; returns what it printed.
fn run(sb: &Sandbox, scenario: &Path, extra: &[&str]) -> Output {
    let out = sb.path("out");
    let mut args = vec![
        "run",
        scenario.to_str().expect("utf-8 path"),
        "--out",
        out.to_str().expect("utf-8 path"),
    ];
    // A prefix names the processes' shared memory: refused with --in-process.
    if !extra.contains(&"--in-process") {
        args.extend(["--prefix", &sb.prefix, "-q"]);
    }
    args.extend_from_slice(extra);
    sb.tactile(&args)
}

/// Everything wrong with how `tactile run SCENARIO` refused (None if it refused as
/// promised): exit status 2, one line on stderr holding every expected substring, no
/// panic, nothing on stdout, no output folder, no process left.
fn refusal_problems(sb: &Sandbox, scenario: &Path, expected: &[&str]) -> Option<String> {
    let o = run(sb, scenario, &[]);
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    let mut problems = Vec::new();
    if o.status.code() != Some(2) {
        problems.push(format!("exit status {:?}, expected 2", o.status.code()));
    }
    if stderr.contains("panicked") || o.status.code() == Some(101) {
        problems.push("panicked".to_string());
    }
    let lines = stderr.trim_end().lines().count();
    if lines != 1 {
        problems.push(format!("{lines} lines on stderr, expected one"));
    }
    for e in expected {
        if !stderr.contains(e) {
            problems.push(format!("stderr does not contain {e:?}"));
        }
    }
    if !stdout.is_empty() {
        problems.push("output on stdout".to_string());
    }
    if sb.path("out").exists() {
        problems.push("the output folder was created".to_string());
    }
    if problems.is_empty() {
        return None;
    }
    Some(format!(
        "{}: {}\n--- stderr ---\n{stderr}--- stdout ---\n{stdout}",
        scenario.display(),
        problems.join("; ")
    ))
}

/// Asserts that `tactile run SCENARIO` refuses it as promised.
fn assert_refused(sb: &Sandbox, scenario: &Path, expected: &[&str]) {
    if let Some(p) = refusal_problems(sb, scenario, expected) {
        panic!("{p}");
    }
    sb.assert_no_leftover_processes();
}

/// Writes each `(file, scenario text, expected substrings)` into the sandbox, checks
/// each is refused, and reports every case that is not (rather than only the first).
fn assert_all_refused(sb: &Sandbox, cases: &[(&str, String, Vec<&str>)]) {
    let mut failures = Vec::new();
    for (file, scenario, expected) in cases {
        let path = sb.write(file, scenario);
        if let Some(p) = refusal_problems(sb, &path, expected) {
            failures.push(format!("{p}--- scenario ---\n{scenario}"));
        }
    }
    sb.assert_no_leftover_processes();
    assert!(
        failures.is_empty(),
        "{} of {} cases not refused as promised:\n\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n\n")
    );
}

/// The message names either the dotted path of the field or the line of the file.
fn field_or_line(sb: &Sandbox, file: &str, scenario: &str, field: &str, line: usize) {
    let path = sb.write(file, scenario);
    let o = run(sb, &path, &[]);
    let stderr = text(&o.stderr);
    assert!(
        stderr.contains(field) || stderr.contains(&format!("line {line}")),
        "{file}: neither the field {field:?} nor line {line} named:\n{stderr}"
    );
}

#[test]
fn the_minimal_scenario_is_valid() {
    // The refusals below differ from this only by their bad part.
    let sb = Sandbox::new("minimal");
    let path = sb.write("ok.toml", BASE);
    let o = run(&sb, &path, &["--in-process"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(sb.path("out").join("summary.json").exists());
}

#[test]
fn unknown_keys_are_named() {
    let sb = Sandbox::new("unknown");
    let top = format!("{BASE}bogus = 1\n");
    let inner = format!("{BASE}[network.forward]\ndelai = [1, 1, 1]\n");
    let deep = format!("{BASE}[slave.controller]\nkp = [6.0, 6.0, 6.0]\nkpp = 1.0\n");
    let object = PAPER_SCENARIO.replace(
        "stiffness = [300.0, 300.0, 300.0]",
        "stiffness = [300.0, 300.0, 300.0]\nfriction = 0.3",
    );
    assert_all_refused(
        &sb,
        &[
            ("top.toml", top.clone(), vec!["top.toml", "bogus"]),
            ("inner.toml", inner.clone(), vec!["inner.toml", "delai"]),
            ("deep.toml", deep.clone(), vec!["deep.toml", "kpp"]),
            ("object.toml", object, vec!["object.toml", "friction"]),
        ],
    );
    // The key alone may be ambiguous in a table: its dotted path or its line locates it.
    field_or_line(&sb, "inner.toml", &inner, "network.forward.delai", 5);
    field_or_line(&sb, "deep.toml", &deep, "slave.controller.kpp", 6);
}

#[test]
fn wrong_types_are_refused() {
    let sb = Sandbox::new("types");
    // (file, scenario, dotted path of the field, line of the bad value)
    let cases = [
        (
            "rate.toml",
            format!("{BASE}rate_hz = \"fast\"\n"),
            "rate_hz",
            4,
        ),
        (
            "samples.toml",
            BASE.replace("samples = 10", "samples = -5"),
            "samples",
            3,
        ),
        (
            "float_samples.toml",
            BASE.replace("samples = 10", "samples = 10.5"),
            "samples",
            3,
        ),
        (
            "arithmetic.toml",
            format!("{BASE}arithmetic = \"f16\"\n"),
            "arithmetic",
            4,
        ),
        (
            "delay.toml",
            format!("{BASE}[network.forward]\ndelay = [1, \"a\", 2]\n"),
            "network.forward.delay",
            5,
        ),
        (
            "short.toml",
            format!("{BASE}[network.backward]\nnoise_std = [0.1, 0.1]\n"),
            "network.backward.noise_std",
            5,
        ),
    ];
    let all: Vec<(&str, String, Vec<&str>)> = cases
        .iter()
        .map(|(f, s, _, _)| (*f, s.clone(), vec![*f]))
        .collect();
    assert_all_refused(&sb, &all);
    for (f, s, field, line) in &cases {
        field_or_line(&sb, f, s, field, *line);
    }
}

#[test]
fn negative_and_unordered_delays_are_refused() {
    let sb = Sandbox::new("delay");
    let delay = PAPER_SCENARIO.replacen("delay = [0, 0, 0]", "delay = [0, -3, 0]", 1);
    let huge = PAPER_SCENARIO.replacen("delay = [0, 0, 0]", "delay = [0, 0, 1000000]", 1);
    let in_schedule =
        format!("{BASE}[network.backward]\nschedule = [[0, 1, 1, 1], [50, 1, -2, 1]]\n");
    let unordered = format!("{BASE}[network.forward]\nschedule = [[5, 1, 1, 1], [5, 2, 2, 2]]\n");
    let negative_start = format!("{BASE}[network.forward]\nschedule = [[-1, 1, 1, 1]]\n");
    assert_all_refused(
        &sb,
        &[
            (
                "delay.toml",
                delay,
                vec!["delay.toml", "network.forward.delay[1]", "negative"],
            ),
            (
                "huge.toml",
                huge,
                vec!["huge.toml", "network.forward.delay[2]"],
            ),
            (
                "in_schedule.toml",
                in_schedule,
                vec!["in_schedule.toml", "network.backward.schedule[1][2]"],
            ),
            (
                "unordered.toml",
                unordered,
                vec![
                    "unordered.toml",
                    "network.forward.schedule[1]",
                    "increasing",
                ],
            ),
            (
                "negative_start.toml",
                negative_start,
                vec!["negative_start.toml", "network.forward.schedule[0]"],
            ),
        ],
    );
}

#[test]
fn zero_absurd_and_non_finite_rates_are_refused() {
    let sb = Sandbox::new("rate");
    let cases: Vec<(&str, String, Vec<&str>)> = [
        ("zero.toml", "rate_hz = 0.0\n"),
        ("int_zero.toml", "rate_hz = 0\n"),
        ("negative.toml", "rate_hz = -100.0\n"),
        ("absurd.toml", "rate_hz = 1e6\n"),
        ("low.toml", "rate_hz = 10.0\n"),
        ("nan.toml", "rate_hz = nan\n"),
        ("inf.toml", "rate_hz = inf\n"),
    ]
    .iter()
    .map(|(f, bad)| (*f, format!("{BASE}{bad}"), vec![*f, "rate_hz"]))
    .collect();
    assert_all_refused(&sb, &cases);
    // The paper scenario's rate, replaced.
    let absurd = PAPER_SCENARIO.replace("rate_hz = 100.0", "rate_hz = 1000000.0");
    assert_all_refused(
        &sb,
        &[(
            "paper_absurd.toml",
            absurd,
            vec!["paper_absurd.toml", "rate_hz"],
        )],
    );
}

#[test]
fn zero_and_absurd_sample_counts_are_refused() {
    let sb = Sandbox::new("samples");
    assert_all_refused(
        &sb,
        &[
            (
                "zero.toml",
                BASE.replace("samples = 10", "samples = 0"),
                vec!["zero.toml", "samples"],
            ),
            (
                "absurd.toml",
                BASE.replace("samples = 10", "samples = 1000000000000"),
                vec!["absurd.toml", "samples"],
            ),
        ],
    );
}

#[test]
fn negative_noise_and_impossible_loss_are_refused() {
    let sb = Sandbox::new("noise");
    let noise = PAPER_SCENARIO.replace(
        "[network.backward]\ndelay = [0, 0, 0]\nnoise_std = [0.0, 0.0, 0.0]",
        "[network.backward]\ndelay = [0, 0, 0]\nnoise_std = [0.0, 0.0, -0.5]",
    );
    assert_ne!(
        noise, PAPER_SCENARIO,
        "the paper scenario changed its layout"
    );
    assert_all_refused(
        &sb,
        &[
            (
                "noise.toml",
                noise,
                vec!["noise.toml", "network.backward.noise_std[2]"],
            ),
            (
                "noise_nan.toml",
                format!("{BASE}[network.forward]\nnoise_std = [nan, 0.0, 0.0]\n"),
                vec!["noise_nan.toml", "network.forward.noise_std[0]"],
            ),
            (
                "loss.toml",
                format!("{BASE}[network.forward]\nloss = 1.5\n"),
                vec!["loss.toml", "network.forward.loss"],
            ),
            (
                "loss_negative.toml",
                format!("{BASE}[network.backward]\nloss = -0.1\n"),
                vec!["loss_negative.toml", "network.backward.loss"],
            ),
        ],
    );
}

#[test]
fn stiffness_above_the_limit_is_refused() {
    let sb = Sandbox::new("stiff");
    let paper = PAPER_SCENARIO.replace(
        "stiffness = [300.0, 300.0, 300.0]",
        "stiffness = [300.0, 8000.0, 300.0]",
    );
    assert_ne!(
        paper, PAPER_SCENARIO,
        "the paper scenario changed its layout"
    );
    assert_all_refused(
        &sb,
        &[
            (
                "stiff.toml",
                paper,
                vec!["stiff.toml", "environment.objects[0].stiffness[1]"],
            ),
            (
                "second.toml",
                format!(
                    "{BASE}{}{}",
                    wall("[300.0, 300.0, 300.0]"),
                    wall("[300.0, 300.0, 1e9]")
                ),
                vec!["second.toml", "environment.objects[1].stiffness[2]"],
            ),
            (
                "negative.toml",
                format!("{BASE}{}", wall("[-1.0, 300.0, 300.0]")),
                vec!["negative.toml", "environment.objects[0].stiffness[0]"],
            ),
        ],
    );
}

#[test]
fn stiffness_above_nominal_loads_with_a_warning_and_runs() {
    let sb = Sandbox::new("warn");
    let path = sb.write(
        "buzz.toml",
        &format!("{BASE}{}", wall("[300.0, 300.0, 1500.0]")),
    );
    let o = run(&sb, &path, &["--in-process"]);
    let stderr = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(0),
        "a stiff but allowed wall must run:\n{stderr}"
    );
    assert!(
        stderr.to_lowercase().contains("warning"),
        "no warning on stderr:\n{stderr}"
    );
    assert!(
        stderr.contains("environment.objects[0].stiffness[2]"),
        "the warning does not name the field:\n{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        sb.path("out").join("summary.json").exists(),
        "it did not run"
    );
    // Stiffness within the nominal range gives no warning.
    let quiet = sb.write(
        "quiet.toml",
        &format!("{BASE}{}", wall("[300.0, 300.0, 700.0]")),
    );
    let o = run(&sb, &quiet, &["--in-process"]);
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(
        !stderr.to_lowercase().contains("warning"),
        "a warning at the nominal maximum:\n{stderr}"
    );
}

/// Writes `traj.csv` with `csv` (or none) next to a CSV-operator scenario and checks
/// the refusal names the CSV file and `expected`.
fn csv_case(name: &str, csv: Option<&str>, expected: &[&str]) -> Option<String> {
    let sb = Sandbox::new(name);
    if let Some(csv) = csv {
        sb.write("traj.csv", csv);
    }
    let scenario = sb.write("csv.toml", &format!("{BASE}{CSV_OPERATOR}"));
    let mut want = vec!["traj.csv"];
    want.extend_from_slice(expected);
    let p = refusal_problems(&sb, &scenario, &want);
    sb.assert_no_leftover_processes();
    p.map(|p| {
        format!(
            "[{name}] {p}--- traj.csv ---\n{}",
            csv.unwrap_or("(none)\n")
        )
    })
}

#[test]
fn bad_trajectory_csv_is_located() {
    let cases: [(&str, Option<&str>, &[&str]); 11] = [
        (
            "nan",
            Some("x,y,z\n0.1,0.2,-0.1\n0.1,NaN,-0.1\n"),
            &["line 3", "column 2"],
        ),
        (
            "inf",
            Some("x,y,z\n0.1,0.2,-0.1\n0.1,0.2,inf\n"),
            &["line 3", "column 3"],
        ),
        (
            "text",
            Some("x,y,z\n0.1,abc,-0.1\n"),
            &["line 2", "column 2"],
        ),
        (
            "header",
            Some("x,y\n0.1,0.2\n"),
            &["line 1", "x,y,z or t,x,y,z"],
        ),
        (
            "truncated",
            Some("x,y,z\n0.1,0.2,-0.1\n0.1,0.2,-0.1\n0.1,0.2"),
            &["line 4", "3 columns"],
        ),
        ("empty", Some("x,y,z\n"), &[]),
        // A time column that goes back, stands still, starts before 0 or is not a number.
        (
            "t-back",
            Some("t,x,y,z\n0,0.1,0.2,-0.1\n0.02,0.1,0.2,-0.1\n0.01,0.1,0.2,-0.1\n"),
            &[
                "line 4",
                "t = 0.01 s is not after the previous row's 0.02 s",
            ],
        ),
        (
            "t-still",
            Some("t,x,y,z\n0,0.1,0.2,-0.1\n\n0,0.1,0.2,-0.1\n"),
            &["line 4", "t = 0 s is not after"],
        ),
        (
            "t-negative",
            Some("t,x,y,z\n-0.5,0.1,0.2,-0.1\n"),
            &["line 2", "before 0"],
        ),
        (
            "t-nan",
            Some("t,x,y,z\nNaN,0.1,0.2,-0.1\n"),
            &["line 2", "column 1 (t)"],
        ),
        ("missing", None, &[]),
    ];
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|(name, csv, expected)| csv_case(name, *csv, expected))
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} CSV cases not refused as promised:\n\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n\n")
    );
}

#[test]
fn trajectory_path_is_relative_to_the_scenario() {
    // The scenario lives in a sub-folder and the CSV next to it is fine; the launcher
    // runs from the sandbox, so a path resolved against the cwd would not be found.
    let sb = Sandbox::new("relative");
    std::fs::create_dir(sb.path("sub")).expect("mkdir");
    sb.write("sub/traj.csv", "x,y,z\n0.1,NaN,-0.1\n");
    let scenario = sb.write("sub/csv.toml", &format!("{BASE}{CSV_OPERATOR}"));
    assert_refused(
        &sb,
        &scenario,
        &["csv.toml", "traj.csv", "line 2", "column 2"],
    );
}

#[test]
fn missing_scenario_file_is_named() {
    let sb = Sandbox::new("missing");
    assert_refused(&sb, &sb.path("nowhere.toml"), &["nowhere.toml"]);
    // Relative to the cwd, as a user types it.
    let o = sb.tactile(&["run", "gone.toml", "--out", "out", "-q"]);
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("gone.toml"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(!sb.path("out").exists());
}

#[test]
fn toml_syntax_errors_name_the_file() {
    let sb = Sandbox::new("syntax");
    assert_all_refused(
        &sb,
        &[
            (
                "unclosed.toml",
                format!("{BASE}arithmetic = \"hybrid\n"),
                vec!["unclosed.toml"],
            ),
            (
                "equals.toml",
                format!("{BASE}rate_hz = = 100\n"),
                vec!["equals.toml"],
            ),
            (
                "table.toml",
                format!("{BASE}[network.forward\ndelay = [1, 1, 1]\n"),
                vec!["table.toml"],
            ),
            (
                "duplicate.toml",
                format!("{BASE}samples = 20\n"),
                vec!["duplicate.toml"],
            ),
        ],
    );
    // The line of the syntax error, so it can be found.
    let path = sb.write("line.toml", &format!("{BASE}rate_hz = = 100\n"));
    let o = run(&sb, &path, &[]);
    assert!(text(&o.stderr).contains("line 4"), "{}", text(&o.stderr));
}

#[test]
fn bad_devices_are_refused() {
    let sb = Sandbox::new("device");
    assert_all_refused(
        &sb,
        &[
            (
                "preset.toml",
                PAPER_SCENARIO.replace("device = \"paper\"", "device = \"phantom\""),
                vec!["preset.toml", "device", "phantom"],
            ),
            (
                "negative.toml",
                format!("{BASE}device = {{ l1 = -0.132, l2 = 0.132, l3 = 0.025, a = 0.035 }}\n"),
                vec!["negative.toml", "device", "l1"],
            ),
            (
                "millimetres.toml",
                format!("{BASE}[device]\nl1 = 132.0\nl2 = 132.0\nl3 = 25.0\na = 35.0\n"),
                vec!["millimetres.toml", "device", "l1"],
            ),
            (
                "zero.toml",
                format!("{BASE}[device]\nl1 = 0.132\nl2 = 0.0\nl3 = 0.025\na = 0.035\n"),
                vec!["zero.toml", "device", "l2"],
            ),
        ],
    );
}

#[test]
fn bad_cordic_formats_are_refused() {
    let sb = Sandbox::new("cordic");
    assert_all_refused(
        &sb,
        &[
            (
                "int_bits.toml",
                PAPER_SCENARIO.replace("word = 16\nfrac = 13", "word = 16\nfrac = 14"),
                vec!["int_bits.toml", "cordic", "integer bits"],
            ),
            (
                "word.toml",
                format!("{BASE}[cordic]\nword = 128\nfrac = 13\n"),
                vec!["word.toml", "cordic", "word"],
            ),
            (
                "iterations.toml",
                format!("{BASE}[cordic]\nword = 16\nfrac = 13\niterations = 40\n"),
                vec!["iterations.toml", "cordic", "iterations"],
            ),
            (
                "rounding.toml",
                format!("{BASE}[cordic]\nrounding = \"stochastic\"\n"),
                vec!["rounding.toml", "stochastic"],
            ),
        ],
    );
}

#[test]
fn bad_operators_are_refused() {
    let sb = Sandbox::new("operator");
    assert_all_refused(
        &sb,
        &[
            (
                "kind.toml",
                format!("{BASE}[operator]\nkind = \"spiral\"\n"),
                vec!["kind.toml", "spiral"],
            ),
            (
                "radius.toml",
                format!(
                    "{BASE}[operator]\nkind = \"circle\"\ncenter = [0.0, -0.05, -0.1]\n\
                     radius = -0.02\nperiod_s = 1.0\n"
                ),
                vec!["radius.toml", "operator.radius"],
            ),
            (
                "plane.toml",
                format!(
                    "{BASE}[operator]\nkind = \"circle\"\ncenter = [0.0, -0.05, -0.1]\n\
                     radius = 0.02\nperiod_s = 1.0\nplane = \"xw\"\n"
                ),
                vec!["plane.toml", "operator.plane"],
            ),
            (
                "path.toml",
                format!("{BASE}[operator]\nkind = \"csv\"\npath = \"\"\n"),
                vec!["path.toml", "operator.path"],
            ),
        ],
    );
}

#[test]
fn every_magnitude_has_a_bound_named_in_the_error() {
    let sb = Sandbox::new("bounds");
    assert_all_refused(
        &sb,
        &[
            (
                "noise_huge.toml",
                format!("{BASE}[network.forward]\nnoise_std = [0.0, 5.0, 0.0]\n"),
                vec![
                    "noise_huge.toml",
                    "network.forward.noise_std[1]",
                    "beyond 1",
                ],
            ),
            (
                "hand_mass.toml",
                format!("{BASE}[master.hand]\nmass = 200.0\n"),
                vec!["hand_mass.toml", "master.hand.mass", "beyond 10"],
            ),
            (
                "gain.toml",
                format!("{BASE}[slave.controller]\nkp = [6.0, 6.0, 1e9]\n"),
                vec!["gain.toml", "slave.controller.kp[2]"],
            ),
            (
                "sphere.toml",
                format!(
                    "{BASE}[[environment.objects]]\nkind = \"sphere\"\ncenter = [0.0, 0.0, 5e3]\n\
                     radius = 0.01\nstiffness = [100.0, 100.0, 100.0]\n"
                ),
                vec!["sphere.toml", "environment.objects[0].center[2]"],
            ),
        ],
    );
}

/// Issue 65, 6: `check` passed what a run could not record (a scenario whose start
/// entry, the scenario as run, is longer than a record's frame): the run failed at
/// its first write, leaving an 8-byte master.rec and no summary. Both are refused
/// before anything starts, naming the field; a name is bounded on its own.
#[test]
fn a_scenario_too_large_to_record_is_refused_by_check_and_run() {
    let sb = Sandbox::new("toolarge");
    let changes = vec!["{at_s=0.05,object=0,move_by=[0,0,0]}"; 20_000].join(",");
    let large = format!(
        "{BASE}[environment]\nobjects = [{{kind = \"plane\", point = [0, 0, -0.16], normal = [0, 0, 1], stiffness = [300, 300, 300]}}]\nchanges = [{changes}]\n"
    );
    assert!(
        large.len() < 1 << 20,
        "{} bytes: a file check reads",
        large.len()
    );
    let name = format!("name = \"{}\"\nsamples = 10\n", "x".repeat(1_000_000));
    for (file, toml, field) in [
        (
            "changes.toml",
            large,
            "field `environment.changes`: the scenario is too large to record",
        ),
        (
            "name.toml",
            name,
            "field `name`: is 1000000 characters long",
        ),
    ] {
        let path = sb.write(file, &toml);
        let o = sb.tactile(&["check", path.to_str().expect("utf-8")]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{file}: {err}");
        assert!(err.contains(field) && o.stdout.is_empty(), "{file}: {err}");
        assert_refused(&sb, &path, &[file, field]);
    }
}

/// Issue 65, 5 and 12: what `check` passed and should not have, refused by `run` (exit
/// 2, one line naming the field, nothing written): environment changes that add up past
/// the bound, MMT forgetting every sample, an integer beyond i64 read as a string, and
/// type errors that named no field through `--set`.
#[test]
fn sums_forgetting_big_integers_and_type_errors_are_refused_naming_the_field() {
    let sb = Sandbox::new("issue65");
    let scenario = sb.write(
        "s.toml",
        &format!("{BASE}{}", wall("[300.0, 300.0, 300.0]")),
    );
    let s = scenario.to_str().expect("utf-8");
    let climb: Vec<String> = (0..50)
        .map(|k| {
            format!(
                "{{at_s={},object=0,move_by=[0,0,0.9]}}",
                f64::from(k) * 0.001
            )
        })
        .collect();
    let climb = format!("environment.changes=[{}]", climb.join(","));
    for (set, needle) in [
        (climb.as_str(), "field `environment.changes[11].move_by`: puts environment.objects[0].point at [0, 0, 10.64] m"),
        ("control.mmt.forgetting=1e-300", "field `control.mmt.forgetting`: 1e-300 is outside [0.95, 1]"),
        ("samples=99999999999999999999", "samples=99999999999999999999\": 99999999999999999999 is out of range"),
        ("network.forward.schedule=[[0,5]]", "field `network.forward.schedule[0]`: invalid length 2"),
        ("network.forward.delay=[1.5,1,1]", "field `network.forward.delay[0]`: invalid type: floating point `1.5`"),
        ("rate_hz=1e300", "field `rate_hz`: 1e300 Hz is outside"),
    ] {
        sb.assert_bad_set(s, set, needle);
    }
}

/// Issue 65, 12: settings that do nothing or let nothing through ran without a word.
/// They are said by `check`, by `run` on stderr, and in the run's `summary.json`.
#[test]
fn what_a_run_ignores_or_cannot_pass_is_said_by_check_run_and_the_summary() {
    let sb = Sandbox::new("warned");
    let scenario = sb.write(
        "s.toml",
        &format!("{BASE}{}", wall("[300.0, 300.0, 300.0]")),
    );
    let s = scenario.to_str().expect("utf-8");
    let sets = [
        "--set",
        "network.forward.corrupt=1.0",
        "--set",
        "control.kind=tdpa",
        "--set",
        "control.mmt.forgetting=0.99",
        "--set",
        "environment.changes=[{at_s=5.0,object=0,move_by=[0,0,0.01]}]",
    ];
    let expected = [
        "network.forward.corrupt = 1 makes every sample NaN, which the receiver refuses: no valid position reaches the slave",
        "control.mmt.forgetting is set, but only control.kind = \"mmt\" uses it, and this run has control.kind = \"tdpa\": it is ignored",
        "environment.changes[0].at_s = 5 s holds from sample 500, after the run's last (9): it never takes effect",
    ];
    let check = sb.tactile(&[&["check", s][..], &sets].concat());
    let run = sb.tactile(&[&["run", s, "--in-process", "-q", "--out", "w"][..], &sets].concat());
    assert!(run.status.success(), "{}", text(&run.stderr));
    let summary = sb.json("w", "summary.json");
    let warnings: Vec<&str> = summary["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .filter_map(|w| w.as_str())
        .collect();
    for w in expected {
        assert!(
            text(&check.stderr).contains(&format!("warning: {w}")),
            "check: {}",
            text(&check.stderr)
        );
        assert!(
            text(&run.stderr).contains(&format!("warning: {w}")),
            "run: {}",
            text(&run.stderr)
        );
        assert!(warnings.contains(&w), "summary: {warnings:#?}");
    }
    // A report made later from the records says the scenario's warnings too.
    let again = sb.tactile(&["report", "w", "--out", "again", "--no-trace"]);
    assert!(again.status.success(), "{}", text(&again.stderr));
    assert_eq!(
        sb.json("again", "summary.json")["warnings"],
        summary["warnings"]
    );
}

#[test]
fn delays_and_schedules_past_the_run_load_with_a_warning() {
    let sb = Sandbox::new("pastrun");
    let late =
        format!("{BASE}[network.forward]\ndelay = [2000, 0, 0]\nschedule = [[5000, 1, 1, 1]]\n");
    let scenario = sb.write("late.toml", &late);
    let o = sb.tactile(&[
        "run",
        scenario.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        "late",
    ]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("network.forward.delay[0] = 2000 samples"),
        "{err}"
    );
    assert!(
        err.contains("network.forward.schedule[0] starts at sample 5000"),
        "{err}"
    );
}

#[test]
fn an_out_that_is_a_file_a_key_swept_twice_and_options_that_do_nothing_are_refused() {
    let sb = Sandbox::new("argsbad");
    let scenario = sb.write("s.toml", BASE);
    sb.write("afile", "not a folder");
    let s = scenario.to_str().expect("utf-8");
    let cases: [(&[&str], &str); 5] = [
        (
            &["run", s, "--in-process", "--out", "afile"],
            "is a file, not a folder",
        ),
        (
            &["sweep", s, "--set", "seed=1,2", "--out", "afile"],
            "is a file, not a folder",
        ),
        (
            &[
                "sweep", s, "--set", "seed=1,2", "--set", "seed=3", "--out", "sw",
            ],
            "swept twice",
        ),
        (
            &["run", s, "--in-process", "--prefix", "abc"],
            "cannot be used with",
        ),
        (
            &["run", s, "--in-process", "--link", "udp"],
            "cannot be used with",
        ),
    ];
    for (args, needle) in cases {
        let o = sb.tactile(args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(!sb.path("sw").exists(), "a refused sweep writes nothing");
    assert_eq!(
        std::fs::read_to_string(sb.path("afile")).ok().as_deref(),
        Some("not a folder")
    );
}

/// Issue 65, 9: `tactile run --out /` wrote twelve files into `/`, and a `--no-trace`
/// run removed a `trace.csv` already in its folder. A folder that holds anything but
/// an earlier output of ours is refused by every command that writes one (exit 2,
/// nothing touched); our own earlier run is still overwritten.
#[test]
fn an_output_folder_of_other_files_is_refused_and_our_own_is_overwritten() {
    let sb = Sandbox::new("outguard");
    let scenario = sb.write("s.toml", BASE);
    let s = scenario.to_str().expect("utf-8");
    for d in ["theirs", "sweep/run-0001"] {
        std::fs::create_dir_all(sb.path(d)).expect("folder");
    }
    sb.write("theirs/trace.csv", "their trace");
    // A sweep's folder of ours, one of its run folders not.
    sb.write(
        "sweep/sweep.json",
        "{\"scenario_hash\": \"0\", \"combinations\": 2}",
    );
    sb.write("sweep/run-0001/notes.txt", "their notes");
    let ran = sb.tactile(&["run", s, "--in-process", "-q", "--out", "ours"]);
    assert!(ran.status.success(), "{}", text(&ran.stderr));
    let theirs = sb.path("theirs");
    let t = theirs.to_str().expect("utf-8");
    let cases: [&[&str]; 4] = [
        &["run", s, "--in-process", "--no-trace", "--out", t],
        &["sweep", s, "--set", "seed=1,2", "--out", t],
        &["sweep", s, "--set", "seed=1,2", "--out", "sweep"],
        &["report", "ours", "--out", t],
    ];
    for args in cases {
        let o = sb.tactile(args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("and no earlier output of tactile's"),
            "{args:?}: {err}"
        );
        assert!(
            err.contains("theirs") || err.contains("run-0001"),
            "{args:?}: {err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    }
    let left: Vec<_> = std::fs::read_dir(&theirs)
        .expect("theirs")
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(left, ["trace.csv"], "nothing written into their folder");
    assert_eq!(
        std::fs::read_to_string(theirs.join("trace.csv"))
            .ok()
            .as_deref(),
        Some("their trace")
    );
    assert!(
        !sb.path("sweep/run-0000").exists(),
        "a refused sweep runs nothing"
    );
    let again = sb.tactile(&[
        "run",
        s,
        "--in-process",
        "-q",
        "--no-trace",
        "--out",
        "ours",
    ]);
    assert!(again.status.success(), "{}", text(&again.stderr));
    assert!(
        !sb.path("ours/trace.csv").exists(),
        "our own earlier trace replaced"
    );
}

/// The shipped UR5 over ROS 2, its URDF by absolute path, with `extra` put into its
/// `[slave.ros2]`.
fn ur5_over_ros2(extra: &str) -> String {
    let root = env!("CARGO_MANIFEST_DIR");
    let text =
        std::fs::read_to_string(format!("{root}/scenarios/ur5-ros2.toml")).expect("ur5-ros2");
    text.replace("../robots/", &format!("{root}/robots/"))
        .replacen("[slave.ros2]\n", &format!("[slave.ros2]\n{extra}\n"), 1)
}

/// A 6-joint robot over ROS 2 is configured by its `[slave.arm]` alone (issue 52): the
/// shipped UR5 checks, and the scenario `check` prints holds none of the paper arm's
/// three-element keys (it printed `joints = ["joint1", "joint2", "joint3"]`, a
/// three-joint `max_velocity` and maps for the six-joint arm) and checks again as
/// printed.
#[test]
fn a_six_joint_robot_over_ros2_checks_with_its_urdf_alone() {
    let sb = Sandbox::new("ur5-ros2-check");
    let path = sb.write("ur5.toml", &ur5_over_ros2(""));
    let o = sb.tactile(&["check", path.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let printed = text(&o.stdout);
    let table: toml::Table = printed.parse().expect("check prints TOML");
    let ros2 = &table["slave"]["ros2"];
    assert_eq!(ros2["command"].as_str(), Some("trajectory"), "{ros2}");
    for key in ["joints", "map", "max_velocity", "wrench_map"] {
        assert!(ros2.get(key).is_none(), "`{key}` printed:\n{ros2}");
    }
    let again = sb.write("printed.toml", &printed);
    let o = sb.tactile(&["check", again.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// Beside `[slave.arm]` each of the paper arm's three-element keys is refused by its
/// name, even at its default value (which passed before issue 52) or with the arm's
/// six joint names (told it takes three before), with what to write instead: exit 2,
/// nothing started.
#[test]
fn the_paper_arms_ros2_keys_beside_an_arm_are_refused_with_what_to_write() {
    let sb = Sandbox::new("ur5-ros2-old-keys");
    let written = [
        "joints = [\"joint1\", \"joint2\", \"joint3\"]",
        "max_velocity = [2.0, 2.0, 2.0]",
        "map = { unit = \"rad\" }",
        "wrench_map = { axes = [0, 1, 2] }",
        // The UR5's own six names: not "it takes 3".
        "joints = [\"shoulder_pan_joint\", \"shoulder_lift_joint\", \"elbow_joint\", \
         \"wrist_1_joint\", \"wrist_2_joint\", \"wrist_3_joint\"]",
    ];
    let wants: Vec<String> = written
        .iter()
        .map(|d| {
            let key = d.split(' ').next().unwrap_or_default();
            format!("field `slave.ros2.{key}`: is for the paper's 3-DoF arm only; with [slave.arm]")
        })
        .collect();
    let cases: Vec<(&str, String, Vec<&str>)> = written
        .iter()
        .zip(&wants)
        .map(|(d, want)| {
            (
                "old-key.toml",
                ur5_over_ros2(d),
                vec![want.as_str(), "delete"],
            )
        })
        .collect();
    assert_all_refused(&sb, &cases);
}
