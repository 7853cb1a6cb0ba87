//! The 6-DoF sample: an operator whose trajectory gives the hand's orientation and
//! a clutch (`deploy/scenarios/panda-pose.toml`). The Panda's hand turns as the
//! operator's does within a degree, holds while the clutch is released, continues
//! from where it held when engaged again (no jump), two runs and the node programs
//! give the same bytes as the in-process run, and a 6-DoF run the rest of the
//! scenario cannot carry is refused before anything starts, naming the field.

use crate::util;

use std::path::{Path, PathBuf};
use util::{column, Sandbox};

fn scenarios() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

/// The shipped scenario's text with its files named by absolute paths.
fn pose_text() -> String {
    let dir = scenarios();
    let text = std::fs::read_to_string(dir.join("panda-pose.toml")).expect("scenario");
    text.replace(
        "\"../robots/panda.urdf\"",
        &format!("{:?}", dir.join("../robots/panda.urdf")),
    )
    .replace(
        "\"panda-pose.csv\"",
        &format!("{:?}", dir.join("panda-pose.csv")),
    )
}

/// A column of joints.csv.
fn joint_col(text: &str, name: &str) -> Vec<f64> {
    column(text, name)
}

/// `text` with the TOML `table` put before its `[slave.arm]`.
fn with_table(text: &str, table: &str) -> String {
    text.replace("[slave.arm]", &format!("{table}\n\n[slave.arm]"))
}

/// The clutch in a run's trace: over `released` the tool stays within a millimetre of
/// where it was at the release; from the engage after it to the run's end its moves
/// equal the master's (`v`) since the engage within a millimetre (the map's scale is 1).
fn held_then_followed(trace: &str, released: std::ops::RangeInclusive<usize>) {
    let tool = [1, 2, 3].map(|i| column(trace, &format!("tool_{i}")));
    let v = [1, 2, 3].map(|i| column(trace, &format!("v_{i}")));
    let moved = |of: &[Vec<f64>; 3], a: usize, b: usize| [0, 1, 2].map(|k| of[k][a] - of[k][b]);
    let norm = |d: [f64; 3]| d.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (first, engage) = (*released.start(), released.end() + 1);
    for n in released {
        let d = norm(moved(&tool, n, first));
        assert!(d < 1e-3, "sample {n}: moved {d} m while released");
    }
    for n in engage..tool[0].len() {
        let (t, m) = (moved(&tool, n, engage), moved(&v, n, engage));
        let e = norm([0, 1, 2].map(|k| t[k] - m[k]));
        assert!(
            e < 1e-3,
            "sample {n}: {e} m off the master's move since the engage"
        );
    }
}

/// Hamilton product of quaternions `[x, y, z, w]`.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let ([ax, ay, az, aw], [bx, by, bz, bw]) = (a, b);
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// Largest difference between two orientations as quaternions (either sign).
fn apart(a: [f64; 4], b: [f64; 4]) -> f64 {
    let d = |s: f64| (0..4).map(|i| (a[i] - s * b[i]).abs()).fold(0.0, f64::max);
    d(1.0).min(d(-1.0))
}

#[test]
fn the_panda_turns_with_the_operator_holds_when_released_and_continues_without_a_jump() {
    let sb = Sandbox::new("pose");
    let scenario = scenarios().join("panda-pose.toml");
    sb.simulate(&scenario, "a");
    let joints = std::fs::read_to_string(sb.path("a").join("joints.csv")).expect("joints");
    let trace = sb.trace("a");
    let err = joint_col(&joints, "rot_error_deg");
    let released = joint_col(&joints, "released");
    // Each column parsed once (per sample it parsed the whole file: 8,000 times).
    let target = ["x", "y", "z", "w"].map(|c| joint_col(&joints, &format!("target_rot_{c}")));
    let rot = |n: usize| [0, 1, 2, 3].map(|k| target[k][n]);
    assert_eq!(err.len(), 6000);
    // The file releases the clutch from t = 3 s to 4 s.
    let (r0, r1) = (
        released.iter().position(|r| *r == 1.0).expect("a release"),
        released.iter().rposition(|r| *r == 1.0).expect("a release"),
    );
    assert_eq!((r0, r1), (3000, 3999));

    // Engaged, the hand's orientation is the target's within a degree (free space),
    // and before the release the target is the operator's own (the file's row at
    // t = 2 s is sample 2000, no delay).
    for (n, e) in err.iter().enumerate() {
        assert!(*e < 1.0, "sample {n}: tool {e} degrees from its target");
    }
    let row_2s = [0.0, 0.0, 0.258819045103, 0.965925826289];
    assert!(apart(rot(2000), row_2s) < 1e-9, "{:?}", rot(2000));

    // Released, the references hold (the joints' own, within 1e-5 of the last target)
    // and the hand stays within a millimetre. Engaged again at 4 s with the hand back
    // home: the Panda continues from where it held, its hand moving as the master's
    // since then, and the operator's turn since then (20 degrees about z) turns it
    // about the base's z.
    assert!(apart(rot(r0), rot(r0 - 1)) < 1e-5);
    for n in r0..=r1 {
        assert_eq!(rot(n), rot(r0), "sample {n}");
    }
    held_then_followed(&trace, r0..=r1);
    let h = 10f64.to_radians();
    let want = mul([0.0, 0.0, h.sin(), h.cos()], rot(r0));
    assert!(apart(rot(5999), want) < 1e-6, "{:?} vs {want:?}", rot(5999));

    // No jump anywhere, the re-engage included: every reference step is inside the
    // joints' velocity limits over one period.
    let chain = tactile_chain::Chain::from_urdf(
        &std::fs::read_to_string(scenarios().join("../robots/panda.urdf")).expect("urdf"),
        "panda_link0",
        "panda_hand",
    )
    .expect("chain");
    for (i, d) in chain.dofs.iter().enumerate() {
        let q = joint_col(&joints, &format!("q_ref_{}", i + 1));
        let step = q
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        assert!(step <= d.velocity * 1e-3, "{}: step {step} rad", d.name);
    }

    // The same scenario and seed give the same bytes.
    sb.simulate(&scenario, "b");
    let again = std::fs::read_to_string(sb.path("b").join("joints.csv")).expect("joints");
    assert!(joints == again, "joints.csv differs between two runs");
    let s = sb.json("a", "summary.json");
    let c = &s["slave"]["counters"];
    assert_eq!(c["rejected"], 0, "{c}");
    assert_eq!(c["ik_clamped"], 0, "{c}");
}

/// Lockstep through the node programs (iceoryx2 between real processes): the pose
/// crosses master, emulator and slave and the arm does what the in-process run's does.
#[test]
fn the_node_programs_carry_the_pose_as_the_in_process_run_does() {
    let sb = Sandbox::new("posenodes");
    let text = with_table(
        &pose_text()
            .replace("mode = \"realtime\"", "mode = \"lockstep\"")
            .replace("samples = 6000", "samples = 800"),
        "[network.forward]\ndelay = [3, 3, 3]",
    );
    let scenario = sb.write("pose.toml", &text);
    sb.simulate(&scenario, "sim");
    sb.run(&scenario, "nodes");
    let read =
        |out: &str| std::fs::read_to_string(sb.path(out).join("joints.csv")).expect("joints");
    let (sim, nodes) = (read("sim"), read("nodes"));
    assert_eq!(sim.lines().count(), 801);
    assert!(
        sim == nodes,
        "joints.csv of the node programs differs from the in-process run's"
    );
    // The turn arrived three samples late, as the delay says.
    let z = joint_col(&nodes, "target_rot_z");
    assert!(z[3..].iter().any(|v| *v > 0.0) && z[..3].iter().all(|v| *v == 0.0));
}

#[test]
fn a_six_dof_run_the_scenario_cannot_carry_is_refused_naming_the_field() {
    let sb = Sandbox::new("posebad");
    let base = pose_text();
    let bad_row = "0.05,0.000003009,-0.107000000,-0.035000000,0.000000000000,0.000000000000,0.5,0.999999999224,1";
    let csv = std::fs::read_to_string(scenarios().join("panda-pose.csv")).expect("csv");
    let mut lines: Vec<&str> = csv.lines().collect();
    lines[2] = bad_row;
    let not_unit = sb.write("not-unit.csv", &(lines.join("\n") + "\n"));
    lines[2] = "0.05,0,-0.107,-0.035,0,0,0,1,2";
    let bad_clutch = sb.write("bad-clutch.csv", &(lines.join("\n") + "\n"));
    let arm_block = base.find("[slave.arm]").expect("arm");
    let cases: Vec<(String, &str)> = vec![
        (base[..arm_block].to_string(), "field `slave.arm`"),
        (
            with_table(&base, "[network.forward]\ndelay = [0, 5, 0]"),
            "field `network.forward.delay`",
        ),
        (
            with_table(&base, "[codec.forward]\nkind = \"deadband\""),
            "field `codec.forward.kind`",
        ),
        (
            base.replace(
                &format!("{:?}", scenarios().join("panda-pose.csv")),
                &format!("{not_unit:?}"),
            ),
            "line 3: the quaternion",
        ),
        (
            base.replace(
                &format!("{:?}", scenarios().join("panda-pose.csv")),
                &format!("{bad_clutch:?}"),
            ),
            "line 3: engaged = 2",
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        sb.assert_refused(k, text, want);
    }
}

/// Corrupted poses (the emulator's fault injection turns position and orientation to
/// NaN) are rejected and counted, never reach the IK: the hand keeps turning with
/// the operator as before.
#[test]
fn a_corrupted_pose_is_rejected_and_counted_and_the_hand_keeps_its_course() {
    let sb = Sandbox::new("posecorrupt");
    let text = with_table(
        &pose_text().replace("samples = 6000", "samples = 3000"),
        "[network.forward]\ncorrupt = 0.02",
    );
    let scenario = sb.write("corrupt.toml", &text);
    sb.simulate(&scenario, "a");
    let s = sb.json("a", "summary.json");
    let corrupted = s["emulator"]["counters"]["forward_corrupted"]
        .as_u64()
        .expect("count");
    assert!(corrupted > 20, "{corrupted} corrupted");
    let c = &s["slave"]["counters"];
    assert_eq!(c["rejected"].as_u64(), Some(corrupted), "{c}");
    assert_eq!(c["ik_clamped"], 0, "{c}");
    let joints = std::fs::read_to_string(sb.path("a").join("joints.csv")).expect("joints");
    let err = joint_col(&joints, "rot_error_deg");
    assert!(
        err.iter().all(|e| *e < 1.0),
        "{:?}",
        err.iter().copied().fold(0.0, f64::max)
    );
}

/// The clutch travels with the pose it belongs to: 200 ms late, the Panda stops where
/// the operator let go (the file's row at 3 s, arriving at 3.2 s) and starts again
/// where the operator engaged (4 s, arriving at 4.2 s), not 200 ms of motion earlier.
#[test]
fn a_late_clutch_arrives_with_its_pose() {
    let sb = Sandbox::new("poselate");
    let text = with_table(&pose_text(), "[network.forward]\ndelay = [200, 200, 200]");
    let scenario = sb.write("late.toml", &text);
    sb.simulate(&scenario, "a");
    let joints = std::fs::read_to_string(sb.path("a").join("joints.csv")).expect("joints");
    let released = joint_col(&joints, "released");
    let first = released.iter().position(|r| *r == 1.0).expect("a release");
    let last = released.iter().rposition(|r| *r == 1.0).expect("a release");
    assert_eq!((first, last), (3200, 4199));
    // Released where the operator let go: the file's orientation at 3 s.
    let row_3s = [
        0.167731259497,
        -0.044943455528,
        0.254887002244,
        0.951251242564,
    ];
    let at = ["x", "y", "z", "w"].map(|c| joint_col(&joints, &format!("target_rot_{c}"))[first]);
    assert!(apart(at, row_3s) < 1e-5, "{at:?}");
    // Held while released; engaged, it follows the master's moves since the engage.
    held_then_followed(&sb.trace("a"), first..=last);
}

/// The shipped clutch scenario (`panda-reach.toml`): three 6 cm strokes with two
/// releases between them carry the Panda's hand 27 cm along its x through the map (a
/// quarter turn between the bases, 1.5 times the motion), the robot holding while the
/// hand goes back; released, the hand feels the clutch spring, not the robot; at the
/// end the wall pushes back, scaled by a half; the plots shade the two releases.
#[test]
fn the_reach_scenario_clutches_twice_to_go_three_times_as_far() {
    let sb = Sandbox::new("reach");
    let o = reach(&sb, &[]);
    let trace = sb.trace("a");
    reach_report(
        &String::from_utf8_lossy(&o.stdout),
        &sb.json("a", "summary.json"),
        &trace,
    );
    let col = |c: &str| column(&trace, c);
    let tool = [1, 2, 3].map(|i| col(&format!("tool_{i}")));
    let handle = [1, 2, 3].map(|i| col(&format!("handle_{i}")));
    let felt = [1, 2, 3].map(|i| col(&format!("felt_{i}")));
    let joints = std::fs::read_to_string(sb.path("a").join("joints.csv")).expect("joints");
    let released = joint_col(&joints, "released");
    let changes: Vec<usize> = (1..released.len())
        .filter(|&n| released[n] != released[n - 1])
        .collect();
    assert_eq!(changes, [2200, 3400, 5100, 6300], "two releases");
    // The tool in the master's frame, back through the map: its move towards -z (away
    // from the operator) is the robot's along +x, divided by the scale.
    let end = tool[2].len() - 1;
    let reach = 1.5 * (tool[2][0] - tool[2][end]);
    assert!((reach - 0.27).abs() < 2e-3, "the hand went {reach} m");
    for (a, b) in [(2200, 3400), (5100, 6300)] {
        let drift = util::largest_move(&tool, a, b);
        assert!(
            drift * 1.5 < 2e-4,
            "moved {} mm while released",
            drift * 1.5e3
        );
        // The spring: 50 N/m towards home, within the 3.3 N limit.
        let n = (a + b) / 2;
        let home = [0.0, -0.107, -0.035];
        for k in 0..3 {
            let want = (50.0 * (home[k] - handle[k][n])).clamp(-3.3, 3.3);
            assert!(
                (felt[k][n] - want).abs() < 1e-9,
                "felt {k} {} against {want}",
                felt[k][n]
            );
        }
    }
    assert!(felt[2][end] > 2.0, "the wall at the end: {}", felt[2][end]);
    let svg = std::fs::read_to_string(sb.path("a").join("positions.svg")).expect("svg");
    assert!(
        svg.contains("clutch released"),
        "the legend names the shading"
    );
    assert_eq!(
        svg.matches("opacity=\"0.25\"").count(),
        2,
        "two shaded stretches"
    );
}

/// MMT through the reach's two re-clutches: the slave estimates the wall where the
/// robot's tool meets it and sends it where the master's handle does (less the
/// clutch's offsets, 12 cm here), so the operator feels it at the end of the third
/// stroke, at the wall's stiffness, as `none` feels it. Sent as the tool meets it, the
/// model would stand 12 cm beyond the handle's reach and nothing would be felt.
#[test]
fn mmt_renders_the_reach_scenarios_wall_where_the_handle_meets_it() {
    let sb = Sandbox::new("reachmmt");
    reach(&sb, &["--set", "control.kind=mmt"]);
    let s = sb.json("a", "summary.json");
    let t = &s["transparency"];
    for key in ["stiffness_ratio", "stiffness_ratio_converged"] {
        let r = util::num(&t[key]);
        assert!((0.9..=1.1).contains(&r), "{key}: {t}");
    }
    let m = &s["mmt"];
    assert!(m["models_taken"].as_u64().is_some_and(|n| n >= 1), "{m}");
    let felt = column(&sb.trace("a"), "felt_3");
    let end = felt.len() - 1;
    assert!(felt[end] > 2.0, "the wall at the end: {}", felt[end]);
}

/// `panda-reach.toml` run in-process into `a` with `extra` arguments; it succeeded.
fn reach(sb: &Sandbox, extra: &[&str]) -> std::process::Output {
    let scenario = scenarios().join("panda-reach.toml");
    let out = sb.path("a");
    let mut args = vec![
        "run",
        scenario.to_str().expect("utf-8"),
        "--in-process",
        "--out",
        out.to_str().expect("utf-8"),
    ];
    args.extend(extra);
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// The reach's report in the task space: the robot follows its mapped target within
/// a millimetre (docs/14: 0.705 mm rms, the wall's 1.4 mm at most; 0.07 mm held while
/// released), the two releases said, and the robot's force before `force_scale`
/// printed beside the h(n) it sent. That force is checked against the wall's own
/// figure from trace.csv (600 N/m times the tool's deepest reach past z = -0.205 m),
/// not against h(n), from which the report derives it.
fn reach_report(text: &str, s: &serde_json::Value, trace: &str) {
    let ts = &s["task_space"];
    let rms = util::num(&ts["position_rms_m"]);
    assert!((rms - 0.705e-3).abs() < 0.1e-3, "tracking rms {rms} m");
    assert!(util::num(&ts["held_max_m"]) < 0.2e-3, "{ts}");
    assert_eq!(
        (&ts["released_samples"], &ts["engages"]),
        (&2400.into(), &2.into())
    );
    let sent = util::num(&s["master"]["motion"]["force_max_n"]);
    let robot = util::num(&ts["robot_force_max_n"]);
    let deepest = column(trace, "tool_3")
        .iter()
        .fold(0.0f64, |d, z| d.max(-0.205 - z));
    let wall = 600.0 * deepest;
    assert!(
        (robot - wall).abs() < 1e-9 && robot > 5.0,
        "{robot} N at the robot, the wall's {wall} N"
    );
    let want = format!("position rms {:.3} mm", rms * 1e3);
    assert!(text.contains(&want), "{want:?} not in {text}");
    let want =
        format!("h(n) sent max {sent:.3} N (the robot's {robot:.3} N times force_scale 0.5)");
    assert!(text.contains(&want), "{want:?} not in {text}");
    assert!(
        text.contains("clutch: released 2400 samples (2.400 s), 2 engages"),
        "{text}"
    );
    // The wall felt, measured from the handle moved by the clutch's offsets.
    let ratio = util::num(&s["transparency"]["stiffness_ratio"]);
    assert!((0.9..1.0).contains(&ratio), "{}", s["transparency"]);
    assert!(
        text.contains("handle (the master's frame, the handle moved by the clutch's offsets, released samples left out)"),
        "{text}"
    );
    // One meaning for every arm: the headline is the task space's figure, and the
    // bilateral figures leave the clutch's offsets and releases out (80.5 mm and
    // 0.81 N with them).
    assert_eq!(util::num(&s["tracking_rms_m"]), rms);
    let position = util::num(&s["tracking"]["position_rms_m"]);
    assert!(position < 1e-3, "{}", s["tracking"]);
    assert_eq!(s["tracking"]["position_samples"], 6600);
    assert!(
        util::num(&s["tracking"]["force_rms_n"]) < 0.1,
        "{}",
        s["tracking"]
    );
}

/// A press, a re-clutch in contact and a hold, at 25 ms rows: 3 cm down from home in
/// 1 s (2 mm into a wall at z = -0.063 m), held; the clutch released from 1.5 s while
/// the hand goes 2 cm back up; engaged again at 2.3 s, held there to the end.
fn press_and_reclutch() -> String {
    let jerk = util::min_jerk;
    let mut text = String::from("t,x,y,z,qx,qy,qz,qw,engaged\n");
    for k in 0..=140 {
        let t = k as f64 * 0.025;
        let (z, engaged) = match t {
            t if t < 1.5 => (-0.035 - 0.03 * jerk(t), 1),
            t if t < 2.3 => (-0.065 + 0.02 * jerk((t - 1.5) / 0.6), 0),
            _ => (-0.045, 1),
        };
        text += &format!("{t:.3},0,-0.107,{z:.9},0,0,0,1,{engaged}\n");
    }
    text
}

/// MMT through a re-clutch in contact at 200 ms of round trip: the robot holds its
/// press while the hand goes 2 cm up; at the engage the master moves the wall's model
/// with the hand at once, so the operator feels the press again where it was (blended
/// in over the switch's 0.1 s), not a wall 2 cm below for the round trip until the
/// slave's re-clutched model arrives.
#[test]
fn mmt_keeps_the_wall_where_a_reclutch_in_contact_left_it() {
    let sb = Sandbox::new("mmtreclutch");
    let csv = sb.write("press.csv", &press_and_reclutch());
    let text = pose_text().replace(
        &format!("{:?}", scenarios().join("panda-pose.csv")),
        &format!("{csv:?}"),
    );
    let wall = "[[environment.objects]]\nkind = \"plane\"\npoint = [0.0, 0.0, -0.063]\nnormal = [0.0, 0.0, 1.0]\nstiffness = [600.0, 600.0, 600.0]";
    let s = sb.write("s.toml", &with_table(&text, wall));
    let sets = [
        "mode=\"lockstep\"",
        "samples=3500",
        "control.kind=mmt",
        "network.forward.delay_ms=100",
        "network.backward.delay_ms=100",
    ];
    let mut args = vec!["run", s.to_str().expect("utf-8"), "--in-process", "--out"];
    let out = sb.path("a");
    args.push(out.to_str().expect("utf-8"));
    args.extend(sets.iter().flat_map(|x| ["--set", x]));
    let o = sb.tactile(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let felt = column(&sb.trace("a"), "felt_3");
    let pressed = felt[1450];
    assert!(pressed > 0.2, "felt {pressed} N before the release");
    // The engage (2.3 s) blends the press back in over `master.switch_ramp_s` (0.1
    // s, from the released hand's zero): half of it halfway. From then on, through
    // the round trip after the engage and to the end, the press as it was.
    let half = felt[2350];
    assert!(
        (half - 0.5 * pressed).abs() < 0.25 * pressed,
        "{half} N halfway through the blend"
    );
    for (n, f) in felt.iter().enumerate().skip(2400) {
        assert!(
            (f - pressed).abs() < 0.5 * pressed,
            "sample {n}: {f} N against {pressed} N"
        );
    }
}
