//! Property tests of the kernels: closed forms, IK after FK, the Jacobian against
//! central differences, the paper's waypoints, and batch against scalar.

use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use tactile_math::arith::{ArithKind, StdTrig};
use tactile_math::cordic::{Cordic, CordicConfig};
use tactile_math::engine::Engine;
use tactile_math::geometry::{Geometry, Lengths};
use tactile_math::kernels::{self, Columns, ColumnsMut, IkStatus};
use tactile_math::validation::WAYPOINTS;

const G: Geometry = Geometry::PAPER;

fn engine(kind: ArithKind) -> Engine {
    Engine::new(kind, G, CordicConfig::S16_13).expect("default format is valid")
}

/// The paper's FK equations, written out independently of the kernel.
fn fk_closed(g: &Geometry, t: [f64; 3]) -> [f64; 3] {
    let (l1, l2, l3, l4) = (g.l1, g.l2, g.l3, g.l4());
    [
        -t[0].sin() * (l2 * t[2].sin() + l1 * t[1].cos()),
        -l2 * t[2].cos() + l1 * t[1].sin() + l3,
        l2 * t[0].cos() * t[2].sin() + l1 * t[0].cos() * t[1].cos() - l4,
    ]
}

/// The paper's Jacobian elements as a nalgebra matrix.
fn jacobian_closed(g: &Geometry, t: [f64; 3]) -> Matrix3<f64> {
    let (l1, l2) = (g.l1, g.l2);
    let (s1, c1, s2, c2, s3, c3) = (
        t[0].sin(),
        t[0].cos(),
        t[1].sin(),
        t[1].cos(),
        t[2].sin(),
        t[2].cos(),
    );
    Matrix3::new(
        -c1 * (l2 * s3 + l1 * c2),
        l1 * s1 * s2,
        -l2 * s1 * c3,
        0.0,
        l1 * c2,
        l2 * s3,
        -l1 * c2 * s1 - l2 * s3 * s1,
        -l1 * s2 * c1,
        l2 * c3 * c1,
    )
}

/// Joint angles inside the elbow-up workspace where the paper's IK is the inverse of
/// FK: the tool is off the vertical axis (R > 0) and the elbow angle
/// alpha = theta3 - theta2 + pi/2 lies strictly inside (0, pi).
fn workspace() -> impl Strategy<Value = [f64; 3]> {
    (-1.5f64..1.5, -0.5f64..1.6, -1.45f64..1.45)
        .prop_map(|(t1, t2, d)| [t1, t2, t2 + d])
        .prop_filter("tool off the vertical axis", |t| {
            G.l2 * t[2].sin() + G.l1 * t[1].cos() > 0.01
        })
}

fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    d.min(2.0 * PI - d)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn f64_fk_matches_closed_form(t in prop::array::uniform3(-PI..PI)) {
        let got = engine(ArithKind::F64).fk(t);
        let want = fk_closed(&G, t);
        for k in 0..3 {
            prop_assert!((got[k] - want[k]).abs() <= 1e-12, "{k}: {got:?} vs {want:?}");
        }
    }

    #[test]
    fn f64_jacobian_and_kff_match_closed_form(
        t in prop::array::uniform3(-PI..PI),
        f in prop::array::uniform3(-5.0f64..5.0),
    ) {
        let e = engine(ArithKind::F64);
        let j = e.jacobian(t);
        let jc = jacobian_closed(&G, t);
        for r in 0..3 {
            for c in 0..3 {
                prop_assert!((j[r][c] - jc[(r, c)]).abs() <= 1e-12);
            }
        }
        let tau = e.kff(t, f);
        let want = jc.transpose() * Vector3::new(f[0], f[1], f[2]);
        for k in 0..3 {
            prop_assert!((tau[k] - want[k]).abs() <= 1e-12, "{tau:?} vs {want:?}");
        }
    }

    #[test]
    fn f64_fbf_matches_closed_form(
        o in prop::array::uniform3(-1.0f64..1.0),
        p in prop::array::uniform3(-1.0f64..1.0),
        h in prop::array::uniform3(0.0f64..2000.0),
    ) {
        let got = engine(ArithKind::F64).fbf(o, p, h);
        for k in 0..3 {
            prop_assert!((got[k] - h[k] * (o[k] - p[k])).abs() <= 1e-12);
        }
    }

    #[test]
    fn jacobian_matches_central_differences(t in prop::array::uniform3(-PI..PI)) {
        let e = engine(ArithKind::F64);
        let j = e.jacobian(t);
        let step = 1e-6;
        for c in 0..3 {
            let (mut tp, mut tm) = (t, t);
            tp[c] += step;
            tm[c] -= step;
            let (fp, fm) = (e.fk(tp), e.fk(tm));
            for r in 0..3 {
                let fd = (fp[r] - fm[r]) / (2.0 * step);
                // Truncation error of a central difference is O(step^2 * L) ~ 1e-13;
                // rounding error is O(eps * L / step) ~ 3e-11.
                prop_assert!((j[r][c] - fd).abs() <= 1e-9, "J[{r}][{c}] {} vs {fd}", j[r][c]);
            }
        }
    }

    #[test]
    fn ik_after_fk_returns_the_angles_f64(t in workspace()) {
        let e = engine(ArithKind::F64);
        let s = e.ik(e.fk(t));
        prop_assert_eq!(s.status, IkStatus::Reachable);
        for k in 0..3 {
            prop_assert!(angle_diff(s.theta[k], t[k]) <= 1e-9, "{:?} vs {t:?}", s.theta);
        }
    }

    #[test]
    fn ik_after_fk_in_f32_and_hybrid_lands_on_the_target(t in workspace()) {
        // Angles near the workspace edge are ill-conditioned in low precision, so the
        // meaningful check is in Cartesian space: FK(IK(p)) returns p.
        let p = engine(ArithKind::F64).fk(t);
        for (kind, tol) in [(ArithKind::F32, 2e-5), (ArithKind::Hybrid, 2e-3)] {
            let e = engine(kind);
            let s = e.ik(p);
            prop_assert!(s.status == IkStatus::Reachable);
            let back = engine(ArithKind::F64).fk(s.theta);
            for k in 0..3 {
                prop_assert!((back[k] - p[k]).abs() <= tol, "{kind}: {back:?} vs {p:?}");
            }
        }
    }

    #[test]
    fn ik_never_returns_nan(p in prop::array::uniform3(-10.0f64..10.0)) {
        for kind in ArithKind::ALL {
            let s = engine(kind).ik(p);
            prop_assert!(s.theta.iter().all(|v| v.is_finite()), "{kind}: {s:?}");
        }
    }

    #[test]
    fn ik_of_huge_targets_is_finite_and_flagged(
        dir in prop::array::uniform3(-1.0f64..1.0),
        exp in 0i32..300,
    ) {
        // Magnitudes up to 1e300: squaring overflows f64 from 1e155 and f32 from 1e19;
        // past f32's range the f32 input itself is infinite (Invalid).
        let scale = 10f64.powi(exp);
        let p = dir.map(|d| d * scale);
        for kind in ArithKind::ALL {
            let s = engine(kind).ik(p);
            prop_assert!(s.theta.iter().all(|v| v.is_finite()), "{kind} {p:?}: {s:?}");
            if dir.iter().map(|d| d * d).sum::<f64>().sqrt() * scale > 1.0 {
                prop_assert!(s.status != IkStatus::Reachable, "{kind} {p:?}: {s:?}");
            }
        }
    }

    #[test]
    fn batch_kernels_equal_scalar_kernels(
        rows in prop::collection::vec((prop::array::uniform3(-3.0f32..3.0), prop::array::uniform3(-4.0f32..4.0)), 0..700)
    ) {
        let g: Lengths<f32> = G.lengths();
        let cordic = Cordic::new(CordicConfig::S16_13).expect("valid");
        let col = |k: usize| rows.iter().map(|r| r.0[k]).collect::<Vec<f32>>();
        let fcol = |k: usize| rows.iter().map(|r| r.1[k]).collect::<Vec<f32>>();
        let (a, b, c) = (col(0), col(1), col(2));
        let (fa, fb, fc) = (fcol(0), fcol(1), fcol(2));
        let n = rows.len();
        let (mut x, mut y, mut z) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        kernels::fk_batch(&g, &cordic, Columns { a: &a, b: &b, c: &c }, ColumnsMut { a: &mut x, b: &mut y, c: &mut z });
        for i in 0..n {
            let want = kernels::fk(&g, &cordic, rows[i].0);
            prop_assert_eq!([x[i].to_bits(), y[i].to_bits(), z[i].to_bits()], want.map(f32::to_bits));
        }
        kernels::kff_batch(&g, &StdTrig, Columns { a: &a, b: &b, c: &c }, Columns { a: &fa, b: &fb, c: &fc }, ColumnsMut { a: &mut x, b: &mut y, c: &mut z });
        for i in 0..n {
            let want = kernels::kff(&g, &StdTrig, rows[i].0, rows[i].1);
            prop_assert_eq!([x[i].to_bits(), y[i].to_bits(), z[i].to_bits()], want.map(f32::to_bits));
        }
        let mut st = vec![IkStatus::Invalid; n];
        kernels::ik_batch(&g, &cordic, Columns { a: &fa, b: &fb, c: &fc }, ColumnsMut { a: &mut x, b: &mut y, c: &mut z }, &mut st);
        for i in 0..n {
            let want = kernels::ik(&g, &cordic, rows[i].1);
            prop_assert_eq!([x[i].to_bits(), y[i].to_bits(), z[i].to_bits()], want.theta.map(f32::to_bits));
            prop_assert_eq!(st[i], want.status);
        }
    }
}

#[test]
fn paper_waypoints_reproduce_the_printed_positions() {
    // The paper prints positions truncated (not rounded) to millimetres: y = -0.01366 is
    // printed -0.013. f64 must truncate to exactly the printed digits; every arithmetic
    // must land within one printed unit of them.
    for kind in ArithKind::ALL {
        let e = engine(kind);
        for (theta, printed) in WAYPOINTS {
            let p = e.fk(theta);
            for k in 0..3 {
                assert!(
                    (p[k] - printed[k]).abs() < 0.001,
                    "{kind} {theta:?}: {p:?} vs printed {printed:?}"
                );
                if kind == ArithKind::F64 {
                    let mm = (p[k] * 1000.0 + 1e-9_f64.copysign(p[k])).trunc();
                    assert_eq!(mm, (printed[k] * 1000.0).round(), "{theta:?}: {p:?}");
                }
            }
        }
    }
}

#[test]
fn omni_lengths_do_not_reproduce_the_waypoints() {
    // The erratum: the text's 0.135 m puts the second waypoint at x = -0.135, not -0.132.
    let e = Engine::new(ArithKind::F64, Geometry::OMNI, CordicConfig::S16_13).expect("valid");
    let p = e.fk(WAYPOINTS[1].0);
    assert!((p[0] - WAYPOINTS[1].1[0]).abs() > 0.002);
}

#[test]
fn ik_flags_unreachable_and_invalid_targets() {
    for kind in ArithKind::ALL {
        let e = engine(kind);
        // Twice the arm's reach straight ahead.
        let far = e.ik([0.0, 0.025, 0.6]);
        assert_eq!(far.status, IkStatus::Clamped, "{kind}");
        assert!(far.theta.iter().all(|v| v.is_finite()));
        // Clamped means stretched towards the target: alpha = pi, so theta3 = theta2 + pi/2.
        assert!(
            (far.theta[2] - far.theta[1] - FRAC_PI_2).abs() < 0.01,
            "{kind}: {far:?}"
        );
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let s = e.ik([0.0, bad, 0.0]);
            assert_eq!(s.status, IkStatus::Invalid);
            assert_eq!(s.theta, [0.0; 3]);
        }
        // The fully stretched arm is on the boundary: reachable despite rounding.
        let stretched = engine(ArithKind::F64).fk([0.3, 0.2, 0.2 + FRAC_PI_2]);
        assert_eq!(e.ik(stretched).status, IkStatus::Reachable, "{kind}");
    }
}
