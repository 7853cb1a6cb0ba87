use super::*;
use proptest::prelude::*;

/// The environment's force on a point at `x` from a wall `w` (the truth the estimator
/// must find).
fn contact(w: &PlaneModel, x: [f64; 3]) -> [f64; 3] {
    w.force(x)
}

/// A press into `w` in `n` samples: from 5 mm outside to `depth` inside along the
/// normal in the first quarter, then in and out between 60 % and 100 % of it, with a
/// sideways slide throughout.
fn press(w: &PlaneModel, depth: f64, n: usize) -> Vec<[f64; 3]> {
    let side = perpendicular(w.normal);
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64;
            let swing = 0.8 + 0.2 * (8.0 * std::f64::consts::PI * t).cos();
            let inward = -0.005 + (depth + 0.005) * (4.0 * t).min(1.0) * swing;
            let along = w.offset - inward;
            std::array::from_fn(|j| w.normal[j] * along + side[j] * 0.01 * t)
        })
        .collect()
}

fn perpendicular(n: [f64; 3]) -> [f64; 3] {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let c = [
        n[1] * a[2] - n[2] * a[1],
        n[2] * a[0] - n[0] * a[2],
        n[0] * a[1] - n[1] * a[0],
    ];
    let m = norm(c);
    c.map(|v| v / m)
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let m = norm(v);
    v.map(|x| x / m)
}

fn learn(e: &mut PlaneEstimator, w: &PlaneModel, path: &[[f64; 3]]) {
    for &x in path {
        e.update(x, contact(w, x));
    }
}

/// An estimator that has pressed `w` once, and `w` itself.
fn learnt(w: PlaneModel) -> (PlaneEstimator, PlaneModel) {
    let mut e = PlaneEstimator::new(EstimatorConfig::default());
    learn(&mut e, &w, &press(&w, 0.01, 2000));
    (e, w)
}

/// The 600 N/m wall of wall-delay.toml.
const WALL: PlaneModel = PlaneModel {
    normal: [0.0, 0.0, 1.0],
    offset: -0.06,
    stiffness: 600.0,
};

fn close(m: &PlaneModel, w: &PlaneModel, k_rel: f64, offset: f64, angle: f64) -> bool {
    (m.stiffness - w.stiffness).abs() <= k_rel * w.stiffness
        && (m.offset - w.offset).abs() <= offset
        && dot(m.normal, w.normal).clamp(-1.0, 1.0).acos() <= angle
}

proptest! {
    /// Any wall the scenarios allow, touched once: the estimate is the wall.
    #[test]
    fn a_pressed_wall_is_found(
        nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in 0.2f64..1.0,
        offset in -0.2f64..0.2, k in 100.0f64..3000.0, depth in 0.002f64..0.02,
    ) {
        let w = PlaneModel { normal: unit([nx, ny, nz]), offset, stiffness: k };
        let mut e = PlaneEstimator::new(EstimatorConfig::default());
        learn(&mut e, &w, &press(&w, depth, 2000));
        let m = e.model().expect("a model after 2000 samples");
        prop_assert!(close(&m, &w, 0.01, 1e-4, 1e-3), "{m:?} vs {w:?}");
        prop_assert!(m.is_valid());
    }

    /// What a peer could send is believed only when valid.
    #[test]
    fn invalid_models_are_refused(
        n in prop::array::uniform3(-2.0f64..2.0), offset in -20.0f64..20.0,
        k in -100.0f64..1.0e4,
    ) {
        let m = PlaneModel { normal: n, offset, stiffness: k };
        let ok = (norm(n) - 1.0).abs() < 1e-6 && offset.abs() <= 10.0
            && (0.0..=MAX_STIFFNESS).contains(&k);
        prop_assert_eq!(m.is_valid(), ok);
    }
}

#[test]
fn no_model_before_contact_or_from_garbage() {
    let mut e = PlaneEstimator::new(EstimatorConfig::default());
    for i in 0..1000 {
        e.update([0.0, 0.0, i as f64 * 1e-5], [0.0; 3]);
        e.update([f64::NAN, 0.0, 0.0], [0.0, 0.0, 5.0]);
        e.update([0.0; 3], [0.0, f64::INFINITY, 1.0]);
    }
    assert_eq!(e.contacts(), 0);
    assert!(e.model().is_none());
}

/// Holding still in contact teaches nothing new: the covariance stays bounded and the
/// estimate stays where it was (no wind-up), however long the hold.
#[test]
fn a_long_hold_keeps_the_estimate() {
    let (mut e, w) = learnt(WALL);
    let x = [0.0, 0.0, -0.07];
    for _ in 0..1_000_000 {
        e.update(x, contact(&w, x));
    }
    let rls = e.rls.expect("contact seen");
    assert!(rls.p[0][0] <= P0[0] && rls.p[1][1] <= P0[1], "{:?}", rls.p);
    let m = e.model().expect("a model");
    assert!(close(&m, &w, 0.01, 1e-4, 1e-3), "{m:?}");
}

/// The wall moved 1 cm deeper: free motion inside the old model moves the surface, and
/// the next contact finds the new wall.
#[test]
fn a_wall_that_moved_away_is_followed() {
    let (mut e, old) = learnt(WALL);
    let new = PlaneModel {
        offset: -0.07,
        ..old
    };
    // Out, then 8 mm into where the old wall was: nothing there.
    let down: Vec<[f64; 3]> = (0..=100)
        .map(|i| [0.0, 0.0, -0.055 - 0.013 * i as f64 / 100.0])
        .collect();
    learn(&mut e, &new, &down);
    let m = e.model().expect("a model");
    assert!(
        m.offset <= -0.068 + 1e-6,
        "the surface left where nothing is: {m:?}"
    );
    assert!(
        (m.stiffness - 600.0).abs() < 6.0,
        "the stiffness kept: {m:?}"
    );
    learn(&mut e, &new, &press(&new, 0.01, 2000));
    let m = e.model().expect("a model");
    assert!(close(&m, &new, 0.02, 2e-4, 1e-3), "{m:?}");
}

/// The wall moved 1 cm out, or doubled its stiffness: forgetting follows it.
#[test]
fn a_wall_that_moved_closer_or_stiffened_is_followed() {
    let old = WALL;
    for new in [
        PlaneModel {
            offset: -0.05,
            ..old
        },
        PlaneModel {
            stiffness: 1200.0,
            ..old
        },
    ] {
        let (mut e, _) = learnt(old);
        learn(&mut e, &new, &press(&new, 0.01, 4000));
        let m = e.model().expect("a model");
        assert!(close(&m, &new, 0.02, 2e-4, 1e-3), "{m:?} vs {new:?}");
    }
}

#[test]
fn changes_are_measured_against_what_was_sent() {
    let sent = WALL;
    let th = ChangeThresholds::default();
    assert!(!sent.differs(&sent, &th));
    assert!(!PlaneModel {
        stiffness: 610.0,
        ..sent
    }
    .differs(&sent, &th));
    assert!(PlaneModel {
        stiffness: 620.0,
        ..sent
    }
    .differs(&sent, &th));
    assert!(!PlaneModel {
        offset: -0.0601,
        ..sent
    }
    .differs(&sent, &th));
    assert!(PlaneModel {
        offset: -0.0605,
        ..sent
    }
    .differs(&sent, &th));
    let tilted = unit([0.03, 0.0, 1.0]);
    assert!(PlaneModel {
        normal: tilted,
        ..sent
    }
    .differs(&sent, &th));
}

#[test]
fn the_model_is_a_spring_behind_its_surface() {
    let w = WALL;
    assert_eq!(w.force([0.0, 0.0, -0.05]), [0.0; 3]);
    assert_eq!(w.energy([0.0, 0.0, -0.05]), 0.0);
    let f = w.force([0.3, 0.0, -0.07]);
    assert!((f[2] - 6.0).abs() < 1e-9 && f[0] == 0.0 && f[1] == 0.0);
    assert!((w.energy([0.0, 0.0, -0.07]) - 0.03).abs() < 1e-12);
}
