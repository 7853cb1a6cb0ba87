//! A 6-DoF master over ROS 2 against stand-ins of real drivers (tests/hand_standin.py,
//! eclipse-zenoh and rosbags): a Geomagic Touch as the omni_common drivers publish it
//! (six joints, the grey button as `OmniButtonEvent` on change, the force taken as
//! `OmniFeedback`) driving a Panda simulated by MuJoCo behind a joint trajectory
//! controller (tests/mujoco_arm.py); and a Force Dimension device as ICube's driver
//! publishes it (`PoseStamped`, a `Bool` clutch, the force as an effort controller's
//! `Float64MultiArray`) driving the simulated Panda. Through the map of docs/14: a
//! rotation between the bases, a position scale, the clutch's offsets, the force
//! scaled and turned back.
#![cfg(feature = "zenoh")]

use crate::ros2::{
    any_arm_standin, floats, listening, mujoco_ready, one_at_a_time, python_ready, report,
    MUJOCO_PANDA, PANDA_JOINTS, PANDA_READY,
};
use crate::util::{self, cannot, free_port, num, Sandbox};
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use std::process::Child;

fn hand_standin(sb: &Sandbox, args: &[&str]) -> Child {
    crate::ros2::python_in(sb, "hand_standin.py", args)
}

/// Minimum-jerk keyframes `(t, values)` sampled every 10 ms, each row `t, values...`;
/// `hold(t)` gives the last column (a button, a clutch) at `t`.
fn keyframes(keys: &[(f64, Vec<f64>)], hold: impl Fn(f64) -> f64, end: f64) -> String {
    let mut out = String::new();
    let mut k = 0;
    let mut t = 0.0;
    while t <= end + 1e-9 {
        while k + 1 < keys.len() && keys[k + 1].0 <= t {
            k += 1;
        }
        let (t0, a) = &keys[k];
        let v: Vec<f64> = match keys.get(k + 1) {
            Some((t1, b)) => {
                let s = util::min_jerk((t - t0) / (t1 - t0));
                a.iter().zip(b).map(|(x, y)| x + s * (y - x)).collect()
            }
            None => a.clone(),
        };
        let cells: Vec<String> = v.iter().map(|x| format!("{x:.9}")).collect();
        out.push_str(&format!("{t:.3},{},{}\n", cells.join(","), hold(t)));
        t += 0.01;
    }
    out
}

/// `[x, y, z, w]` to a rotation matrix.
fn rot(q: &[f64]) -> Matrix3<f64> {
    *UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]))
        .to_rotation_matrix()
        .matrix()
}

/// The angle between two rotations, degrees.
fn angle_deg(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let c = ((a.transpose() * b).trace() - 1.0) / 2.0;
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

/// `[90, 0, -90]` degrees of roll, pitch and yaw: the master's right is the robot's
/// -y, its up the robot's z, towards the operator the robot's -x.
fn touch_to_panda() -> Matrix3<f64> {
    Matrix3::new(0.0, 0.0, -1.0, -1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
}

/// The clutch's engaged stretches of a run, `(first, last)` samples, from joints.csv's
/// `released` column.
fn engaged_stretches(released: &[f64]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (n, r) in released.iter().enumerate() {
        match (start, *r == 0.0) {
            (None, true) => start = Some(n),
            (Some(s), false) => {
                out.push((s, n - 1));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, released.len() - 1));
    }
    out
}

/// The most samples the robot may follow the master's path late while it moves, in
/// the checks: 0.2 s at 1 kHz. The stand-ins simulate in real time in Python, and a
/// suite that loads both cores starves them by more than the 50 samples this was
/// (a 1.56 mm median with 50); a map that is wrong is caught where the hand has
/// stopped (see [`following`]'s `settled`), with no window at all.
const LAG: usize = 200;

/// How long the hand must have been still at a stretch's end for its `settled` error:
/// 0.1 s at 1 kHz (the shortest still spell of the tests' trajectories is 0.2 s).
const STILL: usize = 100;

/// How the robot followed the master's mapped motion: see [`following`].
struct Following {
    moves: Vec<f64>,
    turns: Vec<f64>,
    settled: Vec<f64>,
}

/// Over each engaged stretch (from 50 samples after the engage, free space only: no
/// force back), how far the robot's tool moved from where the map says: its move
/// since the engage against `S R` times the master's (m, the robot's frame), and its
/// turn against the master's turn carried by the map (degrees), each against the
/// nearest of the master's last [`LAG`] samples (`moves`, `turns`, sorted); and
/// `settled`, the move's error with no window at all, at the end of each stretch the
/// hand ended still (unmoved for [`STILL`] samples) out of contact. A window forgives
/// a late robot, and also a short scale along a straight stroke; the settled error
/// forgives neither.
fn following(trace: &str, joints: &str, scale: f64, r: &Matrix3<f64>) -> Following {
    let col = |c: &str| util::column(trace, c);
    let v = [1, 2, 3].map(|i| col(&format!("v_{i}")));
    let h = [1, 2, 3].map(|i| col(&format!("h_{i}")));
    let jc = |c: &str| util::column(joints, c);
    let master_rot = ["x", "y", "z", "w"].map(|c| jc(&format!("master_rot_{c}")));
    let quat = |q: &[Vec<f64>; 4], n: usize| [q[0][n], q[1][n], q[2][n], q[3][n]];
    // The robot's tool from its joints as measured (the robot's record), in its base
    // frame: FK of the Panda's URDF (tactile-chain's, equal to Pinocchio's to 1e-9,
    // tests/chain.rs), not the loop's map back into the master's frame.
    let q: Vec<Vec<f64>> = (1..=7).map(|i| jc(&format!("q_{i}"))).collect();
    let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/panda.urdf");
    let xml = std::fs::read_to_string(urdf).expect("panda.urdf");
    let chain = tactile_chain::Chain::from_urdf(&xml, "panda_link0", "panda_hand").expect("chain");
    let fk = |n: usize| chain.fk(&q.iter().map(|c| c[n]).collect::<Vec<_>>());
    let (mut moves, mut turns, mut settled) = (Vec::new(), Vec::new(), Vec::new());
    for (e, end) in engaged_stretches(&jc("released")) {
        let at = |x: &[Vec<f64>; 3], n: usize| Vector3::new(x[0][n], x[1][n], x[2][n]);
        let m_e = rot(&quat(&master_rot, e));
        let tool_e = fk(e);
        let error =
            |n: usize, m: usize| (fk(n).p - tool_e.p - scale * r * (at(&v, m) - at(&v, e))).norm();
        let still = end >= e + STILL && (end - STILL..=end).all(|m| at(&v, m) == at(&v, end));
        if still && h.iter().all(|c| c[end] == 0.0) {
            settled.push(error(end, end));
        }
        for n in (e + 50)..=end {
            if h.iter().any(|c| c[n] != 0.0) {
                break;
            }
            // Since the engage: the robot's move against S R times the master's, its
            // turn against the master's turn carried by R; the nearest of the
            // master's last LAG samples (a stand-in starved by the suite follows the
            // same path late: this measures the map, not the stand-in's timing).
            let tool = fk(n);
            let lagged = n.saturating_sub(LAG).max(e)..=n;
            moves.push(
                lagged
                    .clone()
                    .map(|m| error(n, m))
                    .fold(f64::INFINITY, f64::min),
            );
            let turned = |m: usize| {
                let turn = rot(&quat(&master_rot, m)) * m_e.transpose();
                angle_deg(&tool.r, &(r * turn * r.transpose() * tool_e.r))
            };
            turns.push(lagged.map(turned).fold(f64::INFINITY, f64::min));
        }
    }
    moves.sort_by(f64::total_cmp);
    turns.sort_by(f64::total_cmp);
    Following {
        moves,
        turns,
        settled,
    }
}

/// The Touch's trajectory: driver values of waist, shoulder, elbow (after the
/// shoulder), yaw, pitch, roll. The grey button pressed at 0.8 s, a stroke down and
/// right while turning the stylus, released at 3 s; back to the start with the stylus
/// rolled (the robot holds), pressed again at 4.8 s; a second stroke down into the
/// wall under the robot.
fn touch_csv() -> String {
    let q0 = vec![0.0, 0.0, 0.0, 3.5, 0.2, 0.1];
    let q1 = vec![0.15, -0.12, 0.12, 3.8, 0.35, 0.1];
    let q0b = vec![0.0, 0.0, 0.0, 3.5, 0.2, 0.5];
    let q2 = vec![-0.1, -0.16, 0.16, 3.3, 0.1, 0.5];
    let keys = [
        (0.0, q0.clone()),
        (1.0, q0),
        (2.8, q1.clone()),
        (3.2, q1),
        (4.6, q0b.clone()),
        (5.0, q0b),
        (6.8, q2),
    ];
    let grey = |t: f64| f64::from(u8::from((0.8..3.0).contains(&t) || t >= 4.8));
    format!(
        "t,waist,shoulder,elbow,yaw,pitch,roll,grey\n{}",
        keyframes(&keys, grey, 9.0)
    )
}

/// The scenario: the Panda of panda.toml behind a joint trajectory controller, the
/// Touch over its driver, the map between them.
fn touch_scenario(domain: u32, ports: [u16; 2]) -> String {
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/scenarios/panda.toml")).expect("panda");
    let text = text
        .replace("../robots/panda.urdf", &format!("{root}/robots/panda.urdf"))
        .replace("samples = 4000", "samples = 8000");
    // No wall of the loop's own: the robot meets MuJoCo's.
    let text = text.split("[[environment.objects]]").next().expect("text");
    format!(
        r#"{text}
rotation = {{ rpy_deg = [90.0, 0.0, -90.0] }}
scale = 1.5
force_scale = 0.02

[ros]
domain_id = {domain}
connect = ["tcp/127.0.0.1:{p0}", "tcp/127.0.0.1:{p1}"]

[master]
backend = "ros2"

[master.ros2]
joint_states = "/phantom/joint_states"
joints = ["waist", "shoulder", "elbow"]
force_topic = "/phantom/force_feedback"
force_message = "omni_feedback"
gimbal = {{ urdf = "{root}/devices/phantom_omni.urdf", base = "base", tip = "stylus", frame = {{ rpy_deg = [-90.0, 0.0, 0.0] }} }}
clutch = {{ kind = "omni_button", topic = "/phantom/button", button = "grey" }}

[master.ros2.map]
elbow_after_shoulder = true

[master.ros2.force_map]
axes = [0, 2, 1]
sign = [1.0, -1.0, 1.0]

[master.ros2.watch]
timeout_ms = 300.0

[slave]
backend = "ros2"

[slave.ros2]
joint_states = "/fr3/joint_states"
command = "trajectory"
command_topic = "/fr3_arm_controller/joint_trajectory"
wrench_topic = "/fts/wrench"

[slave.ros2.watch]
timeout_ms = 300.0
"#,
        p0 = ports[0],
        p1 = ports[1]
    )
}

/// A Touch over the omni_common driver's topics drives a Panda in MuJoCo: the Panda
/// waits for the first press of the grey button; with it held, the tool follows the
/// stylus through the map (a quarter turn between the bases, 1.5 times the motion)
/// within 1 mm and 1 degree at the median; released, the robot holds while the hand
/// goes back; pressed again with the stylus rolled, no step; the wall MuJoCo's hand
/// meets comes back to the Touch as `OmniFeedback`, scaled by 0.02 and turned into its
/// frame.
#[test]
fn a_touch_drives_a_mujoco_panda_through_the_map_with_the_clutch() {
    if !mujoco_ready() {
        return cannot("python3 lacks eclipse-zenoh, rosbags or mujoco");
    }
    let _serial = one_at_a_time();
    let sb = Sandbox::new("hand-touch");
    let ports = [free_port(), free_port()];
    let panda = (PANDA_JOINTS, PANDA_READY, "/fr3/joint_states");
    let command = ("trajectory", "/fr3_arm_controller/joint_trajectory");
    let arm = any_arm_standin(&sb, panda, (40, ports[0]), command, &MUJOCO_PANDA);
    sb.write("touch.csv", &touch_csv());
    let listen = format!("tcp/127.0.0.1:{}", ports[1]);
    let touch = hand_standin(
        &sb,
        &[
            "touch",
            "--domain",
            "40",
            "--listen",
            &listen,
            "--trajectory",
            "touch.csv",
            "--force-topic",
            "/phantom/force_feedback",
            "--end-after",
            "9.0",
            "--report",
            "touch.json",
        ],
    );
    listening(ports[0]);
    listening(ports[1]);
    let scenario = sb.write("touch.toml", &touch_scenario(40, ports));
    sb.run(&scenario, "out");
    let r = report(&sb, arm, "arm.json");
    let d = report(&sb, touch, "touch.json");
    let s = sb.json("out", "summary.json");
    assert_eq!(s["nodes"]["slave"]["ended"], "completed, after sample 7999");
    assert_eq!(num(&s["master"]["device"]["rejected"]), 0.0, "{s}");
    assert_eq!(d["token_problems"], serde_json::json!([]), "{d}");
    assert_eq!(d["bad_attachments"], serde_json::json!([]), "{d}");
    assert_eq!(r["bad_commands"], serde_json::json!([]), "{r}");
    check_touch_run(&sb, &r, &d);
}

fn check_touch_run(sb: &Sandbox, r: &serde_json::Value, d: &serde_json::Value) {
    let trace = sb.trace("out");
    let joints = std::fs::read_to_string(sb.path("out").join("joints.csv")).expect("joints");
    let released = util::column(&joints, "released");
    let stretches = engaged_stretches(&released);
    assert_eq!(stretches.len(), 2, "two presses: {stretches:?}");
    assert!(released[0] == 1.0, "the robot waits for the first press");
    let Following {
        moves,
        turns,
        settled,
    } = following(&trace, &joints, 1.5, &touch_to_panda());
    assert_eq!(settled.len(), 1, "the first stroke ends still: {settled:?}");
    assert!(settled[0] < 1e-3, "{} mm off, settled", settled[0] * 1e3);
    let median = |v: &[f64]| v[v.len() / 2];
    let (worst_m, worst_t) = (moves[moves.len() - 1], turns[turns.len() - 1]);
    assert!(moves.len() > 2000, "{} free-space samples", moves.len());
    assert!(
        median(&moves) < 1e-3 && worst_m < 1e-2,
        "{} mm median, {} mm worst",
        median(&moves) * 1e3,
        worst_m * 1e3
    );
    assert!(
        median(&turns) < 1.0 && worst_t < 5.0,
        "{} degrees median, {worst_t} worst",
        median(&turns)
    );
    // Released: the tool holds while the hand goes back.
    let tool = [1, 2, 3].map(|i| util::column(&trace, &format!("tool_{i}")));
    let (a, b) = (stretches[0].1 + 100, stretches[1].0 - 1);
    let drift = util::largest_move(&tool, a, b + 1);
    assert!(
        drift * 1.5 < 1e-3,
        "the robot moved {} mm while released",
        drift * 1.5e3
    );
    // Engaged again with the stylus rolled 0.4 rad: the references do not step.
    let q_ref: Vec<Vec<f64>> = (1..=7)
        .map(|i| util::column(&joints, &format!("q_ref_{i}")))
        .collect();
    let e = stretches[1].0;
    let step = (0..7)
        .map(|i| (q_ref[i][e] - q_ref[i][e - 1]).abs())
        .fold(0.0, f64::max);
    assert!(step < 1e-6, "the engage stepped a reference {step} rad");
    // No command steps a joint further than its URDF velocity limit allows in 1 ms,
    // but the end's hold (at the joints measured, which a robot pressed into a wall
    // lags its reference by: the step that takes the force off).
    let xml = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/panda.urdf"))
        .expect("panda.urdf");
    let chain = tactile_chain::Chain::from_urdf(&xml, "panda_link0", "panda_hand").expect("chain");
    for (d, step) in chain.dofs.iter().zip(floats(&r["max_step_before_last"])) {
        assert!(
            step <= d.velocity * 1e-3 + 1e-12,
            "{} stepped {step} rad in 1 ms, past {} rad/s",
            d.name,
            d.velocity
        );
    }
    // The wall: MuJoCo's contact pushes the hand up (the robot's z), the master's up
    // (its y) at 0.02 of it, the Touch's z (the omni_common frame's up).
    let h = [1, 2, 3].map(|i| util::column(&trace, &format!("h_{i}")));
    let end = h[1].len() - 1;
    assert!(
        h[1][end] > 0.5,
        "h at the end {:?}",
        [h[0][end], h[1][end], h[2][end]]
    );
    assert!(h[0][end].abs() < 0.2 * h[1][end] && h[2][end].abs() < 0.2 * h[1][end]);
    let f_end = floats(&r["force_before_last"]);
    let f_end = f_end.iter().map(|x| x * x).sum::<f64>().sqrt();
    let h_end = (0..3).map(|k| h[k][end].powi(2)).sum::<f64>().sqrt();
    assert!(
        (h_end - 0.02 * f_end).abs() < 0.1 * h_end,
        "h {h_end} N, MuJoCo's force at the loop's end {f_end} N"
    );
    let last = last_force(d);
    let s = sb.json("out", "summary.json");
    matches_the_loops_force(&s, last[3], h[1][end], "the Touch's z");
    assert!(
        last[1].abs() < 0.2 * last[3] && last[2].abs() < 0.2 * last[3],
        "the Touch's last force {last:?}"
    );
    eprintln!(
        "Touch -> MuJoCo Panda: {} free-space samples within {:.2} mm median ({:.2} worst) and {:.3} degrees ({:.2} worst), \
         {:.3} mm settled; {:.3} mm held while released; engage step {step:.1e} rad; {:.2} N at the Touch for MuJoCo's {:.1} N at the end",
        moves.len(),
        median(&moves) * 1e3,
        worst_m * 1e3,
        median(&turns),
        worst_t,
        settled[0] * 1e3,
        drift * 1.5e3,
        last[3],
        f_end
    );
}

/// The last force a device stand-in received before the end's zero (which must come:
/// the run leaves the device rendering nothing), `[t, fx, fy, fz]`.
/// The device's last force on one axis, `got`, against the loop's last force on that
/// axis, `want`: the same within 0.05 N when the gate ramped the force up only once
/// (at the start); after a restart (the device or the loop lost for a moment, as on a
/// loaded machine) the force may end part way up its ramp, so then it only has to
/// point the same way and be no larger.
fn matches_the_loops_force(s: &serde_json::Value, got: f64, want: f64, what: &str) {
    let device = &s["master"]["device"];
    let (ramps, losses) = (num(&device["ramps"]), num(&device["losses"]));
    if ramps == 1.0 && losses == 0.0 {
        assert!(
            (got - want).abs() < 0.05,
            "{what}: {got} N for the loop's {want} N"
        );
    } else {
        eprintln!("{ramps} ramps, {losses} losses: {what} {got} N for the loop's {want} N");
        assert!(
            got * want > 0.0 && got.abs() <= want.abs() + 0.05,
            "{what}: {got} N for the loop's {want} N after {ramps} ramps, {losses} losses"
        );
    }
}

fn last_force(d: &serde_json::Value) -> Vec<f64> {
    let forces: Vec<Vec<f64>> = d["forces"]
        .as_array()
        .expect("forces")
        .iter()
        .map(floats)
        .collect();
    let end = forces.last().expect("forces came");
    assert_eq!(
        end[1..],
        [0.0; 3],
        "the run ended with {end:?} on the device"
    );
    forces
        .into_iter()
        .rev()
        .find(|f| f[1..].iter().any(|x| *x != 0.0))
        .expect("a force came")
}

/// The Force Dimension device's trajectory: position (m, fd_base) and orientation.
/// The clutch pressed at 0.5 s, a 4 cm stroke forward and a 15 degree turn about its
/// vertical; released at 2.6 s and back (the robot holds); pressed again at 4.4 s, a
/// second stroke.
fn fd_csv() -> String {
    let (s, c) = (15f64.to_radians() / 2.0).sin_cos();
    let p0 = vec![0.01, -0.02, 0.03, 0.0, 0.0, 0.0, 1.0];
    let p1 = vec![0.05, -0.02, 0.03, 0.0, 0.0, s, c];
    let p0b = vec![0.01, -0.02, 0.03, 0.0, 0.0, s, c];
    let keys = [
        (0.0, p0.clone()),
        (0.7, p0),
        (2.4, p1.clone()),
        (2.8, p1.clone()),
        (4.0, p0b.clone()),
        (4.6, p0b),
        (6.0, p1),
    ];
    let clutch = |t: f64| f64::from(u8::from((0.5..2.6).contains(&t) || t >= 4.4));
    format!(
        "t,x,y,z,qx,qy,qz,qw,clutch\n{}",
        keyframes(&keys, clutch, 7.0)
    )
}

/// A Force Dimension device as ICube's driver publishes it (its pose in fd_base, the
/// clutch as a Bool, the force taken as a Float64MultiArray) drives the simulated Panda
/// at twice its motion: the pose moves and turns the tool from the first press on,
/// the release holds it, and the force reaches the device as `[fx, fy, fz]`.
#[test]
fn a_force_dimension_device_drives_the_panda_with_its_clutch() {
    if !python_ready() {
        return cannot("python3 lacks eclipse-zenoh or rosbags");
    }
    let _serial = one_at_a_time();
    let sb = Sandbox::new("hand-fd");
    let port = free_port();
    sb.write("fd.csv", &fd_csv());
    let listen = format!("tcp/127.0.0.1:{port}");
    let fd = hand_standin(
        &sb,
        &[
            "fd",
            "--domain",
            "41",
            "--listen",
            &listen,
            "--trajectory",
            "fd.csv",
            "--force-topic",
            "/fd/fd_controller/commands",
            "--end-after",
            "8.0",
            "--report",
            "fd.json",
        ],
    );
    listening(port);
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/scenarios/panda.toml")).expect("panda");
    let text = text
        .replace("../robots/panda.urdf", &format!("{root}/robots/panda.urdf"))
        .replace("samples = 4000", "samples = 7000");
    let (objects_at, _) = text.split_once("[[environment.objects]]").expect("a wall");
    let scenario = format!(
        r#"{objects_at}scale = 2.0

[[environment.objects]]
kind = "plane"
point = [0.055, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
stiffness = [100.0, 100.0, 100.0]

[ros]
domain_id = 41
connect = ["tcp/127.0.0.1:{port}"]

[master]
backend = "ros2"

[master.ros2]
input = "pose"
pose_topic = "/fd/ee_pose"
force_topic = "/fd/fd_controller/commands"
force_message = "float64_multi_array"
clutch = {{ kind = "bool", topic = "/fd/fd_clutch" }}

[master.ros2.watch]
timeout_ms = 300.0
"#
    );
    let path = sb.write("fd.toml", &scenario);
    sb.run(&path, "out");
    let d = report(&sb, fd, "fd.json");
    let s = sb.json("out", "summary.json");
    assert_eq!(s["nodes"]["slave"]["ended"], "completed, after sample 6999");
    assert_eq!(num(&s["master"]["device"]["rejected"]), 0.0, "{s}");
    assert_eq!(d["token_problems"], serde_json::json!([]), "{d}");
    let trace = sb.trace("out");
    let joints = std::fs::read_to_string(sb.path("out").join("joints.csv")).expect("joints");
    let stretches = engaged_stretches(&util::column(&joints, "released"));
    assert_eq!(stretches.len(), 2, "{stretches:?}");
    let Following {
        moves,
        turns,
        settled,
    } = following(&trace, &joints, 2.0, &Matrix3::identity());
    assert!(!settled.is_empty(), "a stroke ends still: {settled:?}");
    assert!(
        settled.iter().all(|d| *d < 1e-3),
        "{settled:?} m off, settled"
    );
    let median = |v: &[f64]| v[v.len() / 2];
    assert!(median(&moves) < 1e-3, "{} mm", median(&moves) * 1e3);
    assert!(median(&turns) < 1.0, "{} degrees", median(&turns));
    // The hand reaches x = 0.05 + 0.04 in the loop's frame past its first stroke's
    // clutch: the second stroke ends 2 cm into the wall at x = 0.055 (the first
    // stroke's 4 cm plus 4 cm from where the first stroke left it): the force pushes
    // back along -x and reaches the device as the array.
    let h1 = util::column(&trace, "h_1");
    let end = h1.len() - 1;
    assert!(h1[end] < -0.5, "h_1 at the end {}", h1[end]);
    let last = last_force(&d);
    assert_eq!(last.len(), 4, "t and three forces: {last:?}");
    matches_the_loops_force(&s, last[1], h1[end], "the device's x");
    eprintln!(
        "Force Dimension -> Panda: {} free-space samples within {:.2} mm and {:.3} degrees at the median, {:.3} mm settled; {:.2} N at the device",
        moves.len(),
        median(&moves) * 1e3,
        median(&turns),
        settled.iter().fold(0.0f64, |a, d| a.max(*d)) * 1e3,
        last[1]
    );
}
