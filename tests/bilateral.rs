//! The bilateral loop: the operator's impedance hand, a stiff wall felt through a
//! delayed network, and the control that keeps the channel passive (TDPA, wave
//! variables). Runs are in-process (the nodes' own code, bit for bit the lockstep trio)
//! except the determinism test, which also runs the real processes.

use crate::util;

use util::{column, wall_change, wall_delay, Sandbox};

/// Runs `scenario` in-process with `sets`, returns the summary.
fn run(sb: &Sandbox, scenario: &str, out: &str, sets: &[&str]) -> serde_json::Value {
    let s = sb.write(&format!("{out}.toml"), scenario);
    let mut args = vec![
        "run",
        s.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        out,
        "-q",
    ];
    for set in sets {
        args.extend(["--set", set]);
    }
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    sb.json(out, "summary.json")
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// The thresholds, from the physics of this scenario:
/// - The hand's spring (250 N/m) pulls the handle towards a point 15 mm inside the
///   wall; at rest the contact holds about 2 N and stores 1/2 F^2 / k = 3.3 mJ in the
///   wall. A channel that made more than 50 mJ, fifteen times that, is a source of
///   energy, not rounding: "well below zero" is below -50 mJ.
/// - A contact that keeps oscillating leaves the wall on every cycle, so over the
///   last second its force swings from zero to its peak (more than the 2 N it holds
///   at rest); one that has settled swings by the datapath's quantization and the
///   controllers' small corrections. The line between: 0.5 N, a quarter of the force
///   at rest.
/// - Passive control cannot drive the tool past the point the hand pulls towards:
///   penetration stays under 15 mm (at rest it is 15 mm x 250 / (250 + 600), 4.4 mm,
///   less the slave controller's compliance).
#[test]
fn wall_delay_oscillates_without_control_and_settles_with_tdpa_and_wave() {
    let sb = Sandbox::new("walldelay");
    let text = wall_delay();
    let none = run(&sb, &text, "none", &[]);
    assert_eq!(none["control"], "none");
    assert_eq!(none["hand"], "impedance");
    let w = f(&none["passivity"]["observer_min_j"]);
    assert!(w < -0.05, "without control the channel is active: {w} J");
    let swing = f(&none["contact"]["force_swing_n"]);
    assert!(
        swing > 2.0,
        "without control the contact oscillates: {swing} N"
    );
    assert_eq!(none["packets"]["forward"], 8000);
    assert_eq!(none["packets"]["backward"], 8000);
    for kind in ["tdpa", "wave"] {
        let s = run(&sb, &text, kind, &[&format!("control.kind={kind}")]);
        assert_eq!(s["control"], kind);
        let w = f(&s["passivity"]["observer_min_j"]);
        assert!(w >= -1e-3, "{kind}: observer {w} J");
        if kind == "tdpa" {
            // TDPA's controllers act on each side's own observer; for waves only the
            // sum of the sides is bounded by the theory.
            let side = f(&s["passivity"]["side_observer_min_j"]);
            assert!(side >= -1e-3, "{kind}: a side's observer {side} J");
        }
        let swing = f(&s["contact"]["force_swing_n"]);
        assert!(swing < 0.5, "{kind}: the contact still swings {swing} N");
        let depth = f(&s["contact"]["max_penetration_m"]);
        assert!(
            depth > 1e-3 && depth < 0.015,
            "{kind}: penetration {depth} m"
        );
        assert!(
            f(&s["passivity"]["dissipated_j"]) > 0.0,
            "{kind}: nothing dissipated"
        );
        // The price: the slave's reference drifts from the master's position.
        let drift = f(&s["passivity"]["drift_max_m"]);
        assert!(drift > 1e-3, "{kind}: drift {drift} m");
    }
}

/// Transparency (summary.json's `transparency`): with no delay the operator feels the
/// wall in series with the slave's position controller, about 1.6 kN/m at the tool
/// (1 / (1/600 + 1/1600) = 436 N/m, a ratio of 0.73); 50 ms of round trip makes every
/// kind feel softer than that, and the environment's own is identified as the 600 N/m
/// the scenario gives it.
#[test]
fn the_felt_stiffness_is_the_series_spring_without_delay_and_softer_with_it() {
    let sb = Sandbox::new("transparency");
    let text = wall_delay();
    let ratio = |s: &serde_json::Value| f(&s["transparency"]["stiffness_ratio"]);
    let direct = run(
        &sb,
        &text,
        "direct",
        &[
            "network.forward.delay=[0,0,0]",
            "network.backward.delay=[0,0,0]",
        ],
    );
    let env = f(&direct["transparency"]["environment_stiffness_n_per_m"]);
    assert!((env - 600.0).abs() < 1.0, "environment {env} N/m");
    let r0 = ratio(&direct);
    assert!((0.65..0.82).contains(&r0), "no delay: ratio {r0}");
    for kind in ["none", "tdpa", "wave"] {
        let s = run(
            &sb,
            &text,
            &format!("t-{kind}"),
            &[&format!("control.kind={kind}")],
        );
        let r = ratio(&s);
        assert!(
            r > 0.05 && r < 0.8 * r0,
            "{kind}: ratio {r} against {r0} without delay"
        );
    }
}

/// Model-mediated teleoperation at 200 ms of round trip against the 600 N/m wall,
/// beside TDPA and waves (thresholds as above; the issue's own for MMT):
/// - MMT settles (the force's swing over the last second under 0.2 N), its slave
///   follows the handle's position (drift under 1 mm: it is `none`'s follower), and once
///   the model converged the operator feels the wall within 10 % of its 600 N/m, where
///   TDPA and waves, which keep the channel passive by softening it, give a quarter of
///   that or less.
/// - The model is sent a few dozen times, not every sample, and every model sent is
///   taken. With `update = "passive"` and `slave = "tdpa"` the channel's energy stays
///   above -1 mJ, and the wall is felt as TDPA feels it. Blending the late-felt wall to
///   its place adds energy at the handle, booked, at most what the wall stores at the
///   hand's 15 mm (67 mJ).
/// - The 1 s press is 14 mm into the wall when the first news of it comes back: 60 mJ
///   of wall unfelt, which no control can both render where it is and keep out of the
///   channel (docs/05). A press of 12 s enters 1.3 mm (0.5 mJ) before the news, and
///   MMT's defaults then meet all four figures: settled, drift under 1 mm, the wall
///   within 10 %, the channel above -1 mJ.
#[test]
fn mmt_feels_the_wall_at_200_ms_where_the_passive_controls_soften_it() {
    let sb = Sandbox::new("mmt200");
    let text = wall_delay();
    let delay = [
        "network.forward.delay=[100,100,100]",
        "network.backward.delay=[100,100,100]",
    ];
    let m = run(&sb, &text, "mmt", &[delay[0], delay[1], "control.kind=mmt"]);
    assert_eq!(m["control"], "mmt");
    let t = &m["transparency"];
    let swing = f(&m["contact"]["force_swing_n"]);
    assert!(swing < 0.2, "mmt: swing {swing} N");
    let drift = f(&m["passivity"]["drift_max_m"]);
    assert!(drift < 1e-3, "mmt: drift {drift} m");
    let converged = f(&t["stiffness_ratio_converged"]);
    assert!((0.9..=1.1).contains(&converged), "mmt: {t}");
    let ms = f(&t["model_convergence_ms"]);
    assert!((0.0..500.0).contains(&ms), "mmt: converged after {ms} ms");
    let counts = &m["mmt"];
    let sent = counts["models_sent"].as_u64().unwrap_or(0);
    assert!((1..100).contains(&sent), "mmt: {counts}");
    assert_eq!(counts["models_taken"], sent);
    assert_eq!(counts["models_refused"], 0);
    let injected = f(&counts["injected_j"]);
    assert!(injected > 0.0 && injected < 0.067, "mmt: {injected} J");
    let unfelt = f(&t["unfelt_energy_j"]);
    assert!((0.05..0.067).contains(&unfelt), "mmt: {t}");
    let slow = [
        delay[0],
        delay[1],
        "control.kind=mmt",
        "operator.move_s=12",
        "samples=16000",
    ];
    let s = run(&sb, &text, "slow", &slow);
    let unfelt = f(&s["transparency"]["unfelt_energy_j"]);
    assert!(unfelt < 1e-3, "slow press: {}", s["transparency"]);
    let figures = [
        f(&s["contact"]["force_swing_n"]) / 0.2,
        f(&s["passivity"]["drift_max_m"]) / 1e-3,
        (f(&s["transparency"]["stiffness_ratio_converged"]) - 1.0).abs() / 0.1,
        -f(&s["passivity"]["observer_min_j"]) / 1e-3,
    ];
    assert!(
        figures.iter().all(|x| *x < 1.0),
        "slow press, each of the four against its bound: {figures:?}"
    );
    // The strict settings keep the channel's energy above -1 mJ, at TDPA's price.
    let strict = [
        delay[0],
        delay[1],
        "control.kind=mmt",
        "control.mmt.update=passive",
        "control.mmt.slave=tdpa",
    ];
    let s = run(&sb, &text, "strict", &strict);
    let w = f(&s["passivity"]["observer_min_j"]);
    assert!(w >= -1e-3, "strict mmt: {w} J");
    assert!(f(&s["transparency"]["stiffness_ratio"]) < 0.25 * converged);
    for kind in ["tdpa", "wave"] {
        let s = run(
            &sb,
            &text,
            kind,
            &[delay[0], delay[1], &format!("control.kind={kind}")],
        );
        let ratio = f(&s["transparency"]["stiffness_ratio"]);
        assert!(ratio < 0.25 * converged, "{kind}: ratio {ratio}");
        assert!(s["mmt"].is_null() && s["transparency"]["model_convergence_ms"].is_null());
    }
}

/// `tactile sweep` over docs/05's round trips (all on the forward channel) and `sets`,
/// into `out`.
fn wall_sweep(sb: &Sandbox, out: &str, sets: &[&str]) {
    let s = sb.write("wall.toml", &wall_delay());
    let delays = "network.forward.delay=[0,0,0],[10,10,10],[50,50,50],[100,100,100],[200,200,200]";
    let mut args = vec!["sweep", s.to_str().expect("utf-8"), "--set", delays];
    for set in sets.iter().chain(&["network.backward.delay=[0,0,0]"]) {
        args.extend(["--set", set]);
    }
    args.extend(["--out", out]);
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// docs/05's wall-delay study, re-run as the docs say: its table is the committed
/// `deploy/results/wall-delay/sweep.csv` byte for byte (so the rows of the controls
/// before MMT are unchanged by it, and the docs' figures are the code's).
#[test]
fn the_wall_delay_study_gives_the_committed_table() {
    let sb = Sandbox::new("wallstudy");
    wall_sweep(&sb, "study", &["control.kind=none,tdpa,wave,mmt"]);
    let table = std::fs::read_to_string(sb.path("study").join("sweep.csv")).expect("sweep.csv");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/results/wall-delay/sweep.csv");
    let committed = std::fs::read_to_string(path).expect("the committed table");
    assert_eq!(table, committed);
}

/// MMT over a backward channel that corrupts 30 % of its packets to NaN: the master
/// refuses and counts each corrupted new model, takes it from the next whole packet
/// (every sample carries it), and the run ends with the wall felt.
#[test]
fn mmt_refuses_corrupted_models_and_takes_the_next_whole_copy() {
    let sb = Sandbox::new("mmtcorrupt");
    let sets = [
        "control.kind=mmt",
        "network.backward.corrupt=0.3",
        "samples=3000",
    ];
    let s = run(&sb, &wall_delay(), "corrupt", &sets);
    let m = &s["mmt"];
    let (sent, taken) = (m["models_sent"].as_u64(), m["models_taken"].as_u64());
    assert!(m["models_refused"].as_u64().unwrap_or(0) > 0, "{m}");
    assert!(sent.is_some() && taken == sent, "{m}");
    let converged = f(&s["transparency"]["stiffness_ratio_converged"]);
    assert!(converged > 0.8, "{}", s["transparency"]);
}

/// `wall-change.toml`: at 200 ms, the wall jumps 1 cm into the held tool at 4 s and
/// doubles its stiffness at 6 s. The operator's hand takes the force's largest step
/// from one sample to the next (`contact.felt_step_max_n`): MMT's slave refits the
/// model and its master blends it in at 50 N/s, so no step is more than a tenth of
/// the device's 3.3 N limit; the others pass the jump on as it comes, 200 ms late.
/// The same scenario and seed repeat byte for byte.
#[test]
fn a_changing_wall_does_not_kick_the_operator_with_mmt() {
    let sb = Sandbox::new("wallchange");
    let text = wall_change();
    let file = sb.write("change.toml", &text);
    for (set, needle) in [
        (
            "environment.changes[0].object=3",
            "environment.changes[0].object",
        ),
        (
            "environment.changes[1].at_s=-1",
            "environment.changes[1].at_s",
        ),
        (
            "environment.changes[0].move_by=[0,0,2]",
            "environment.changes[0].move_by",
        ),
        (
            "environment.changes[1].stiffness=[1,1,1e9]",
            "environment.changes[1].stiffness[2]",
        ),
    ] {
        sb.assert_bad_set(file.to_str().expect("utf-8"), set, needle);
    }
    let step = |s: &serde_json::Value| f(&s["contact"]["felt_step_max_n"]);
    let m = run(&sb, &text, "mmt", &[]);
    assert_eq!(m["control"], "mmt");
    let mmt = step(&m);
    assert!(mmt < 0.33, "mmt: a {mmt} N step");
    assert_eq!(m["mmt"]["models_refused"], 0);
    booked_energy_balances(&sb, "mmt");
    for kind in ["none", "tdpa", "wave"] {
        let s = run(&sb, &text, kind, &[&format!("control.kind={kind}")]);
        assert!(
            step(&s) > 3.0 * mmt,
            "{kind}: a {} N step against mmt's {mmt} N",
            step(&s)
        );
    }
    run(&sb, &text, "mmt-again", &[]);
    let signals = |d: &str| tactile_report::trace::signal_columns(&sb.trace(d));
    assert_eq!(signals("mmt"), signals("mmt-again"));
}

/// The energy MMT's model changes booked (`model_injected_m`, the last row) is what
/// the rendered force then gave the handle plus what the spring still stores at the
/// end, from the trace alone: the felt force's work on the handle (trapezoids over
/// `felt` and `handle`) and the last model's stored energy behind the 3.3 N limit
/// (per axis, the spring `k n_i` clamped and integrated over the depth). Within 5 %
/// (the sampled spring's own error); booking the unlimited spring's rises alone gave
/// 0.132 J where these add up to 0.060 J.
fn booked_energy_balances(sb: &Sandbox, out: &str) {
    let trace = sb.trace(out);
    let col = |name: &str| column(&trace, name);
    let (felt, handle) = (
        [1, 2, 3].map(|i| col(&format!("felt_{i}"))),
        [1, 2, 3].map(|i| col(&format!("handle_{i}"))),
    );
    let work: f64 = (1..felt[0].len())
        .map(|n| {
            (0..3)
                .map(|i| 0.5 * (felt[i][n] + felt[i][n - 1]) * (handle[i][n] - handle[i][n - 1]))
                .sum::<f64>()
        })
        .sum();
    let last = |name: &str| *col(name).last().expect("rows");
    let normal = [1, 2, 3].map(|i| last(&format!("model_normal_{i}")));
    let end = [0, 1, 2].map(|i| *handle[i].last().expect("rows"));
    let depth = (last("model_offset") - (0..3).map(|i| normal[i] * end[i]).sum::<f64>()).max(0.0);
    let limit = 3.3;
    let stored: f64 = normal
        .iter()
        .map(|n| {
            let a = last("model_k") * n.abs();
            let knee = limit / a;
            n.abs()
                * if depth <= knee {
                    0.5 * a * depth * depth
                } else {
                    0.5 * limit * knee + limit * (depth - knee)
                }
        })
        .sum();
    let booked = last("model_injected_m");
    assert!(
        (booked - (work + stored)).abs() <= 0.05 * booked,
        "booked {booked} J, against {work} J of work and {stored} J stored"
    );
}

/// Two 600 N/m walls at a corner (a floor, a side wall), pressed diagonally into both
/// at 100 ms each way: MMT's estimate swings between the faces, and its master turns
/// the rendered force towards each new normal by at most `force_rate` (50 mN a
/// sample) instead of switching it (steps of 0.34 N before).
#[test]
fn mmt_turns_the_force_in_a_corner_without_a_kick() {
    let sb = Sandbox::new("corner");
    let corner = wall_delay()
        .replace("to = [0.0, -0.11, -0.075]", "to = [0.02, -0.11, -0.075]")
        .replace("delay = [25, 25, 25]", "delay = [100, 100, 100]")
        + "\n[[environment.objects]]\nkind = \"plane\"\npoint = [0.01, 0.0, 0.0]\nnormal = [-1.0, 0.0, 0.0]\nstiffness = [600.0, 600.0, 600.0]\n";
    let s = run(&sb, &corner, "corner", &["control.kind=mmt"]);
    assert_eq!(s["mmt"]["models_refused"], 0);
    let step = f(&s["contact"]["felt_step_max_n"]);
    assert!(step < 0.1, "a {step} N step");
    let rows = sb.trace("corner");
    let side = column(&rows, "contact_object")
        .iter()
        .filter(|o| **o == 1.0)
        .count();
    assert!(side > 1000, "{side} steps on the side wall");
}

/// The goal the issue sets: TDPA stable at every round trip of the sweep against walls
/// up to the Omni's nominal 700 N/m (thresholds as in the test above).
#[test]
fn tdpa_is_stable_at_every_delay_against_the_omni_stiffness() {
    let sb = Sandbox::new("tdpasweep");
    wall_sweep(
        &sb,
        "sweep",
        &[
            "environment.objects[0].stiffness=[600,600,600],[700,700,700]",
            "control.kind=tdpa",
        ],
    );
    // Each run's own summary (sweep.csv quotes the bracketed values).
    for k in 0..10 {
        let s = sb.json(&format!("sweep/run-{k:04}"), "summary.json");
        assert_eq!(s["control"], "tdpa");
        let w = f(&s["passivity"]["observer_min_j"]);
        let swing = f(&s["contact"]["force_swing_n"]);
        let depth = f(&s["contact"]["max_penetration_m"]);
        assert!(w >= -1e-3, "run {k}: observer {w} J");
        assert!(swing < 0.5, "run {k}: swing {swing} N");
        assert!(depth > 1e-4, "run {k}: never pressed the wall ({depth} m)");
    }
    assert!(!sb.path("sweep/run-0010").exists());
}

/// With no delay and no control, the impedance hand on the paper's trajectory tracks
/// as well as the ideal hand: the slave follows the master's handle no worse than 10 %
/// behind the ideal hand's figure (the hand's own lag is not tracking error), and the
/// handle stays within a few millimetres of where the hand means it to be.
#[test]
fn the_impedance_hand_tracks_like_the_ideal_hand() {
    let sb = Sandbox::new("hand");
    let text = tactile_launch::PAPER_SCENARIO;
    let ideal = run(&sb, text, "ideal", &[]);
    let hand = run(&sb, text, "hand", &["master.hand.mode=impedance"]);
    assert_eq!(ideal["hand"], "position");
    let (a, b) = (
        f(&ideal["tracking"]["position_rms_m"]),
        f(&hand["tracking"]["position_rms_m"]),
    );
    assert!(a > 0.0 && b <= a * 1.1, "ideal {a} m, impedance {b} m");
    // The handle against the intended position: the hand is a spring of 250 N/m, so
    // the 1.5 N wall force moves it by 6 mm; in free motion it lags by a millimetre or
    // two. RMS over the run under 5 mm.
    let trace = sb.trace("hand");
    let mut sq = 0.0;
    let rows = column(&trace, "n").len();
    for i in 1..=3 {
        let (h, t) = (
            column(&trace, &format!("handle_{i}")),
            column(&trace, &format!("target_{i}")),
        );
        sq += h.iter().zip(&t).map(|(h, t)| (h - t).powi(2)).sum::<f64>();
    }
    let rms = (sq / rows as f64).sqrt();
    assert!(
        rms > 1e-4 && rms < 5e-3,
        "handle {rms} m from the intended position"
    );
}

/// Same scenario and seed, same trace, for every control kind; and the real processes
/// in lockstep compute what the in-process simulation computes, bit for bit.
#[test]
fn every_control_kind_repeats_and_the_processes_match_the_simulation() {
    let sb = Sandbox::new("ctldet");
    for kind in ["none", "tdpa", "wave", "mmt"] {
        let text = wall_delay()
            .replace("samples = 8000", "samples = 1500")
            .replace("kind = \"none\"", &format!("kind = \"{kind}\""));
        // Noise in both channels, so the seed matters.
        let text = text.replace(
            "delay = [25, 25, 25]\n",
            "delay = [25, 25, 25]\nnoise_std = [1e-5, 1e-5, 1e-5]\n",
        );
        let s = sb.write(&format!("{kind}.toml"), &text);
        let a = format!("{kind}-a");
        let b = format!("{kind}-b");
        sb.run(&s, &a);
        sb.run(&s, &b);
        let sim = run(&sb, &text, &format!("{kind}-sim"), &[]);
        assert_eq!(sim["control"], kind);
        let signals = |d: &str| tactile_report::trace::signal_columns(&sb.trace(d));
        assert_eq!(signals(&a), signals(&b), "{kind}: two runs differ");
        assert_eq!(
            signals(&a),
            signals(&format!("{kind}-sim")),
            "{kind}: processes and simulation differ"
        );
        // Another seed gives another trace.
        let other = run(&sb, &text, &format!("{kind}-seed"), &["seed=2"]);
        assert_eq!(other["samples_sent"], 1500);
        assert_ne!(signals(&a), signals(&format!("{kind}-seed")), "{kind}");
    }
}

/// Bad control settings are refused like any other scenario error.
#[test]
fn bad_control_settings_name_the_field() {
    let sb = Sandbox::new("ctlbad");
    let s = sb.write("wall.toml", &wall_delay());
    let s = s.to_str().expect("utf-8");
    for (set, needle) in [
        ("control.kind=passive", "unknown variant `passive`"),
        ("control.wave_impedance=0", "control.wave_impedance"),
        ("control.mmt.forgetting=1.5", "control.mmt.forgetting"),
        ("control.mmt.force_rate=0", "control.mmt.force_rate"),
        ("control.mmt.min_contacts=0", "control.mmt.min_contacts"),
        ("control.mmt.update=maybe", "unknown variant `maybe`"),
        ("control.mmt.slave=lead", "unknown variant `lead`"),
        ("control.mmt.gain=1", "unknown field `gain`"),
        ("master.hand.mass=-1", "master.hand.mass"),
        ("master.hand.mode=robot", "unknown variant `robot`"),
        ("master.device.step_s=1", "master.device.step_s"),
        ("operator.move_s=0", "operator.move_s"),
    ] {
        sb.assert_bad_set(s, set, needle);
    }
}
