//! The URDF arm's unit tests (beside the module, which they would double).
use super::*;
use crate::environment::Scene;
use nalgebra::{Quaternion, UnitQuaternion};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use tactile_scenario::{
    ArmIkConfig, ArmServo, CartesianConfig, FrameRotation, Object, Scale, Workspace,
};

fn panda_xml() -> String {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../deploy/robots/panda.urdf");
    std::fs::read_to_string(p).expect("panda.urdf")
}

fn panda_cfg() -> ArmConfig {
    ArmConfig {
        urdf: "panda.urdf".into(),
        base: "panda_link0".into(),
        tip: "panda_hand".into(),
        home: vec![
            0.0,
            -FRAC_PI_4,
            0.0,
            -3.0 * FRAC_PI_4,
            0.0,
            FRAC_PI_2,
            FRAC_PI_4,
        ],
        kp: vec![600.0, 600.0, 600.0, 600.0, 250.0, 150.0, 50.0],
        kd: vec![50.0, 50.0, 50.0, 50.0, 30.0, 25.0, 15.0],
        scale: Scale::Uniform(1.0),
        rotation: FrameRotation::default(),
        workspace: None,
        force_scale: 1.0,
        step_s: 2.5e-4,
        gravity: [0.0, 0.0, -9.81],
        ik: ArmIkConfig::default(),
        servo: ArmServo::Joint,
        cartesian: CartesianConfig::default(),
    }
}

const HOME: [f64; 3] = [0.0, -0.107, -0.035];

#[test]
fn gravity_compensation_holds_the_arm_at_home() {
    let mut arm = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    for _ in 0..1000 {
        arm.follow(HOME, None, 1e-3);
        assert_eq!(arm.advance(1e-3, Touch::Scene(&Scene::new(&[]))), 0);
    }
    let s = arm.state();
    for (q, h) in s.q.iter().zip(&panda_cfg().home) {
        assert!((q - h).abs() < 1e-6, "{q} against {h}");
    }
    let tool = arm.tool();
    for k in 0..3 {
        assert!((tool[k] - HOME[k]).abs() < 1e-6, "{tool:?}");
    }
}

#[test]
fn at_rest_the_servo_gives_the_gravity_torques() {
    // At home with no error the servo's effort is the gravity torque itself (RNEA),
    // far from zero: without it the arm would sag.
    let arm = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    let g = arm.dynamics.gravity_torques(&panda_cfg().home).expect("g");
    let tau = arm.servo_now();
    assert_eq!(tau, g);
    assert!(g[1].abs() > 1.0, "{g:?}");
}

#[test]
fn the_tool_follows_a_scaled_displacement_and_maps_back() {
    let cfg = ArmConfig {
        scale: Scale::Uniform(2.0),
        ..panda_cfg()
    };
    let mut arm = UrdfArm::new(&cfg, &panda_xml(), HOME).expect("arm");
    let home_tool = arm.chain().fk(&cfg.home);
    let goal = [HOME[0] + 0.01, HOME[1] - 0.02, HOME[2] + 0.015];
    for _ in 0..2000 {
        arm.follow(goal, None, 1e-3);
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    // In the robot's frame the tool moved twice the master's displacement...
    let p = arm.chain().fk(&arm.state().q).p - home_tool.p;
    for (k, d) in [0.02, -0.04, 0.03].iter().enumerate() {
        assert!((p[k] - d).abs() < 1e-5, "{p:?}");
    }
    // ...and mapped back it is where the master is.
    let t = arm.tool();
    for k in 0..3 {
        assert!((t[k] - goal[k]).abs() < 1e-5, "{t:?}");
    }
}

/// The map of a Touch on a desk (its y up, its z towards the operator) onto a robot
/// (z up): a quarter turn about x, a per-axis scale. The tool follows `S R d`, the
/// master's turn about its own up axis turns the tool about the robot's up axis, and
/// a force the robot measures comes back in the master's axes, scaled.
#[test]
fn a_rotated_per_axis_map_moves_turns_and_feels_in_the_right_axes() {
    let cfg = ArmConfig {
        scale: Scale::PerAxis([2.0, 3.0, 1.5]),
        rotation: FrameRotation::RpyDeg([90.0, 0.0, 0.0]),
        force_scale: 0.5,
        ..panda_cfg()
    };
    let arm = UrdfArm::new(&cfg, &panda_xml(), HOME).expect("arm");
    let home_tool = arm.chain().fk(&cfg.home);
    // Master: 1 cm right, 2 cm up, 1 cm towards the operator.
    let goal = [HOME[0] + 0.01, HOME[1] + 0.02, HOME[2] + 0.01];
    let (t, clamped) = arm.target(goal, None);
    assert!(!clamped);
    let d = t.p - home_tool.p;
    // Right stays x (x2), up becomes z (x1.5), towards the operator becomes -y (x3).
    for (k, want) in [0.02, -0.03, 0.03].iter().enumerate() {
        assert!((d[k] - want).abs() < 1e-12, "{d:?}");
    }
    let back = cfg.to_master(home_tool.p.into(), HOME, t.p.into());
    for k in 0..3 {
        assert!((back[k] - goal[k]).abs() < 1e-12, "{back:?}");
    }
    // A turn about the master's up axis (y) is a turn about the robot's up axis (z).
    let turn = UnitQuaternion::from_axis_angle(&nalgebra::Vector3::y_axis(), 0.3);
    let (t, _) = arm.target(HOME, Some([turn.i, turn.j, turn.k, turn.w]));
    let about = tactile_chain::spatial::log_rotation(&(t.r * home_tool.r.transpose()));
    assert!(
        (about - nalgebra::Vector3::new(0.0, 0.0, 0.3)).norm() < 1e-12,
        "{about:?}"
    );
    // 10 N pushing the robot's tool down (-z) is 5 N pushing the hand down (-y).
    let f = arm.felt([0.0, 0.0, -10.0]);
    for (k, want) in [0.0, -5.0, 0.0].iter().enumerate() {
        assert!((f[k] - want).abs() < 1e-12, "{f:?}");
    }
}

/// A target beyond the workspace box is clamped onto it and said to be; the arm goes
/// no further however far the master goes.
#[test]
fn a_target_outside_the_workspace_is_clamped_and_counted() {
    let probe = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    let home = probe.chain().fk(&panda_cfg().home).p;
    let cfg = ArmConfig {
        workspace: Some(Workspace {
            min: [home.x - 0.5, home.y - 0.5, home.z - 0.02],
            max: [home.x + 0.5, home.y + 0.5, home.z + 0.5],
        }),
        ..panda_cfg()
    };
    let mut arm = UrdfArm::new(&cfg, &panda_xml(), HOME).expect("arm");
    // A box the tool's home is not in is refused: the robot would move at once.
    let outside = ArmConfig {
        workspace: Some(Workspace {
            min: [home.x + 0.1, home.y - 0.5, home.z - 0.5],
            max: [home.x + 0.5, home.y + 0.5, home.z + 0.5],
        }),
        ..panda_cfg()
    };
    let e = UrdfArm::new(&outside, &panda_xml(), HOME).expect_err("refused");
    assert!(
        e.contains("slave.arm.workspace") && e.contains("outside the box"),
        "{e}"
    );
    let down = [HOME[0], HOME[1], HOME[2] - 0.05];
    let mut clamped = 0;
    for _ in 0..3000 {
        clamped += u32::from(arm.follow(down, None, 1e-3).workspace_clamped);
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    assert!(clamped > 2000, "{clamped}");
    let z = arm.chain().fk(&arm.state().q).p.z;
    assert!(
        (z - (home.z - 0.02)).abs() < 1e-4,
        "{z} against the floor {}",
        home.z - 0.02
    );
}

/// The Cartesian impedance is a spring at the tool: held 2 cm into a 1000 N/m wall
/// with a 1000 N/m stiffness along z, the tool settles half way (two equal springs
/// in series: 1 cm, 10 N).
#[test]
fn a_cartesian_impedance_yields_as_its_stiffness_says() {
    let wall_z = HOME[2] - 0.01;
    let wall = Object::Plane {
        point: [0.0, 0.0, wall_z],
        normal: [0.0, 0.0, 1.0],
        stiffness: [1000.0; 3],
    };
    let goal = [HOME[0], HOME[1], wall_z - 0.02];
    let settle = |cfg: &ArmConfig| {
        let mut arm = UrdfArm::new(cfg, &panda_xml(), HOME).expect("arm");
        for _ in 0..4000 {
            arm.follow(goal, None, 1e-3);
            arm.advance(1e-3, Touch::Scene(&Scene::new(std::slice::from_ref(&wall))));
        }
        wall_z - arm.tool()[2]
    };
    let cfg = ArmConfig {
        servo: ArmServo::Cartesian,
        cartesian: CartesianConfig {
            stiffness: [1000.0, 1000.0, 1000.0, 100.0, 100.0, 100.0],
            ..CartesianConfig::default()
        },
        ..panda_cfg()
    };
    let pen = settle(&cfg);
    assert!((pen - 0.01).abs() < 5e-4, "penetration {pen} m");
    // Three times stiffer: three quarters of the way (15 mm, 15 N).
    let mut stiffer = cfg.clone();
    stiffer.cartesian.stiffness[2] = 3000.0;
    let pen = settle(&stiffer);
    assert!((pen - 0.015).abs() < 5e-4, "penetration {pen} m");
}

#[test]
fn a_wall_pushes_the_tool_back_and_efforts_stay_in_limits() {
    let mut arm = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    let wall = Object::Plane {
        point: [0.0, 0.0, HOME[2] - 0.01],
        normal: [0.0, 0.0, 1.0],
        stiffness: [600.0; 3],
    };
    let goal = [HOME[0], HOME[1], HOME[2] - 0.03];
    for _ in 0..3000 {
        arm.follow(goal, None, 1e-3);
        arm.advance(1e-3, Touch::Scene(&Scene::new(std::slice::from_ref(&wall))));
    }
    let t = arm.tool();
    // Held between the wall and the target: inside the wall, short of the target.
    assert!(t[2] < HOME[2] - 0.01 && t[2] > goal[2] + 1e-3, "{t:?}");
    for (tau, d) in arm.state().tau.iter().zip(&arm.chain().dofs) {
        assert!(tau.abs() <= d.effort);
    }
}

#[test]
fn a_hold_keeps_the_joints_where_the_input_went_silent() {
    let mut arm = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    let goal = [HOME[0] + 0.02, HOME[1], HOME[2]];
    for _ in 0..100 {
        arm.follow(goal, None, 1e-3);
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    // Still moving when the input stops: the servo brings it back to where it was.
    let at_silence = arm.state().q;
    let first = arm.hold(1e-3, Touch::Scene(&Scene::new(&[])));
    assert!(first.started);
    let mut last = first;
    for _ in 0..1000 {
        last = arm.hold(1e-3, Touch::Scene(&Scene::new(&[])));
        assert!(!last.started);
        // Braking from the velocity limit overshoots by about 2 mm, no more.
        assert!(last.drift_m < 5e-3, "{last:?}");
    }
    assert!(last.drift_m < 1e-6, "{last:?}");
    for (q, h) in arm.state().q.iter().zip(&at_silence) {
        assert!((q - h).abs() < 1e-5);
    }
    arm.end_hold();
    assert!(arm.hold(1e-3, Touch::Scene(&Scene::new(&[]))).started);
}

#[test]
fn a_chain_that_does_not_fit_the_table_is_named() {
    let cfg = ArmConfig {
        kp: vec![1.0; 6],
        ..panda_cfg()
    };
    let e = UrdfArm::new(&cfg, &panda_xml(), HOME).expect_err("six gains");
    assert!(
        e.contains("slave.arm.kp") && e.contains("has 7 joints"),
        "{e}"
    );
    let e = UrdfArm::new(&panda_cfg(), "<robot name=\"x\"/>", HOME).expect_err("empty");
    assert!(e.contains("panda_link0"), "{e}");
}

/// A 6-DoF master's turn, under either servo: the hand turns to it about the base's
/// axes (its orientation relative to home is the master's rotation).
#[test]
fn both_servos_turn_the_hand_to_the_masters_rotation() {
    let h = 15f64.to_radians();
    // 30 degrees about z, then 20 about x, composed about the base's axes.
    let turn = quaternion(
        &(rotation_matrix([h.sin(), 0.0, 0.0, h.cos()])
            * rotation_matrix([0.0, 0.0, (2.0 * h).sin(), (2.0 * h).cos()])),
    );
    // Round trip of the two conversions.
    let back = quaternion(&rotation_matrix(turn));
    assert!(turn.iter().zip(&back).all(|(a, b)| (a - b).abs() < 1e-15));
    for servo in [ArmServo::Joint, ArmServo::Cartesian] {
        let mut arm = UrdfArm::new(
            &ArmConfig {
                servo,
                ..panda_cfg()
            },
            &panda_xml(),
            HOME,
        )
        .expect("arm");
        for n in 0..=2000 {
            // Along a slerp from home over the first second.
            let s = (n as f64 / 1000.0).min(1.0);
            let r = UnitQuaternion::identity().slerp(
                &UnitQuaternion::from_quaternion(Quaternion::new(
                    turn[3], turn[0], turn[1], turn[2],
                )),
                s,
            );
            arm.follow(HOME, Some([r.i, r.j, r.k, r.w]), 1e-3);
            arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
        }
        let got = arm.tool_rotation();
        let err = (0..4).map(|k| (got[k] - turn[k]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-3, "{servo:?}: {got:?} vs {turn:?}");
        let p = arm.tool();
        assert!(
            (0..3).all(|k| (p[k] - HOME[k]).abs() < 1e-3),
            "{servo:?}: {p:?}"
        );
    }
}

/// Released, the references hold whatever the master does; engaged again, the
/// target continues from the held reference (no step), then follows the master's
/// moves from there.
#[test]
fn the_clutch_holds_the_references_and_reengages_without_a_step() {
    let mut arm = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    let away = [HOME[0] + 0.02, HOME[1], HOME[2]];
    for _ in 0..500 {
        arm.follow(away, None, 1e-3);
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    let held = arm.state().q_ref;
    for _ in 0..200 {
        arm.release();
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    assert_eq!(arm.state().q_ref, held);
    assert!(arm.released());
    // Engaged with the master back home: the reference does not move.
    arm.follow(HOME, None, 1e-3);
    let step = arm
        .state()
        .q_ref
        .iter()
        .zip(&held)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(step < 1e-9, "re-engage stepped {step} rad");
    let at_engage = arm.tool();
    for _ in 0..1000 {
        arm.follow([HOME[0], HOME[1] + 0.01, HOME[2]], None, 1e-3);
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    let p = arm.tool();
    assert!(
        (p[1] - at_engage[1] - 0.01).abs() < 1e-3,
        "{p:?} from {at_engage:?}"
    );
}

/// The clutch with the operator's hand turned: released at one orientation, engaged
/// at another, the reference does not step, and the operator's turn since the engage
/// turns the tool about the base's axes from where it held.
#[test]
fn a_turned_reengage_continues_from_the_held_orientation() {
    let mut arm = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    let about = |axis: usize, deg: f64| {
        let h = deg.to_radians() / 2.0;
        let mut q = [0.0, 0.0, 0.0, h.cos()];
        q[axis] = h.sin();
        q
    };
    for _ in 0..1000 {
        arm.follow(HOME, Some(about(2, 20.0)), 1e-3);
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    let held = arm.target_rotation();
    for _ in 0..100 {
        arm.release();
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    // Engaged with the hand turned elsewhere (30 degrees about x): no step.
    let before = arm.state().q_ref;
    arm.follow(HOME, Some(about(0, 30.0)), 1e-3);
    let step = arm
        .state()
        .q_ref
        .iter()
        .zip(&before)
        .map(|(a, b)| (a - b).abs());
    assert!(step.fold(0.0, f64::max) < 1e-9);
    // Then 10 degrees more about the base's z: the tool turns by it from the hold.
    let turned = quaternion(&(rotation_matrix(about(2, 10.0)) * rotation_matrix(about(0, 30.0))));
    for _ in 0..1500 {
        arm.follow(HOME, Some(turned), 1e-3);
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    let want = quaternion(&(rotation_matrix(about(2, 10.0)) * rotation_matrix(held)));
    let got = arm.target_rotation();
    let apart = (0..4).map(|k| (got[k] - want[k]).abs()).fold(0.0, f64::max);
    assert!(apart < 1e-9, "{got:?} vs {want:?}");
    let tool = arm.tool_rotation();
    assert!((0..4).all(|k| (tool[k] - want[k]).abs() < 1e-3), "{tool:?}");
}

/// A URDF of `n` revolute joints in a row, from `l0` to `l{n}`.
fn long_chain(n: usize) -> String {
    let mut xml = String::from("<robot name=\"long\"><link name=\"l0\"/>");
    for k in 1..=n {
        xml += &format!(
            "<link name=\"l{k}\"><inertial><mass value=\"0.1\"/><inertia ixx=\"1e-3\" ixy=\"0\" ixz=\"0\" iyy=\"1e-3\" iyz=\"0\" izz=\"1e-3\"/></inertial></link>\
             <joint name=\"j{k}\" type=\"revolute\"><parent link=\"l{}\"/><child link=\"l{k}\"/>\
             <origin xyz=\"0 0 0.01\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"1\"/></joint>",
            k - 1
        );
    }
    xml += "</robot>";
    xml
}

/// A chain of 300 joints and a `home` of one value: the error listed every joint's
/// name on one line (10,000 of them for a 10,000-joint chain); it names the first ten.
#[test]
fn a_long_chains_joints_are_listed_short() {
    let xml = long_chain(300);
    let cfg = ArmConfig {
        base: "l0".into(),
        tip: "l300".into(),
        home: vec![0.0],
        ..panda_cfg()
    };
    let e = UrdfArm::new(&cfg, &xml, HOME).expect_err("home has one value");
    assert!(
        e.contains("has 300 joints (j1, j2,") && e.contains("j10, ... and 290 more)"),
        "{e}"
    );
    assert!(e.len() < 300, "{} characters", e.len());
}

/// An arm carries its joints inline (no heap per sample): a chain longer than that
/// is refused at load, naming the limit.
#[test]
fn a_chain_of_more_joints_than_an_arm_holds_is_refused() {
    let xml = long_chain(17);
    let cfg = ArmConfig {
        base: "l0".into(),
        tip: "l17".into(),
        home: vec![0.0; 17],
        kp: vec![1.0; 17],
        kd: vec![0.1; 17],
        ..panda_cfg()
    };
    let e = UrdfArm::new(&cfg, &xml, HOME).expect_err("17 joints");
    assert!(
        e.contains("has 17 joints; an arm may have at most 16"),
        "{e}"
    );
}

/// A one-joint arm: a continuous joint (no position limit stops it) with `damping`.
fn one_joint(damping: &str, inertia: &str) -> (ArmConfig, String) {
    let xml = format!(
        r#"<robot name="r"><link name="base"/>
        <link name="a"><inertial><mass value="1"/><inertia {inertia}/></inertial></link>
        <joint name="j" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit effort="10" velocity="10"/><dynamics damping="{damping}"/></joint></robot>"#
    );
    let cfg = ArmConfig {
        base: "base".into(),
        tip: "a".into(),
        home: vec![0.0],
        kp: vec![10.0],
        kd: vec![1.0],
        ..panda_cfg()
    };
    (cfg, xml)
}

/// Issue 51: a dynamics step that failed froze the arm, nothing counted or logged.
/// A damping the semi-implicit Euler step cannot integrate (the velocity grows by
/// 1e12 step / inertia each step) fails once the velocity is not finite: counted,
/// its cause kept for the slave's log (once).
#[test]
fn a_failed_dynamics_step_is_counted_and_its_cause_kept() {
    let (cfg, xml) = one_joint("1e12", r#"ixx="0.01" iyy="0.01" izz="0.01""#);
    let mut arm = UrdfArm::new(&cfg, &xml, HOME).expect("arm");
    arm.state.qd[0] = 1.0;
    for _ in 0..100 {
        arm.advance(1e-3, Touch::Scene(&Scene::new(&[])));
    }
    assert!(arm.dynamics_failures() > 0, "no failure counted");
    let e = arm.take_failure().expect("a cause");
    assert!(e.contains("not finite"), "{e}");
    assert_eq!(arm.take_failure(), None);
    assert!(arm.state().qd.iter().all(|v| v.is_finite()));
}

/// Issue 51: the failed steps were logged but in no output: the slave's counters
/// (its record's totals, summary.json's `slave` counters) carry them.
#[test]
fn failed_dynamics_steps_reach_the_slaves_counters() {
    let (cfg, xml) = one_joint("1e12", r#"ixx="0.01" iyy="0.01" izz="0.01""#);
    let mut arm = UrdfArm::new(&cfg, &xml, HOME).expect("arm");
    arm.state.qd[0] = 1.0;
    let mut scenario = tactile_scenario::Scenario::default();
    scenario.slave.arm = Some(cfg);
    let mut slave =
        crate::hsd::Slave::new(&scenario, Box::new(arm), analytic(&scenario)).expect("slave");
    assert_eq!(slave.counters().dynamics_failed, 0);
    for _ in 0..100 {
        slave.hold(None);
    }
    let failed = slave.counters().dynamics_failed;
    assert!(failed > 0, "no failure in the counters");
    assert_eq!(failed, 100);
}

/// A link whose mass sits on its own joint's axis, with no inertia about it: every
/// step's dynamics would fail, so the arm is refused at load.
#[test]
fn dynamics_that_fail_at_home_are_refused_at_load() {
    let (cfg, xml) = one_joint("0", r#"ixx="0" iyy="0" izz="0""#);
    let e = UrdfArm::new(&cfg, &xml, HOME).expect_err("refused");
    assert!(
        e.contains("at home") && e.contains("joint `j` has no inertia about its axis"),
        "{e}"
    );
}

/// A 6-DoF sample whose orientation is no rotation is the slave's
/// `ROTATION_REJECTED`, not `REJECTED`: its position was still followed, so the
/// position's tracking errors keep the step. A sample rejected on both counts is
/// counted once.
#[test]
fn a_rejected_orientation_is_told_apart_from_a_rejected_position() {
    use tactile_messages::samples::{Flags, Forward, Signal};
    let arm = UrdfArm::new(&panda_cfg(), &panda_xml(), HOME).expect("arm");
    let mut scenario = tactile_scenario::Scenario::default();
    scenario.slave.arm = Some(panda_cfg());
    let mut slave =
        crate::hsd::Slave::new(&scenario, Box::new(arm), analytic(&scenario)).expect("slave");
    let pose = |seq: u64, value: [f64; 3], rotation: [f64; 4]| Forward {
        seq,
        signal: Signal {
            value,
            sent_seq: [seq; 3],
            flags: Flags::POSE,
            ..Signal::default()
        },
        rotation,
        ..Forward::default()
    };
    let (turn, not_a_turn) = ([0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 2.0]);
    let mut h = None;
    let good = slave.step(&pose(0, HOME, turn), &mut h).flags;
    assert!(!good.intersects(Flags::REJECTED | Flags::ROTATION_REJECTED));
    let turned = slave.step(&pose(1, HOME, not_a_turn), &mut h).flags;
    assert!(turned.contains(Flags::ROTATION_REJECTED), "{turned:?}");
    assert!(!turned.intersects(Flags::REJECTED), "{turned:?}");
    assert_eq!(slave.rotation(), Some(turn), "the last rotation is held");
    assert_eq!(slave.counters().rejected, 1);
    let both = slave
        .step(&pose(2, [f64::NAN; 3], not_a_turn), &mut h)
        .flags;
    assert!(
        both.contains(Flags::REJECTED | Flags::ROTATION_REJECTED),
        "{both:?}"
    );
    assert_eq!(slave.counters().rejected, 2, "one sample, counted once");
}

/// The scenario's analytic scene as the slave's world.
fn analytic(scenario: &tactile_scenario::Scenario) -> crate::world::SlaveWorld {
    crate::world::SlaveWorld::Analytic(Scene::new(&scenario.environment.objects))
}
