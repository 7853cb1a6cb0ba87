//! tactile-chain against Pinocchio (the `pin` wheel, an independent implementation)
//! on the arms of example-robot-data read from their own URDFs: the Panda (7 joints,
//! fingers locked), the UR3, UR5 and UR10 (6), the xArm7 (7), Kinova's Jaco2 (6, three
//! continuous), Unitree's Z1 (6) and the SO-101 (5). FK and the Jacobian at
//! random configurations to 1e-9, ABA's accelerations to 1e-9 relative, RNEA's
//! efforts likewise (tests/pin_reference.py makes the reference).

use crate::util::cannot;
use nalgebra::{Matrix6xX, Vector3};
use serde_json::Value;
use std::process::Command;
use tactile_chain::dynamics::Dynamics;
use tactile_chain::Chain;

fn pin_ready() -> bool {
    crate::util::python_has("pinocchio")
}

fn reference() -> Value {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/pin_reference.py");
    let o = Command::new("python3")
        .arg(script)
        .args(["--seed", "7", "--cases", "50"])
        .output()
        .expect("python3 runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("the reference is JSON")
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

/// Largest of `|a - b|` over two equal-length lists.
fn worst(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// `|a - b| / max(|b|, 1)` at worst.
fn worst_relative(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().map(|x| x.abs()).fold(1.0, f64::max);
    worst(a, b) / scale
}

fn check_arm(arm: &Value) -> [f64; 4] {
    let name = arm["name"].as_str().expect("name");
    let xml = std::fs::read_to_string(arm["urdf"].as_str().expect("urdf")).expect("the URDF");
    let chain = Chain::from_urdf(
        &xml,
        arm["base"].as_str().expect("base"),
        arm["tip"].as_str().expect("tip"),
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"));
    let names: Vec<&str> = chain.dofs.iter().map(|d| d.name.as_str()).collect();
    let theirs: Vec<&str> = arm["joints"]
        .as_array()
        .expect("joints")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    assert_eq!(names, theirs, "{name}: the joints, in order");
    let g = floats(&arm["gravity"]);
    let dynamics = Dynamics::new(&chain, Vector3::new(g[0], g[1], g[2])).expect("dynamics");
    let mut jac = Matrix6xX::zeros(chain.dof());
    let mut errors = [0.0f64; 4];
    for case in arm["cases"].as_array().expect("cases") {
        let q = floats(&case["q"]);
        let tip = chain.jacobian(&q, &mut jac);
        let r: Vec<f64> = case["r"]
            .as_array()
            .expect("r")
            .iter()
            .flat_map(floats)
            .collect();
        let ours_r: Vec<f64> = (0..9).map(|k| tip.r[(k / 3, k % 3)]).collect();
        let fk = worst(tip.p.as_slice(), &floats(&case["p"])).max(worst(&ours_r, &r));
        let their_j: Vec<f64> = case["jacobian"]
            .as_array()
            .expect("j")
            .iter()
            .flat_map(floats)
            .collect();
        let ours_j: Vec<f64> = (0..6 * chain.dof())
            .map(|k| jac[(k / chain.dof(), k % chain.dof())])
            .collect();
        let qdd = dynamics
            .aba(&q, &floats(&case["qd"]), &floats(&case["tau"]))
            .expect("aba");
        let tau = dynamics
            .rnea(&q, &floats(&case["qd"]), &floats(&case["qdd_in"]))
            .expect("rnea");
        let e = [
            fk,
            worst(&ours_j, &their_j),
            worst_relative(&qdd, &floats(&case["qdd"])),
            worst_relative(&tau, &floats(&case["tau_rnea"])),
        ];
        for (w, x) in errors.iter_mut().zip(e) {
            *w = w.max(x);
        }
    }
    errors
}

#[test]
fn kinematics_and_dynamics_equal_pinocchios_on_every_arm_of_example_robot_data() {
    if !pin_ready() {
        return cannot(
            "python3 lacks pinocchio (pin) and example-robot-data (tests/requirements.txt)",
        );
    }
    let reference = reference();
    let arms = reference["arms"].as_array().expect("arms");
    assert_eq!(arms.len(), 8, "every arm of tests/pin_reference.py");
    for arm in arms {
        let [fk, jac, aba, rnea] = check_arm(arm);
        let name = &arm["name"];
        eprintln!(
            "{name}: fk {fk:.1e}, jacobian {jac:.1e}, aba {aba:.1e} rel, rnea {rnea:.1e} rel"
        );
        assert!(
            fk < 1e-9 && jac < 1e-9,
            "{name}: fk {fk:e}, jacobian {jac:e}"
        );
        assert!(
            aba < 1e-9 && rnea < 1e-9,
            "{name}: aba {aba:e}, rnea {rnea:e}"
        );
    }
}

/// The Touch's gimbal (deploy/devices/phantom_omni.urdf, the omni_common drivers'
/// chain) against Pinocchio's FK of the same URDF at random joint values, through the
/// master's own reading of a driver's `JointState` (joints in another order, and the
/// URDF's base turned into the paper's frame): the orientation to 1e-9.
#[test]
fn the_touchs_gimbal_turns_as_pinocchio_says() {
    use tactile_devices::hand::Gimbal;
    use tactile_ros::msg::JointState;
    use tactile_scenario::FrameRotation;
    if !pin_ready() {
        return cannot("python3 lacks pinocchio (pin) (tests/requirements.txt)");
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let urdf = root.join("devices/phantom_omni.urdf");
    let o = Command::new("python3")
        .arg(root.join("../tests/gimbal_reference.py"))
        .arg("--urdf")
        .arg(&urdf)
        .output()
        .expect("python3 runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let reference: Value = serde_json::from_slice(&o.stdout).expect("JSON");
    let xml = std::fs::read_to_string(&urdf).expect("the URDF");
    let frame = FrameRotation::RpyDeg([-90.0, 0.0, 0.0]);
    let gimbal = Gimbal::new(&xml, "base", "stylus", &frame).expect("gimbal");
    let names: Vec<String> = reference["joints"]
        .as_array()
        .expect("joints")
        .iter()
        .map(|v| v.as_str().expect("a name").to_string())
        .collect();
    assert_eq!(gimbal.names(), names.as_slice());
    let f = nalgebra::Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0);
    let mut worst_seen = 0.0f64;
    for case in reference["cases"].as_array().expect("cases") {
        let q = floats(&case["q"]);
        let r: Vec<f64> = case["r"]
            .as_array()
            .expect("r")
            .iter()
            .flat_map(floats)
            .collect();
        let theirs = f * nalgebra::Matrix3::from_row_slice(&r);
        // The driver's message: its joints in reverse order, one it has besides.
        let mut js = JointState::default();
        for (name, v) in names.iter().zip(&q).rev() {
            js.name.push(name.clone());
            js.position.push(*v);
        }
        js.name.push("gripper".into());
        js.position.push(0.0);
        let x = gimbal.read(&js).expect("a reading");
        let ours = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            x[3], x[0], x[1], x[2],
        ))
        .to_rotation_matrix();
        worst_seen = worst_seen.max((ours.matrix() - theirs).abs().max());
    }
    eprintln!("the gimbal against pinocchio: {worst_seen:.1e}");
    assert!(worst_seen < 1e-9, "{worst_seen:e}");
}
