//! The paper's modules (FK-HMD/FK-HSD, KFF-HMD, FBF-HSD, IK-HSD) as RTL: their
//! constants (`kin_params.vh`) and their test vectors, both from the hybrid model's
//! kernels (`tactile_math::kernels`), so the hardware and the model share every
//! number and every rounding.
//!
//! A vector holds the inputs, the values at the module's stage boundaries (the TFBs'
//! sines and cosines, the Jacobian, IK's intermediates) and the outputs, as f32 bits.
//! The inputs: the paper's validation run (1,200 samples through all four), an even
//! sweep of the joint space (FK, KFF) or of a box around the workspace (IK), random
//! values in range, random bit patterns (every exponent, infinities, NaN), and edges.

use super::vectors::SplitMix;
use std::f32::consts::PI;
use tactile_math::arith::Trig;
use tactile_math::cordic::Cordic;
use tactile_math::geometry::{Geometry, Lengths};
use tactile_math::kernels::{self, IkStatus};
use tactile_math::validation::validation_inputs;

/// A module of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Module {
    /// Forward kinematics (FK-HMD and FK-HSD are the same module).
    Fk,
    /// Kinesthetic feedback force: tau = J^T F.
    Kff,
    /// Feedback force: F = h (obj - env).
    Fbf,
    /// Inverse kinematics.
    Ik,
}

fn hex(v: &[f32]) -> String {
    v.iter()
        .map(|x| format!("{:08x}", x.to_bits()))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `|angle| < 3 pi`: what the TFB's sin/cos takes (beyond it the RTL flags err).
fn in_tfb_range(t: [f32; 3], three_pi_up: u32) -> bool {
    t.iter().all(|a| a.to_bits() & 0x7fff_ffff < three_pi_up)
}

/// FK's line: angles, err, the six sines and cosines, x y z.
fn fk_line(g: &Lengths<f32>, c: &Cordic, t: [f32; 3], three_pi_up: u32) -> String {
    if !in_tfb_range(t, three_pi_up) {
        return format!("{} 1 {}", hex(&t), hex(&[0.0; 9]));
    }
    let (s, co) = Trig::<f32>::sin_cos3(c, t);
    let p = kernels::fk(g, c, t);
    format!(
        "{} 0 {} {}",
        hex(&t),
        hex(&[s[0], co[0], s[1], co[1], s[2], co[2]]),
        hex(&p)
    )
}

/// KFF's line: angles, force, err, sines and cosines, the Jacobian by rows, tau.
fn kff_line(g: &Lengths<f32>, c: &Cordic, t: [f32; 3], f: [f32; 3], top: u32) -> String {
    if !in_tfb_range(t, top) {
        return format!("{} {} 1 {}", hex(&t), hex(&f), hex(&[0.0; 18]));
    }
    let (s, co) = Trig::<f32>::sin_cos3(c, t);
    let j = kernels::jacobian(g, c, t);
    let tau = kernels::kff(g, c, t, f);
    let jf: Vec<f32> = j.iter().flatten().copied().collect();
    format!(
        "{} {} 0 {} {} {}",
        hex(&t),
        hex(&f),
        hex(&[s[0], co[0], s[1], co[1], s[2], co[2]]),
        hex(&jf),
        hex(&tau)
    )
}

/// FBF's line: obj, env, h, the differences, the force.
fn fbf_line(o: [f32; 3], e: [f32; 3], h: [f32; 3]) -> String {
    let d = [o[0] - e[0], o[1] - e[1], o[2] - e[2]];
    let f = kernels::fbf(o, e, h);
    format!(
        "{} {} {} {} {}",
        hex(&o),
        hex(&e),
        hex(&h),
        hex(&d),
        hex(&f)
    )
}

/// IK's line: the target, the status, every intermediate, the angles.
fn ik_line(g: &Lengths<f32>, c: &Cordic, p: [f32; 3]) -> String {
    let k = kernels::ik_taps(g, c, p);
    let status = match k.solution.status {
        IkStatus::Reachable => 0,
        IkStatus::Clamped => 1,
        IkStatus::Invalid => 2,
    };
    let taps = [
        k.shoulder[0],
        k.shoulder[1],
        k.shoulder[2],
        k.atan,
        k.rr2,
        k.big_r,
        k.r2,
        k.r,
        k.cos_gamma,
        k.gamma,
        k.beta,
        k.cos_alpha,
        k.alpha,
    ];
    format!(
        "{} {status} {} {}",
        hex(&p),
        hex(&taps),
        hex(&k.solution.theta)
    )
}

/// Random f32 bit patterns: every exponent, subnormals, infinities and NaN.
fn any3(rng: &mut SplitMix) -> [f32; 3] {
    let (a, b) = (rng.next(), rng.next());
    [a as u32, (a >> 32) as u32, b as u32].map(f32::from_bits)
}

fn uniform3(rng: &mut SplitMix, lo: f32, hi: f32) -> [f32; 3] {
    [0; 3].map(|_| lo + (hi - lo) * rng.unit() as f32)
}

/// An even grid of `n` points (at least one per axis) over `[lo, hi]^3`.
fn grid(n: usize, lo: [f32; 3], hi: [f32; 3]) -> Vec<[f32; 3]> {
    let per = ((n as f64).cbrt().floor() as usize).max(1);
    let at = |i: usize, k: usize| lo[k] + (hi[k] - lo[k]) * (i as f32 + 0.5) / per as f32;
    let mut v = Vec::with_capacity(per * per * per);
    for i in 0..per {
        for j in 0..per {
            for l in 0..per {
                v.push([at(i, 0), at(j, 1), at(l, 2)]);
            }
        }
    }
    v
}

/// Angle triples: edges, the paper's run, a sweep of [-pi, pi]^3, random in the TFB's
/// range and random bit patterns.
fn angles(geometry: &Geometry, count: usize, top: u32, rng: &mut SplitMix) -> Vec<[f32; 3]> {
    let limit = f32::from_bits(top - 1);
    let edge = [
        0.0,
        -0.0,
        f32::from_bits(1),
        PI / 2.0,
        -PI / 2.0,
        PI,
        -PI,
        limit,
        -limit,
        f32::from_bits(top),
    ];
    let mut v: Vec<[f32; 3]> = edge
        .iter()
        .map(|&a| [a, edge[(a.to_bits() % 7) as usize], -a])
        .collect();
    v.extend(
        validation_inputs(geometry)
            .iter()
            .map(|i| i.theta.map(|t| t as f32)),
    );
    v.extend(grid(count / 2, [-PI; 3], [PI; 3]));
    for i in 0..count - count / 2 {
        v.push(if i % 20 == 19 {
            // Beyond the TFB's range (err): any bit pattern, infinities and NaN too.
            any3(rng).map(|a| f32::from_bits(a.to_bits() | top))
        } else if i % 4 == 3 {
            any3(rng).map(|a| f32::from_bits((a.to_bits() % top) | (a.to_bits() & 0x8000_0000)))
        } else {
            uniform3(rng, -limit, limit)
        });
    }
    v
}

/// Targets for IK: edges (the shoulder, full stretch, far away, non-finite), the
/// paper's run, a sweep of a box twice the reach, random in it and random bit patterns.
fn targets(
    geometry: &Geometry,
    g: &Lengths<f32>,
    count: usize,
    rng: &mut SplitMix,
) -> Vec<[f32; 3]> {
    let reach = g.l1 + g.l2;
    let centre = [0.0, g.l3, -g.l4];
    let mut v = vec![
        centre,
        [0.0, g.l3 + reach, -g.l4],
        [reach, g.l3, -g.l4],
        [0.0, g.l3, -g.l4 + reach * 1.000_001],
        [1e30, 1e30, -1e30],
        [f32::MAX, -f32::MAX, f32::MAX],
        [f32::NAN, 0.0, 0.0],
        [0.0, f32::INFINITY, 0.0],
        [0.0, 0.0, f32::NEG_INFINITY],
        [f32::from_bits(1), g.l3, -g.l4],
    ];
    v.extend(
        validation_inputs(geometry)
            .iter()
            .map(|i| i.position.map(|p| p as f32)),
    );
    // The stretched arm: targets at the reach and a few ulps either side of it, in 40
    // directions, so cos alpha lands at -1, inside clamp_unit's tolerance band
    // (1, 1 + 16 eps] and beyond it.
    for i in 0..40 {
        let (a, b) = (i as f32 * 0.61, i as f32 * 0.37);
        let dir = [a.sin() * b.cos(), a.cos(), a.sin() * b.sin()];
        for s in [
            1.0 - 4e-7,
            1.0,
            1.0 + 1e-7,
            1.0 + 4e-7,
            1.0 + 1e-6,
            1.0 + 4e-6,
        ] {
            let r = reach * s;
            v.push([dir[0] * r, centre[1] + dir[1] * r, centre[2] + dir[2] * r]);
        }
    }
    let lo = centre.map(|c| c - 1.2 * reach);
    let hi = centre.map(|c| c + 1.2 * reach);
    v.extend(grid(count / 2, lo, hi));
    for i in 0..count - count / 2 {
        v.push(if i % 4 == 3 {
            any3(rng)
        } else {
            let u = uniform3(rng, -1.2 * reach, 1.2 * reach);
            [u[0] + centre[0], u[1] + centre[1], u[2] + centre[2]]
        });
    }
    v
}

/// Forces for KFF (newtons) and stiffnesses for FBF: mostly device-like, some any.
fn forces(rng: &mut SplitMix, i: usize, lo: f32, hi: f32) -> [f32; 3] {
    if i % 8 == 7 {
        any3(rng)
    } else {
        uniform3(rng, lo, hi)
    }
}

/// Writes the vector file for `module` to `out`, a line at a time as each is made;
/// returns its number of samples.
#[allow(clippy::too_many_arguments)] // the block, its model and the file: one call site
pub fn kin_vectors(
    module: Module,
    name: &str,
    cordic: &Cordic,
    three_pi_up: u32,
    geometry: &Geometry,
    count: usize,
    seed: u64,
    out: &mut dyn std::io::Write,
) -> std::io::Result<usize> {
    let g: Lengths<f32> = geometry.lengths();
    let mut rng = SplitMix(seed);
    let cfg = cordic.config();
    writeln!(
        out,
        "// tactile hdl vectors: {name} for [s{}.{}], {} iterations, {:?}; seed {seed}",
        cfg.word, cfg.frac, cfg.iterations, cfg.rounding
    )?;
    let mut n = 0;
    let mut line = |text: String| {
        n += 1;
        writeln!(out, "{text}")
    };
    match module {
        Module::Fk => {
            for t in angles(geometry, count, three_pi_up, &mut rng) {
                line(fk_line(&g, cordic, t, three_pi_up))?;
            }
        }
        Module::Kff => {
            let runs = validation_inputs(geometry);
            let t = angles(geometry, count, three_pi_up, &mut rng);
            for (i, t) in t.into_iter().enumerate() {
                // The paper's run with its own forces, the rest with random ones.
                let f = match runs.iter().find(|r| r.theta.map(|a| a as f32) == t) {
                    Some(r) => r.force.map(|f| f as f32),
                    None => forces(&mut rng, i, -5.0, 5.0),
                };
                line(kff_line(&g, cordic, t, f, three_pi_up))?;
            }
        }
        Module::Fbf => {
            for r in validation_inputs(geometry) {
                let h = [tactile_math::validation::SPRING_N_PER_M as f32; 3];
                line(fbf_line(
                    r.home.map(|p| p as f32),
                    r.position.map(|p| p as f32),
                    h,
                ))?;
            }
            for i in 0..count {
                let o = forces(&mut rng, i, -0.4, 0.4);
                let e = forces(&mut rng, i + 1, -0.4, 0.4);
                let h = forces(&mut rng, i + 2, 0.0, 5000.0);
                line(fbf_line(o, e, h))?;
            }
        }
        Module::Ik => {
            for p in targets(geometry, &g, count, &mut rng) {
                line(ik_line(&g, cordic, p))?;
            }
        }
    }
    Ok(n)
}
