//! The IK into its workspace against the IK as it was before it (issue 66; the test's
//! reference), interleaved: rounds of 1,000 calls of one, then 1,000 of the other,
//! each following the same target circling 5 cm at 1 Hz, sampled at 1 kHz, from its
//! own last answer (the two answers are the same bit for bit). A shared machine's
//! load drifts over seconds, and criterion times one function after the other: here
//! it weighs on both alike. Prints, per arm, the median time per call of each and the
//! median of the rounds' ratios.
//!
//! Run with `cargo bench -p tactile-chain --bench ik_ratio`.

mod arms;
#[path = "../tests/ik_reference/mod.rs"]
mod ik_reference;

use arms::{arms, circle};
use std::hint::black_box;
use std::time::Instant;
use tactile_chain::ik::Workspace;
use tactile_chain::{Ik, IkConfig};

const ROUNDS: usize = 300;
const CALLS: u64 = 1000;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    for (name, arm, q) in arms() {
        let home = arm.fk(&q);
        let mut ik = Ik::new(&arm, IkConfig::default()).expect("ik");
        let mut ws = Workspace::new(&ik);
        let mut reference = ik_reference::Reference::new(&arm, IkConfig::default()).expect("ik");
        let (mut now, mut next, mut was) = (q.clone(), q.clone(), q.clone());
        let (mut new_ns, mut old_ns, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
        for round in 0..ROUNDS as u64 {
            let t = Instant::now();
            for k in round * CALLS..(round + 1) * CALLS {
                ik.step_into(&mut ws, &now, black_box(&circle(&home, k)), 1e-3, &mut next)
                    .expect("step");
                std::mem::swap(&mut now, &mut next);
            }
            let new = t.elapsed().as_nanos() as f64 / CALLS as f64;
            let t = Instant::now();
            for k in round * CALLS..(round + 1) * CALLS {
                was = reference
                    .step(&was, black_box(&circle(&home, k)), 1e-3)
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
