//! Time per call of each of the paper's modules simulated by Verilator, beside the
//! hybrid model's, in one run (compare them as ratios: the machines are shared).
//!
//! Run with `cargo bench -p tactile-rtl --features verilator --bench modules`; the
//! simulated pipeline is `TACTILE_RTL_PIPELINE` at build time (`module` by default).
//! Each call cycles through 1024 inputs of the paper's validation run. Without the
//! simulation in the build (no feature, or no Verilator) it says so and measures
//! nothing.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use tactile_math::arith::ArithKind;
use tactile_math::cordic::CordicConfig;
use tactile_math::engine::Engine;
use tactile_math::geometry::Geometry;
use tactile_math::validation::validation_inputs;

fn engine(kind: ArithKind) -> Option<Engine> {
    tactile_rtl::engine(kind, Geometry::PAPER, CordicConfig::S16_13).ok()
}

fn modules(c: &mut Criterion) {
    let Some(rtl) = engine(ArithKind::Rtl) else {
        eprintln!("SKIPPED: this build does not simulate the RTL (--features verilator, and Verilator on PATH)");
        return;
    };
    let Some(hybrid) = engine(ArithKind::Hybrid) else {
        return;
    };
    let inp: Vec<_> = validation_inputs(&Geometry::PAPER)
        .into_iter()
        .cycle()
        .take(1024)
        .collect();
    let mask = 1023;
    let mut group = c.benchmark_group("module_call");
    for (name, e) in [("hybrid", &hybrid), ("rtl", &rtl)] {
        let mut i = 0usize;
        group.bench_function(BenchmarkId::new("fk", name), |b| {
            b.iter(|| {
                i = (i + 1) & mask;
                e.fk(black_box(inp[i].theta))
            })
        });
        group.bench_function(BenchmarkId::new("kff", name), |b| {
            b.iter(|| {
                i = (i + 1) & mask;
                e.kff(black_box(inp[i].theta), black_box(inp[i].force))
            })
        });
        group.bench_function(BenchmarkId::new("ik", name), |b| {
            b.iter(|| {
                i = (i + 1) & mask;
                e.ik(black_box(inp[i].position))
            })
        });
        group.bench_function(BenchmarkId::new("fbf", name), |b| {
            b.iter(|| {
                i = (i + 1) & mask;
                e.fbf(
                    black_box(inp[i].home),
                    black_box(inp[i].position),
                    [12.0; 3],
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, modules);
criterion_main!(benches);
