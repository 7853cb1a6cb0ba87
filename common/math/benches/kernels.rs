//! Time per call and batch throughput of each module in each arithmetic.
//!
//! Run with `cargo bench -p tactile-math --bench kernels`. Per-call benchmarks cycle
//! through 1024 distinct inputs from the paper's validation run so neither the branch
//! predictor nor the optimiser sees one constant input; batch benchmarks run the
//! structure-of-arrays kernels over 4096 samples and report samples per second.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use tactile_math::arith::{Real, StdTrig, Trig};
use tactile_math::cordic::{Cordic, CordicConfig};
use tactile_math::geometry::{Geometry, Lengths};
use tactile_math::kernels::{self, Columns, ColumnsMut, IkStatus};
use tactile_math::validation::{validation_inputs, ValidationInput};

const BATCH: usize = 4096;

fn inputs() -> Vec<ValidationInput> {
    let v = validation_inputs(&Geometry::PAPER);
    // 4096 samples: the 1200-sample run repeated.
    v.iter().cycle().take(BATCH).copied().collect()
}

fn per_call_group<R: Real, T: Trig<R>>(c: &mut Criterion, arith: &str, trig: &T) {
    let g: Lengths<R> = Geometry::PAPER.lengths();
    let inp = inputs();
    let cv = |v: [f64; 3]| v.map(R::from_f64);
    let theta: Vec<[R; 3]> = inp.iter().map(|i| cv(i.theta)).collect();
    let pos: Vec<[R; 3]> = inp.iter().map(|i| cv(i.position)).collect();
    let force: Vec<[R; 3]> = inp.iter().map(|i| cv(i.force)).collect();
    let home = cv(inp[0].home);
    let h = [R::from_f64(12.0); 3];
    let mut group = c.benchmark_group("per_call");
    let mask = 1023;
    group.bench_function(BenchmarkId::new("fk", arith), |b| {
        let mut i = 0usize;
        b.iter(|| {
            i = (i + 1) & mask;
            kernels::fk(&g, trig, black_box(theta[i]))
        })
    });
    group.bench_function(BenchmarkId::new("ik", arith), |b| {
        let mut i = 0usize;
        b.iter(|| {
            i = (i + 1) & mask;
            kernels::ik(&g, trig, black_box(pos[i]))
        })
    });
    group.bench_function(BenchmarkId::new("kff", arith), |b| {
        let mut i = 0usize;
        b.iter(|| {
            i = (i + 1) & mask;
            kernels::kff(&g, trig, black_box(theta[i]), black_box(force[i]))
        })
    });
    group.bench_function(BenchmarkId::new("fbf", arith), |b| {
        let mut i = 0usize;
        b.iter(|| {
            i = (i + 1) & mask;
            kernels::fbf(black_box(home), black_box(pos[i]), black_box(h))
        })
    });
    group.finish();
}

struct Soa<R> {
    cols: [Vec<R>; 9],
}

fn soa<R: Real>(inp: &[ValidationInput]) -> Soa<R> {
    let col = |f: &dyn Fn(&ValidationInput) -> f64| -> Vec<R> {
        inp.iter().map(|i| R::from_f64(f(i))).collect()
    };
    Soa {
        cols: [
            col(&|i| i.theta[0]),
            col(&|i| i.theta[1]),
            col(&|i| i.theta[2]),
            col(&|i| i.position[0]),
            col(&|i| i.position[1]),
            col(&|i| i.position[2]),
            col(&|i| i.force[0]),
            col(&|i| i.force[1]),
            col(&|i| i.force[2]),
        ],
    }
}

fn batch_group<R: Real, T: Trig<R>>(c: &mut Criterion, arith: &str, trig: &T) {
    let g: Lengths<R> = Geometry::PAPER.lengths();
    let inp = inputs();
    let s = soa::<R>(&inp);
    let [t1, t2, t3, px, py, pz, fx, fy, fz] = &s.cols;
    let home: Vec<Vec<R>> = (0..3)
        .map(|k| vec![R::from_f64(inp[0].home[k]); BATCH])
        .collect();
    let (mut o1, mut o2, mut o3) = (
        vec![R::ZERO; BATCH],
        vec![R::ZERO; BATCH],
        vec![R::ZERO; BATCH],
    );
    let mut status = vec![IkStatus::Invalid; BATCH];
    let h = [R::from_f64(12.0); 3];
    let mut group = c.benchmark_group("batch");
    group.throughput(Throughput::Elements(BATCH as u64));
    group.bench_function(BenchmarkId::new("fk", arith), |b| {
        b.iter(|| {
            kernels::fk_batch(
                &g,
                trig,
                Columns {
                    a: t1,
                    b: t2,
                    c: t3,
                },
                ColumnsMut {
                    a: &mut o1,
                    b: &mut o2,
                    c: &mut o3,
                },
            );
            black_box(&o1);
        })
    });
    group.bench_function(BenchmarkId::new("ik", arith), |b| {
        b.iter(|| {
            kernels::ik_batch(
                &g,
                trig,
                Columns {
                    a: px,
                    b: py,
                    c: pz,
                },
                ColumnsMut {
                    a: &mut o1,
                    b: &mut o2,
                    c: &mut o3,
                },
                &mut status,
            );
            black_box(&o1);
        })
    });
    group.bench_function(BenchmarkId::new("kff", arith), |b| {
        b.iter(|| {
            kernels::kff_batch(
                &g,
                trig,
                Columns {
                    a: t1,
                    b: t2,
                    c: t3,
                },
                Columns {
                    a: fx,
                    b: fy,
                    c: fz,
                },
                ColumnsMut {
                    a: &mut o1,
                    b: &mut o2,
                    c: &mut o3,
                },
            );
            black_box(&o1);
        })
    });
    group.bench_function(BenchmarkId::new("fbf", arith), |b| {
        b.iter(|| {
            kernels::fbf_batch(
                Columns {
                    a: &home[0],
                    b: &home[1],
                    c: &home[2],
                },
                Columns {
                    a: px,
                    b: py,
                    c: pz,
                },
                h,
                ColumnsMut {
                    a: &mut o1,
                    b: &mut o2,
                    c: &mut o3,
                },
            );
            black_box(&o1);
        })
    });
    group.finish();
}

fn benches(c: &mut Criterion) {
    let cordic = Cordic::new(CordicConfig::S16_13).expect("default format is valid");
    per_call_group::<f64, _>(c, "f64", &StdTrig);
    per_call_group::<f32, _>(c, "f32", &StdTrig);
    per_call_group::<f32, _>(c, "hybrid", &cordic);
    batch_group::<f64, _>(c, "f64", &StdTrig);
    batch_group::<f32, _>(c, "f32", &StdTrig);
    batch_group::<f32, _>(c, "hybrid", &cordic);
}

criterion_group! {
    name = kernel_benches;
    config = Criterion::default()
        .warm_up_time(std::time::Duration::from_millis(500))
        .measurement_time(std::time::Duration::from_secs(2));
    targets = benches
}
criterion_main!(kernel_benches);
