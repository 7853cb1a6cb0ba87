//! The IK on the Panda (7 joints, redundant) and the UR5 (6, a wrist singularity):
//! convergence, the limits per call, damping at the singularity, unreachable targets
//! counted, the posture term moving only the null space.

use nalgebra::{DMatrix, Matrix6xX, SymmetricEigen, Vector3};
use proptest::prelude::*;
use tactile_chain::{Chain, Frame, Ik, IkConfig};

const PANDA: &str = include_str!("../../../deploy/robots/panda.urdf");
const UR5: &str = include_str!("../../../deploy/robots/ur5_robot.urdf");
const DT: f64 = 0.001;

fn panda() -> Chain {
    Chain::from_urdf(PANDA, "panda_link0", "panda_hand").expect("the Panda")
}

fn ur5() -> Chain {
    Chain::from_urdf(UR5, "base_link", "tool0").expect("the UR5")
}

/// The Panda's ready pose.
const READY: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

/// Steps `calls` times toward `target`, checking every command against the limits.
fn follow(ik: &mut Ik, mut q: Vec<f64>, target: &Frame, calls: usize) -> Vec<f64> {
    for _ in 0..calls {
        let (next, _) = ik.step(&q, target, DT).expect("a step");
        for ((a, b), d) in q.iter().zip(&next).zip(&ik.chain().dofs) {
            assert!(
                (b - a).abs() <= d.velocity * DT * (1.0 + 1e-9),
                "{}: {a} -> {b}",
                d.name
            );
            assert!(
                (d.lower..=d.upper).contains(b),
                "{}: {b} out of its limits",
                d.name
            );
        }
        q = next;
    }
    q
}

fn errors(c: &Chain, q: &[f64], target: &Frame) -> (f64, f64) {
    let tip = c.fk(q);
    let r = tactile_chain::spatial::log_rotation(&(target.r * tip.r.transpose()));
    ((target.p - tip.p).norm(), r.norm())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A reachable target 0.1 rad per joint away is reached to 1 um and 10 urad
    /// within 200 ms, never faster than the velocity limits allow.
    #[test]
    fn the_panda_reaches_a_reachable_pose(d in prop::array::uniform7(-0.1f64..0.1)) {
        let c = panda();
        let goal: Vec<f64> = READY.iter().zip(d).map(|(a, b)| a + b).collect();
        let target = c.fk(&goal);
        let mut ik = Ik::new(&c, IkConfig::default()).expect("ik");
        let q = follow(&mut ik, READY.to_vec(), &target, 200);
        let (ep, er) = errors(&c, &q, &target);
        prop_assert!(ep < 1e-6 && er < 1e-5, "{ep:e} m, {er:e} rad");
        prop_assert_eq!(ik.stats.unreachable, 0);
    }
}

#[test]
fn a_far_target_moves_at_the_velocity_limit_and_never_jumps() {
    let c = panda();
    let mut ik = Ik::new(&c, IkConfig::default()).expect("ik");
    let mut target = c.fk(&READY);
    target.p += Vector3::new(0.2, -0.2, -0.1);
    let q = follow(&mut ik, READY.to_vec(), &target, 2000);
    assert!(ik.stats.velocity_limited > 0, "{:?}", ik.stats);
    let (ep, er) = errors(&c, &q, &target);
    assert!(ep < 1e-6 && er < 1e-5, "{ep:e} m, {er:e} rad");
}

#[test]
fn a_target_out_of_reach_is_counted_and_the_arm_stays_within_its_limits() {
    let c = panda();
    let mut ik = Ik::new(&c, IkConfig::default()).expect("ik");
    let mut target = c.fk(&READY);
    target.p = Vector3::new(1.5, 0.0, 0.5);
    follow(&mut ik, READY.to_vec(), &target, 3000);
    assert!(ik.stats.unreachable > 100, "{:?}", ik.stats);
    assert!(
        ik.stats.clamped > 0,
        "stretching out meets a limit: {:?}",
        ik.stats
    );
}

/// The direction the Panda's joints can move at `q` without moving the hand.
fn self_motion(c: &Chain, q: &[f64]) -> Vec<f64> {
    let mut jac = Matrix6xX::zeros(7);
    c.jacobian(q, &mut jac);
    let j = DMatrix::from_fn(6, 7, |i, k| jac[(i, k)]);
    // The null space of J is the kernel of J^T J: its eigenvector of eigenvalue 0.
    let e = SymmetricEigen::new(j.transpose() * j);
    let k = e.eigenvalues.imin();
    e.eigenvectors.column(k).iter().copied().collect()
}

#[test]
fn the_posture_term_moves_the_elbow_and_not_the_hand() {
    let c = panda();
    // A rest posture along the arm's self-motion from the ready pose.
    let dir = self_motion(&c, &READY);
    let rest: Vec<f64> = READY.iter().zip(&dir).map(|(a, d)| a + 0.3 * d).collect();
    let config = IkConfig {
        posture: Some(rest.clone()),
        posture_gain: 0.05,
        ..IkConfig::default()
    };
    let mut ik = Ik::new(&c, config).expect("ik");
    let target = c.fk(&READY);
    let gap = |q: &[f64]| {
        q.iter()
            .zip(&rest)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let q = follow(&mut ik, READY.to_vec(), &target, 1000);
    let (ep, er) = errors(&c, &q, &target);
    assert!(
        ep < 1e-6 && er < 1e-5,
        "the hand held: {ep:e} m, {er:e} rad"
    );
    assert!(
        gap(&q) < 0.1 * gap(&READY),
        "the elbow went to rest: {} -> {}",
        gap(&READY),
        gap(&q)
    );
}

#[test]
fn through_the_ur5s_wrist_singularity_the_damping_rises_and_nothing_jumps() {
    let c = ur5();
    let mut ik = Ik::new(&c, IkConfig::default()).expect("ik");
    // wrist_2 at zero lines wrist_1 and wrist_3 up: a target path through it.
    let start = vec![0.0, -1.2, 1.4, -1.8, 0.3, 0.0];
    let through = vec![0.0, -1.2, 1.4, -1.8, -0.3, 0.0];
    let mut q = start.clone();
    for k in 0..=400 {
        let s = k as f64 / 400.0;
        let goal: Vec<f64> = start
            .iter()
            .zip(&through)
            .map(|(a, b)| a + s * (b - a))
            .collect();
        q = follow(&mut ik, q, &c.fk(&goal), 1);
    }
    q = follow(&mut ik, q, &c.fk(&through), 500);
    assert!(ik.stats.damped > 0, "the damping rose: {:?}", ik.stats);
    let (ep, _) = errors(&c, &q, &c.fk(&through));
    assert!(ep < 1e-4, "and the target was met past it: {ep:e} m");
}

#[test]
fn a_bad_configuration_names_its_field() {
    let c = panda();
    let bad = IkConfig {
        posture: Some(vec![0.0; 3]),
        ..IkConfig::default()
    };
    let e = Ik::new(&c, bad)
        .expect_err("three values for seven joints")
        .to_string();
    assert!(
        e.contains("posture") && e.contains("3 values") && e.contains("7 joints"),
        "{e}"
    );
    let e = Ik::new(
        &c,
        IkConfig {
            damping_max: -1.0,
            ..IkConfig::default()
        },
    )
    .expect_err("negative")
    .to_string();
    assert!(e.contains("damping_max"), "{e}");
}
