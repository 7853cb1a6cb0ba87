//! Time per call of the chain's kernels on a 7-joint arm (the Panda) and a 6-joint
//! one (the UR5): FK, the Jacobian, RNEA, ABA (allocating, and into a workspace made
//! once), and the IK following a moving target as a slave does every period (the
//! paper gives each side 37.5 us): into a workspace made once (`ik_step`), and as it
//! was before its workspace (`ik_step_reference`, the test's reference, issue 66), in
//! the same run.
//!
//! Run with `cargo bench -p tactile-chain --bench chain`.

mod arms;
#[path = "../tests/ik_reference/mod.rs"]
mod ik_reference;

use arms::{arms, circle};
use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::Matrix6xX;
use tactile_chain::dynamics::{Workspace, EARTH};
use tactile_chain::ik::Workspace as IkWorkspace;
use tactile_chain::{Dynamics, Ik, IkConfig};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("chain");
    for (name, arm, q) in arms() {
        let dynamics = Dynamics::new(&arm, EARTH).expect("dynamics");
        let zero = vec![0.0; q.len()];
        let mut jac = Matrix6xX::zeros(arm.dof());
        g.bench_function(BenchmarkId::new("fk", name), |b| {
            b.iter(|| arm.fk(black_box(&q)))
        });
        g.bench_function(BenchmarkId::new("jacobian", name), |b| {
            b.iter(|| arm.jacobian(black_box(&q), &mut jac))
        });
        g.bench_function(BenchmarkId::new("rnea", name), |b| {
            b.iter(|| dynamics.rnea(black_box(&q), &zero, &zero))
        });
        g.bench_function(BenchmarkId::new("aba", name), |b| {
            b.iter(|| dynamics.aba(black_box(&q), &zero, &zero))
        });
        // The same two with a workspace made once, as a simulation's inner loop calls
        // them: the difference is the allocations.
        let mut ws = Workspace::new(&arm);
        let mut out = vec![0.0; q.len()];
        g.bench_function(BenchmarkId::new("rnea_into", name), |b| {
            b.iter(|| dynamics.rnea_into(&mut ws, black_box(&q), &zero, &zero, &mut out))
        });
        g.bench_function(BenchmarkId::new("aba_into", name), |b| {
            b.iter(|| dynamics.aba_into(&mut ws, black_box(&q), &zero, &zero, &mut out))
        });
        // The target circles 5 cm around the start at 1 Hz, sampled at 1 kHz: each
        // call starts from the last one's answer, as the slave's does.
        let home = arm.fk(&q);
        let mut ik = Ik::new(&arm, IkConfig::default()).expect("ik");
        let mut ws = IkWorkspace::new(&ik);
        let (mut now, mut next, mut k) = (q.clone(), q.clone(), 0u64);
        g.bench_function(BenchmarkId::new("ik_step", name), |b| {
            b.iter(|| {
                k += 1;
                ik.step_into(&mut ws, &now, black_box(&circle(&home, k)), 1e-3, &mut next)
                    .expect("step");
                std::mem::swap(&mut now, &mut next);
            })
        });
        eprintln!("{name}: {:?}", ik.stats);
        let mut reference = ik_reference::Reference::new(&arm, IkConfig::default()).expect("ik");
        let (mut now, mut k) = (q.clone(), 0u64);
        g.bench_function(BenchmarkId::new("ik_step_reference", name), |b| {
            b.iter(|| {
                k += 1;
                now = reference
                    .step(&now, black_box(&circle(&home, k)), 1e-3)
                    .expect("step")
                    .q;
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
