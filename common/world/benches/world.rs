//! The physics world's step: 5, 10, 20 and 40 dynamic bodies resting and pushed on a
//! static 10,000-triangle mesh, with the tool pushing through them, at the loop's
//! 1 kHz with the default 4 substeps.
//!
//! Run with `cargo bench -p tactile-world --bench world`. Besides criterion's mean,
//! each size prints the percentiles of 5,000 single steps timed one by one (the
//! issue's bound is on the p99 of the step for 20 bodies and the mesh).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::fmt::Write as _;
use std::time::Instant;
use tactile_world::mesh::{to_obj, Mesh};
use tactile_world::{PhysicsWorld, Pose, ToolState, World};

const DT: f64 = 1e-3;

/// A 1 m x 0.5 m floor of 100 x 50 cells, 10,000 triangles, gently waved (0.5 mm).
fn floor() -> Mesh {
    let (nx, ny) = (100usize, 50usize);
    let mut vertices = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let (x, y) = (i as f64 * 0.01 - 0.5, j as f64 * 0.01 - 0.25);
            vertices.push([x, y, 0.0005 * (x * 40.0).sin() * (y * 40.0).cos()]);
        }
    }
    let at = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Mesh {
        vertices,
        triangles,
    }
}

/// The world: `bodies` boxes and balls resting on the mesh (`on_mesh`), or on a box
/// table with the mesh beside them as a fixture (under the table, touching nothing).
fn scene(bodies: usize, dir: &std::path::Path, on_mesh: bool) -> PhysicsWorld {
    let path = dir.join("floor.obj");
    std::fs::write(&path, to_obj(&floor())).expect("floor written");
    let mut text = format!(
        "[environment]\nengine = \"physics\"\n[[environment.bodies]]\nname = \"floor\"\nshape = {{ type = \"mesh\", file = \"{}\" }}\nposition = [0.0, 0.0, {}]\n",
        path.display(),
        if on_mesh { 0.0 } else { -0.1 }
    );
    if !on_mesh {
        text.push_str("[[environment.bodies]]\nname = \"table\"\nshape = { type = \"box\", half_extents = [0.5, 0.25, 0.01] }\nposition = [0.0, 0.0, -0.01]\n");
    }
    for k in 0..bodies {
        let (i, j) = (k % 10, k / 10);
        let shape = if k % 2 == 0 {
            "{ type = \"box\", half_extents = [0.015, 0.015, 0.015] }"
        } else {
            "{ type = \"sphere\", radius = 0.015 }"
        };
        let _ = write!(
            text,
            "[[environment.bodies]]\nname = \"b{k}\"\nkind = \"dynamic\"\nshape = {shape}\nposition = [{}, {}, 0.016]\nmass = 0.1\n",
            -0.3 + 0.05 * i as f64,
            -0.1 + 0.05 * j as f64
        );
    }
    let s = tactile_scenario::Scenario::from_toml_str(&text).expect("scene");
    PhysicsWorld::new(&s.environment, dir, &[], DT).expect("world")
}

/// The tool sweeping along x through the first row of bodies at 0.1 m/s.
fn tool(k: usize) -> ToolState {
    let t = k as f64 * DT;
    ToolState {
        pose: Pose {
            position: [-0.4 + 0.1 * (t % 6.0), -0.1, 0.02],
            ..Pose::default()
        },
        velocity: [0.1, 0.0, 0.0],
        ..ToolState::default()
    }
}

fn percentiles(bodies: usize, dir: &std::path::Path, on_mesh: bool) {
    let mut w = scene(bodies, dir, on_mesh);
    for k in 0..1000 {
        w.step(&tool(k), &[], DT);
    }
    let mut ns: Vec<u64> = (1000..6000)
        .map(|k| {
            let t0 = Instant::now();
            w.step(&tool(k), &[], DT);
            t0.elapsed().as_nanos() as u64
        })
        .collect();
    ns.sort_unstable();
    let p = |q: f64| ns[((ns.len() - 1) as f64 * q) as usize] as f64 / 1e3;
    eprintln!(
        "world step, {bodies} dynamic bodies {} the 10,000-triangle mesh: p50 {:.1} us, p99 {:.1} us, max {:.1} us (5,000 steps, events {:?})",
        if on_mesh { "on" } else { "on a table beside" },
        p(0.5),
        p(0.99),
        p(1.0),
        w.counters()
    );
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temp dir");
    for on_mesh in [true, false] {
        for n in [5, 10, 20, 40] {
            percentiles(n, dir.path(), on_mesh);
        }
    }
    let mut g = c.benchmark_group("world_step");
    for n in [5, 10, 20, 40] {
        let mut w = scene(n, dir.path(), true);
        let mut k = 0usize;
        g.bench_function(BenchmarkId::new("bodies", n), |b| {
            b.iter(|| {
                k += 1;
                w.step(&tool(k), &[], DT).wrench[0]
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
