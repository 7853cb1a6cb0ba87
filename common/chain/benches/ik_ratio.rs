//! The IK into its workspace against the IK as it was before it (issue 66; the test's
//! reference), interleaved: rounds of 1,000 calls of one, then 1,000 of the other,
//! each following the same target circling 5 cm at 1 Hz, sampled at 1 kHz, from its
//! own last answer (the two answers are the same bit for bit). A shared machine's
//! load drifts over seconds, and criterion times one function after the other: here
//! it weighs on both alike. Prints, per arm, the median time per call of each and the
//! median of the rounds' ratios.
//!
//! Run with `cargo bench -p tactile-chain --bench ik_ratio`.

#[path = "../tests/ik_reference/mod.rs"]
mod ik_reference;

use nalgebra::Vector3;
use std::hint::black_box;
use std::time::Instant;
use tactile_chain::ik::Workspace;
use tactile_chain::{Chain, Frame, Ik, IkConfig};

const PANDA: &str = include_str!("../../../deploy/robots/panda.urdf");
const UR5: &str = include_str!("../../../deploy/robots/ur5_robot.urdf");
const ROUNDS: usize = 300;
const CALLS: u64 = 1000;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let arms = [
        (
            "panda",
            Chain::from_urdf(PANDA, "panda_link0", "panda_hand").expect("panda"),
            vec![0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
        ),
        (
            "ur5",
            Chain::from_urdf(UR5, "base_link", "tool0").expect("ur5"),
            vec![0.0, -1.2, 1.4, -1.8, -1.2, 0.0],
        ),
    ];
    for (name, arm, q) in arms {
        let home = arm.fk(&q);
        let circle = |k: u64| {
            let t = (k % 1000) as f64 * 1e-3 * std::f64::consts::TAU;
            let mut target: Frame = home;
            target.p += Vector3::new(0.05 * t.cos() - 0.05, 0.05 * t.sin(), 0.0);
            target
        };
        let mut ik = Ik::new(&arm, IkConfig::default()).expect("ik");
        let mut ws = Workspace::new(&ik);
        let mut reference = ik_reference::Reference::new(&arm, IkConfig::default()).expect("ik");
        let (mut now, mut next, mut was) = (q.clone(), q.clone(), q.clone());
        let (mut new_ns, mut old_ns, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
        for round in 0..ROUNDS as u64 {
            let t = Instant::now();
            for k in round * CALLS..(round + 1) * CALLS {
                ik.step_into(&mut ws, &now, black_box(&circle(k)), 1e-3, &mut next)
                    .expect("step");
                std::mem::swap(&mut now, &mut next);
            }
            let new = t.elapsed().as_nanos() as f64 / CALLS as f64;
            let t = Instant::now();
            for k in round * CALLS..(round + 1) * CALLS {
                was = reference
                    .step(&was, black_box(&circle(k)), 1e-3)
                    .expect("step")
                    .q;
            }
            let old = t.elapsed().as_nanos() as f64 / CALLS as f64;
            assert_eq!(now, was, "the same answers");
            new_ns.push(new);
            old_ns.push(old);
            ratios.push(new / old);
        }
        println!(
            "{name}: ik_step {:.0} ns, as it was {:.0} ns, ratio {:.2} (medians of {ROUNDS} rounds of {CALLS} calls each)",
            median(new_ns),
            median(old_ns),
            median(ratios)
        );
    }
}
