//! The IK with its workspace (issue 66: a call allocates nothing) gives the bits of the
//! IK as it was (`ik_reference`, kept verbatim): over random chains (revolute,
//! continuous, prismatic, fixed and mimic joints, any axes, limits finite or not),
//! random configurations (the 3-row and the 6-row task, a posture or not) and random
//! targets followed call after call, and on the Panda and the UR5 as a slave drives
//! them. One workspace serves every chain in turn, so its remaking is tested too.

mod ik_reference;

use ik_reference::Reference;
use nalgebra::Vector3;
use proptest::prelude::*;
use tactile_chain::ik::Workspace;
use tactile_chain::{Chain, Frame, Ik, IkConfig};

const PANDA: &str = include_str!("../../../deploy/robots/panda.urdf");
const UR5: &str = include_str!("../../../deploy/robots/ur5_robot.urdf");

/// One joint of a random arm.
#[derive(Debug, Clone)]
struct Spec {
    /// 0 revolute, 1 continuous, 2 prismatic, 3 fixed, 4 a mimic of the first joint.
    kind: u8,
    xyz: [f64; 3],
    rpy: [f64; 3],
    axis: [f64; 3],
    /// Lower limit and range.
    limits: (f64, f64),
    /// Velocity limit (0: none, infinite).
    velocity: f64,
}

fn spec() -> impl Strategy<Value = Spec> {
    (
        0u8..5,
        prop::array::uniform3(-0.3f64..0.3),
        prop::array::uniform3(-3.2f64..3.2),
        prop::array::uniform3(-1.0f64..1.0),
        (-3.0f64..0.5, 0.1f64..4.0),
        prop_oneof![4 => 0.1f64..5.0, 1 => Just(0.0)],
    )
        .prop_map(|(kind, xyz, rpy, axis, limits, velocity)| Spec {
            kind,
            xyz,
            rpy,
            axis,
            limits,
            velocity,
        })
}

/// The URDF of a serial arm of `specs` (the first joint always moves on its own).
fn urdf(specs: &[Spec]) -> String {
    let mut s = String::from(r#"<robot name="random"><link name="l0"/>"#);
    for (i, j) in specs.iter().enumerate() {
        let kind = match (i, j.kind) {
            (0, _) | (_, 0) | (_, 4) => "revolute",
            (_, 1) => "continuous",
            (_, 2) => "prismatic",
            _ => "fixed",
        };
        let axis = match Vector3::from(j.axis).norm() > 0.1 {
            true => j.axis,
            false => [0.0, 0.0, 1.0],
        };
        let (lo, range) = j.limits;
        let mimic = match (i, j.kind) {
            (0, _) => String::new(),
            (_, 4) => r#"<mimic joint="j0" multiplier="0.7" offset="0.1"/>"#.into(),
            _ => String::new(),
        };
        s += &format!(
            r#"<link name="l{}"/><joint name="j{i}" type="{kind}"><parent link="l{i}"/><child link="l{}"/>
            <origin xyz="{} {} {}" rpy="{} {} {}"/><axis xyz="{} {} {}"/>
            <limit lower="{lo}" upper="{}" effort="10" velocity="{}"/>{mimic}</joint>"#,
            i + 1,
            i + 1,
            j.xyz[0],
            j.xyz[1],
            j.xyz[2],
            j.rpy[0],
            j.rpy[1],
            j.rpy[2],
            axis[0],
            axis[1],
            axis[2],
            lo + range,
            j.velocity,
        );
    }
    s + "</robot>"
}

/// A random IK configuration.
fn config() -> impl Strategy<Value = (bool, bool, f64, f64, f64, usize)> {
    (
        any::<bool>(),
        any::<bool>(),
        0.0f64..0.1,
        0.0f64..0.1,
        0.001f64..0.1,
        1usize..6,
    )
}

/// Calls both IKs toward each target in turn from where the reference left the arm,
/// and compares every bit of the command and of the report.
fn same_bits(
    chain: &Chain,
    config: IkConfig,
    ws: &mut Workspace,
    start: Vec<f64>,
    targets: &[Frame],
    dt: f64,
) -> Result<(), TestCaseError> {
    let mut reference = Reference::new(chain, config.clone()).expect("a configuration");
    let mut ik = Ik::new(chain, config).expect("a configuration");
    let mut q = start;
    let mut out = vec![f64::NAN; q.len()];
    for target in targets {
        let want = reference.step(&q, target, dt);
        let got = ik.step_into(ws, &q, target, dt, &mut out);
        match (want, got) {
            (Ok(w), Ok(g)) => {
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(bits(&out), bits(&w.q), "the command");
                prop_assert_eq!(g.position_error.to_bits(), w.position_error.to_bits());
                prop_assert_eq!(g.orientation_error.to_bits(), w.orientation_error.to_bits());
                prop_assert_eq!(g.damping.to_bits(), w.damping.to_bits());
                prop_assert_eq!(
                    (g.iterations, g.clamped, g.velocity_limited, g.unreachable),
                    (w.iterations, w.clamped, w.velocity_limited, w.unreachable)
                );
                q = w.q;
            }
            (Err(w), Err(g)) => prop_assert_eq!(w, g),
            (w, g) => prop_assert!(false, "{w:?} but {g:?}"),
        }
    }
    prop_assert_eq!(ik.stats, reference.stats);
    Ok(())
}

/// `home`'s tool moved by `d` (m) and turned by `r` (rad about the base's axes).
fn moved(chain: &Chain, home: &[f64], d: [f64; 3], r: [f64; 3]) -> Frame {
    let mut f = chain.fk(home);
    f.p += Vector3::from(d);
    f.r = nalgebra::Rotation3::from_scaled_axis(Vector3::from(r)).into_inner() * f.r;
    f
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Random arms of 1 to 12 joints, random configurations and targets near and far.
    #[test]
    fn the_workspace_ik_gives_the_bits_of_the_ik_as_it_was(
        specs in prop::collection::vec(spec(), 1..12),
        (position_only, posture, gain, damping_max, threshold, iterations) in config(),
        start in prop::collection::vec(-3.5f64..3.5, 12),
        moves in prop::collection::vec((prop::array::uniform3(-0.5f64..0.5), prop::array::uniform3(-1.0f64..1.0)), 1..12),
        dt in prop_oneof![Just(1e-3), 1e-4f64..0.05],
    ) {
        let chain = Chain::from_urdf(&urdf(&specs), "l0", &format!("l{}", specs.len()))
            .expect("a serial arm");
        let n = chain.dof();
        let start = start[..n].to_vec();
        let config = IkConfig {
            position_only,
            posture: posture.then(|| start.iter().map(|x| 0.5 * x).collect()),
            posture_gain: gain,
            damping_max,
            singular_threshold: threshold,
            max_iterations: iterations,
            ..IkConfig::default()
        };
        let targets: Vec<Frame> = moves.iter().map(|(d, r)| moved(&chain, &start, *d, *r)).collect();
        // A workspace made for another arm: remade on its first call.
        let mut ws = Workspace::new(&Ik::new(&Chain::from_urdf(UR5, "base_link", "tool0").expect("ur5"), IkConfig::default()).expect("ik"));
        same_bits(&chain, config, &mut ws, start, &targets, dt)?;
    }
}

/// The shipped arms as a slave drives them: a target circling 5 cm at 1 Hz, sampled
/// at 1 kHz, then out of reach; 6 rows and 3; one workspace for all.
#[test]
fn the_panda_and_the_ur5_give_the_same_bits() {
    let arms = [
        (
            Chain::from_urdf(PANDA, "panda_link0", "panda_hand").expect("panda"),
            vec![0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
        ),
        (
            Chain::from_urdf(UR5, "base_link", "tool0").expect("ur5"),
            vec![0.0, -1.2, 1.4, -1.8, -1.2, 0.0],
        ),
    ];
    let mut ws = Workspace::default();
    for (chain, home) in &arms {
        for position_only in [false, true] {
            let mut targets: Vec<Frame> = (0..1500)
                .map(|k| {
                    let t = k as f64 * 1e-3 * std::f64::consts::TAU;
                    let d = [0.05 * t.cos() - 0.05, 0.05 * t.sin(), 0.0];
                    moved(chain, home, d, [0.0, 0.0, 0.2 * t.sin()])
                })
                .collect();
            targets.extend((0..300).map(|_| moved(chain, home, [1.5, 0.0, 0.5], [0.0; 3])));
            let config = IkConfig {
                position_only,
                posture: Some(home.clone()),
                ..IkConfig::default()
            };
            same_bits(chain, config, &mut ws, home.clone(), &targets, 1e-3).expect("same bits");
        }
    }
}

/// Refusals are the same: a wrong length, a non-finite joint or period.
#[test]
fn the_same_calls_are_refused() {
    let chain = Chain::from_urdf(UR5, "base_link", "tool0").expect("ur5");
    let home = vec![0.0, -1.2, 1.4, -1.8, -1.2, 0.0];
    let target = chain.fk(&home);
    let mut ws = Workspace::default();
    for (q, dt) in [
        (vec![0.0; 5], 1e-3),
        (vec![f64::NAN; 6], 1e-3),
        (home.clone(), 0.0),
        (home.clone(), f64::INFINITY),
    ] {
        let mut r = Reference::new(&chain, IkConfig::default()).expect("ik");
        let mut ik = Ik::new(&chain, IkConfig::default()).expect("ik");
        let mut out = vec![7.0; 6];
        let want = r.step(&q, &target, dt).expect_err("refused");
        let got = ik.step_into(&mut ws, &q, &target, dt, &mut out);
        assert_eq!(got.expect_err("refused"), want);
        assert_eq!(out, vec![7.0; 6], "the command untouched");
    }
    let mut ik = Ik::new(&chain, IkConfig::default()).expect("ik");
    let e = ik.step_into(&mut ws, &home, &target, 1e-3, &mut [0.0; 5]);
    assert!(e.expect_err("5 outputs").to_string().contains("ik command"));
}
