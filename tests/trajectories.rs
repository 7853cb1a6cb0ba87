//! What the operator's hand does with a trajectory: a file shorter than the run holds
//! its last point or loops as the scenario says (and warns either way), a file with a
//! time column plays at its own speed whatever the run's rate, and every trajectory
//! starts from where the handle is, the devices' home, instead of jumping onto its
//! first point. (Bad time columns are refused in bad_input.rs, with the CSV's other
//! faults.)

use crate::util;

use util::{column, Sandbox};

/// A 1 kHz lockstep run of `samples` reading `traj.csv`, ending as `end`, with no
/// approach from home, so the targets are the file's own.
fn csv_scenario(samples: u64, end: &str) -> String {
    format!(
        "name = \"traj\"\nmode = \"lockstep\"\nrate_hz = 1000.0\nsamples = {samples}\n\
         [operator]\nkind = \"csv\"\npath = \"traj.csv\"\nend = \"{end}\"\n\
         [master.hand]\napproach_s = 0.0\n"
    )
}

/// Runs `scenario` in-process as `out`; returns stderr and the targets a(n).
fn run(sb: &Sandbox, scenario: &str, out: &str) -> (String, Vec<[f64; 3]>) {
    let s = sb.write(&format!("{out}.toml"), scenario);
    let o = sb.tactile(&[
        "run",
        s.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        out,
        "-q",
    ]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    let trace = sb.trace(out);
    let axes: Vec<Vec<f64>> = (1..=3)
        .map(|i| column(&trace, &format!("target_{i}")))
        .collect();
    let targets = (0..axes[0].len())
        .map(|n| [axes[0][n], axes[1][n], axes[2][n]])
        .collect();
    (err, targets)
}

#[test]
fn a_short_file_holds_or_loops_as_told_and_warns() {
    let sb = Sandbox::new("trajend");
    let (a, b) = ([0.01, -0.1, -0.05], [0.0, -0.1, -0.05]);
    sb.write("traj.csv", "x,y,z\n0.01,-0.1,-0.05\n0.0,-0.1,-0.05\n");
    let (err, t) = run(&sb, &csv_scenario(50, "hold"), "hold");
    assert_eq!(t.len(), 50);
    assert_eq!(t[0], a);
    assert!(
        t[1..].iter().all(|p| *p == b),
        "after the last row the target stays put"
    );
    assert!(
        err.contains("warning: operator.path:")
            && err.contains("traj.csv has 2 rows")
            && err.contains("its last row is held from sample 2 on (end = \"hold\")"),
        "{err}"
    );
    let (err, t) = run(&sb, &csv_scenario(50, "loop"), "loop");
    for (n, p) in t.iter().enumerate() {
        assert_eq!(*p, if n % 2 == 0 { a } else { b }, "sample {n}");
    }
    assert!(
        err.contains("it starts again from its first row at sample 2, every 2 samples"),
        "{err}"
    );
    // A file as long as the run says nothing.
    let (err, _) = run(&sb, &csv_scenario(2, "hold"), "exact");
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn a_timed_file_plays_at_its_own_speed() {
    // Rows every 10 ms, the run at 1 kHz: the samples between rows lie on the
    // straight line between them, and the file's 40 ms last 40 samples.
    let sb = Sandbox::new("trajtime");
    let rows: Vec<(f64, [f64; 3])> = vec![
        (0.00, [0.0, -0.1, -0.05]),
        (0.01, [0.01, -0.1, -0.05]),
        (0.02, [0.01, -0.11, -0.05]),
        (0.03, [0.01, -0.11, -0.06]),
        (0.04, [0.0, -0.1, -0.05]),
    ];
    let mut csv = String::from("t,x,y,z\n");
    for (t, p) in &rows {
        csv += &format!("{t},{},{},{}\n", p[0], p[1], p[2]);
    }
    sb.write("traj.csv", &csv);
    let (err, t) = run(&sb, &csv_scenario(100, "hold"), "timed");
    for (n, a) in t.iter().enumerate().take(41) {
        let k = (n / 10).min(3);
        let w = (n - 10 * k) as f64 / 10.0;
        let (p, q) = (rows[k].1, rows[k + 1].1);
        let want: [f64; 3] = [0, 1, 2].map(|i| p[i] + w * (q[i] - p[i]));
        let off = (0..3).map(|i| (a[i] - want[i]).abs()).fold(0.0, f64::max);
        assert!(off < 1e-12, "sample {n}: {a:?}, the line says {want:?}");
    }
    assert!(t[40..].iter().all(|p| *p == rows[4].1), "held after 40 ms");
    assert!(
        err.contains("ends at t = 0.04 s, before the run's last sample at 0.099 s")
            && err.contains("its last point is held from sample 41 on"),
        "{err}"
    );
    // Looped, the 40 ms start again at sample 40.
    let (err, l) = run(&sb, &csv_scenario(100, "loop"), "timedloop");
    assert_eq!(l[..40], t[..40]);
    for n in 40..100 {
        let d = (0..3)
            .map(|i| (l[n][i] - t[n % 40][i]).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-12, "sample {n}: {:?} against {:?}", l[n], t[n % 40]);
    }
    assert!(
        err.contains("starts again from t = 0 at sample 40"),
        "{err}"
    );
}

/// A circle 3.6 cm from home: before the approach was the ideal hand's too, the first
/// target was the circle's first point, 36.1 mm from the handle, the slave's torques
/// saturated and it fell 36 mm behind. Now the first target is home and the hand
/// takes a second to reach the circle.
#[test]
fn a_circle_away_from_home_is_reached_smoothly() {
    let sb = Sandbox::new("trajcircle");
    let text = tactile_launch::PAPER_SCENARIO
        .replace("mode = \"realtime\"", "mode = \"lockstep\"")
        .replace("rate_hz = 100.0", "rate_hz = 1000.0")
        .replace("samples = 1200", "samples = 2000")
        .replace(
            "kind = \"paper\"",
            "kind = \"circle\"\ncenter = [0.0, -0.107, -0.065]\nradius = 0.02\n\
             period_s = 2.0\nplane = \"xz\"",
        );
    let (_, t) = run(&sb, &text, "circle");
    // The paper device's home, as the trace's handle has it before anything moves.
    let home = [0.0, 0.025 - 0.132, 0.132 - 0.167];
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    assert!(dist(t[0], home) < 1e-12, "first target {:?}", t[0]);
    let step = t.windows(2).map(|w| dist(w[0], w[1])).fold(0.0, f64::max);
    // The circle alone moves 0.063 mm a sample; the blend adds at most 1.875 x
    // 36 mm / 1000 samples = 0.068 mm.
    assert!(step < 1.5e-4, "largest step {step} m");
    let s = sb.json("circle", "summary.json");
    let motion = &s["master"]["motion"];
    let max = util::num(&motion["tracking_max_m"]);
    assert!(max < 5e-3, "tracking max {max} m");
    assert_eq!(s["slave"]["counters"]["torque_clamps"], 0);
}

/// A 126 MB trajectory took 1.47 GB: its text, then a vector per row, then the
/// points. Read a line at a time into its columns, a file of 10^6 rows (29 MB) costs
/// about its points (24 MB) over a file of one row, checked as `tactile check` loads it.
#[test]
fn a_large_file_costs_about_its_values() {
    let sb = Sandbox::new("trajbig");
    let scenario = sb.write("s.toml", &csv_scenario(100, "hold"));
    let peak = |rows: usize| {
        let mut text = String::with_capacity(rows * 29 + 8);
        text.push_str("x,y,z\n");
        for n in 0..rows {
            let x = (n % 1000) as f64 * 1e-5;
            text.push_str(&format!("{x:.6},-0.100000,-0.050000\n"));
        }
        sb.write("traj.csv", &text);
        drop(text);
        let (status, kb) =
            util::run_measured(sb.command(&["check", scenario.to_str().expect("utf-8")]));
        assert!(status.success(), "{status}");
        kb
    };
    let (small, large) = (peak(1), peak(1_000_000));
    let extra_mb = large.saturating_sub(small) / 1024;
    assert!(extra_mb < 48, "10^6 rows: {extra_mb} MB over one row");
}

/// A scenario copied to another folder without its trajectory: the message said only
/// which file it could not read. It says how paths are resolved, and the fix.
#[test]
fn a_copied_scenarios_missing_input_says_how_to_copy_it() {
    let sb = Sandbox::new("trajcopy");
    sb.write("traj.csv", "x,y,z\n0,-0.1,-0.05\n");
    std::fs::create_dir_all(sb.path("elsewhere")).expect("folder");
    let copy = sb.write("elsewhere/s.toml", &csv_scenario(10, "hold"));
    let o = sb.tactile(&["check", copy.to_str().expect("utf-8")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("\"traj.csv\" is not there: it is resolved against the scenario's own folder")
            && err.contains("elsewhere/traj.csv")
            && err.contains("tactile check ORIGINAL.toml > copy.toml"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
}
