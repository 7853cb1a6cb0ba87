use super::*;
use proptest::prelude::*;
use tactile_messages::samples::Model;
use tactile_scenario::MmtConfig;

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

/// The z axis of a rendered force.
pub(super) fn z(f: Option<[f64; 3]>) -> f64 {
    f.expect("a model")[2]
}

pub(super) fn unit(v: [f64; 3]) -> [f64; 3] {
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
pub(super) const WALL: PlaneModel = PlaneModel {
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

/// The wall jumps 1 cm into a tool held 5 mm deep, or doubles its stiffness under it:
/// the force leaves the model at once, the fit starts again there, and every model
/// on the way is a wall a hand could feel (no spring of nothing 6 m away, which a
/// least-squares fit through the jump gives).
#[test]
fn a_wall_that_jumps_under_a_held_tool_is_refitted_not_smeared() {
    for new in [
        PlaneModel {
            offset: -0.05,
            ..WALL
        },
        PlaneModel {
            stiffness: 1200.0,
            ..WALL
        },
    ] {
        let (mut e, _) = learnt(WALL);
        let held = [0.0, 0.0, -0.065];
        for _ in 0..500 {
            e.update(held, contact(&WALL, held));
        }
        assert_eq!(e.jumps(), 0, "no jump on the old wall");
        for i in 0..300 {
            e.update(held, contact(&new, held));
            let m = e.model().expect("a model");
            assert!(
                (300.0..=1300.0).contains(&m.stiffness) && m.offset.abs() < 0.1,
                "{i}: {m:?}"
            );
            // The model gives the force the tool feels.
            assert!(
                (m.force(held)[2] - contact(&new, held)[2]).abs() < 0.05,
                "{i}: {m:?}"
            );
        }
        assert_eq!(e.jumps(), 1);
        // Pressed again, it is the new wall.
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

/// A wall touched far from the origin (the wall-delay handle is 11 cm off the axis)
/// with a force whose direction wobbles by a few hundredths of a radian (the slave's
/// fixed-point tool): positions along the normal are measured from the first contact,
/// so the wobble does not move them by 11 cm times the angle.
#[test]
fn a_wall_far_off_the_axis_with_a_wobbling_force_is_found() {
    let w = PlaneModel {
        normal: [0.0, 0.0, 1.0],
        offset: -0.06,
        stiffness: 600.0,
    };
    let mut e = PlaneEstimator::new(EstimatorConfig::default());
    for (i, x) in press(&w, 0.01, 4000).into_iter().enumerate() {
        let x = [x[0], x[1] - 0.11, x[2]];
        let h = contact(&w, x);
        let wobble = 0.03 * (i as f64 * 0.7).sin() * h[2];
        e.update(x, [0.0, wobble, h[2]]);
    }
    let m = e.model().expect("a model");
    assert!((m.stiffness - 600.0).abs() < 0.02 * 600.0, "{m:?}");
    assert!(
        (m.offset - dot(m.normal, [0.0, -0.11, -0.06])).abs() < 2e-4,
        "{m:?}"
    );
}

/// The slave sends a model once it has one, then only when it changed past a
/// threshold; each sent model has the next number, and every sample carries the last.
#[test]
fn the_sender_numbers_models_and_sends_only_changes() {
    let cfg = MmtConfig::default();
    let mut s = ModelSender::new(&cfg);
    assert_eq!(s.sent(), Model::default());
    let mut sent = 0;
    for x in press(&WALL, 0.01, 2000) {
        if s.update(x, contact(&WALL, x), [0.0; 3]) {
            sent += 1;
            assert_eq!(s.sent().seq, sent);
        }
    }
    let last = PlaneModel::of_message(&s.sent()).expect("a model");
    assert!(close(&last, &WALL, 0.02, 2e-4, 0.02), "{last:?}");
    // A few dozen models for a whole press, not one a sample.
    assert!((1..60).contains(&sent), "{sent} sent");
    // Holding still on the wall changes nothing.
    let hold = [0.0, 0.0, -0.065];
    for _ in 0..1000 {
        assert!(!s.update(hold, contact(&WALL, hold), [0.0; 3]));
    }
    assert_eq!(s.sent().seq, sent);
}

/// A re-clutch that puts the tool 2 cm further along the wall's normal than the handle
/// (the operator moved the handle 2 cm towards the wall while the robot held): the wall, still in the
/// tool's space, is sent at once 2 cm nearer the handle's side, and holding on changes
/// nothing more; sideways offsets do not move a plane.
#[test]
fn a_reclutch_sends_the_model_where_the_handle_meets_the_wall() {
    let mut s = ModelSender::new(&MmtConfig::default());
    for x in press(&WALL, 0.01, 2000) {
        s.update(x, contact(&WALL, x), [0.0; 3]);
    }
    let before = PlaneModel::of_message(&s.sent()).expect("a model");
    let hold = [0.0, 0.0, -0.065];
    let shift = [0.05, -0.03, 0.02];
    assert!(s.update(hold, contact(&WALL, hold), shift));
    let after = PlaneModel::of_message(&s.sent()).expect("a model");
    assert!(
        (after.offset - (before.offset - 0.02 * before.normal[2])).abs() < 1e-3,
        "{before:?} {after:?}"
    );
    assert!((after.stiffness - before.stiffness).abs() < 0.02 * before.stiffness);
    let seq = s.sent().seq;
    for _ in 0..1000 {
        assert!(!s.update(hold, contact(&WALL, hold), shift));
    }
    assert_eq!(s.sent().seq, seq);
}

/// A re-clutch that carried the handle 3 cm up (out of the wall, along its normal)
/// while the robot held: at the engage the model moves with it, so the handle meets it
/// as before the release; a release and engage in place changes nothing.
pub(super) fn apart(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([0, 1, 2].map(|i| a[i] - b[i]))
}

#[test]
fn a_reclutch_moves_the_rendered_model_with_the_handle() {
    let mut r = ModelReceiver::new(&MmtConfig::default(), 1e-3, f64::INFINITY);
    let outside = [0.0, 0.0, -0.05];
    assert_eq!(r.take(&WALL.to_message(1), outside, [0.0; 3]), Taken::New);
    let inside = [0.0, 0.0, -0.065];
    let before = r.force(inside).expect("a model");
    assert!(before[2] > 1.0, "{before:?}");
    r.clutch(true, inside);
    r.clutch(true, [0.01, 0.0, -0.04]);
    let up = [0.0, 0.0, -0.035];
    r.clutch(false, up);
    let after = r.force(up).expect("a model");
    assert!(apart(after, before) < 1e-9, "{after:?} against {before:?}");
    r.clutch(true, up);
    r.clutch(false, up);
    assert!(apart(r.force(up).expect("a model"), before) < 1e-9);
}

/// The master takes each new number once, ignores an older or repeated one, refuses
/// a corrupted model once (counted by the caller), and takes the same number when a
/// later sample carries it whole (every sample carries the last model sent).
#[test]
fn the_receiver_takes_new_models_once_and_refuses_garbage() {
    let mut r = ModelReceiver::new(&MmtConfig::default(), 1e-3, f64::INFINITY);
    let x = [0.0, 0.0, -0.05];
    assert_eq!(r.take(&Model::default(), x, [0.0; 3]), Taken::Nothing);
    assert!(r.force(x).is_none());
    assert_eq!(r.take(&WALL.to_message(1), x, [0.0; 3]), Taken::New);
    assert_eq!(r.take(&WALL.to_message(1), x, [0.0; 3]), Taken::Nothing);
    let bad = Model {
        stiffness: f64::NAN,
        ..WALL.to_message(2)
    };
    assert_eq!(r.take(&bad, x, [0.0; 3]), Taken::Refused);
    assert_eq!(r.take(&bad, x, [0.0; 3]), Taken::Nothing);
    assert_eq!(r.take(&WALL.to_message(1), x, [0.0; 3]), Taken::Nothing);
    let soft = PlaneModel {
        stiffness: 450.0,
        ..WALL
    };
    assert_eq!(r.take(&soft.to_message(2), x, [0.0; 3]), Taken::New);
    assert_eq!(r.renderer().model(), Some(soft));
    let stiff = PlaneModel {
        stiffness: 900.0,
        ..WALL
    };
    assert_eq!(r.take(&stiff.to_message(3), x, [0.0; 3]), Taken::New);
    assert_eq!(r.renderer().model(), Some(stiff));
    assert!((z(r.force([0.0, 0.0, -0.07])) - 9.0).abs() < 1e-9);
}

/// The floor pressed, then without a break in contact a face tilted 40 degrees from
/// it (a corner's second wall, a tilted body): the force turns at once, and the
/// estimate is the new face within 500 samples. Averaged into the floor's normal the
/// turned force left the plane between the two (0.04 rad off here; in a corner,
/// where the force keeps turning, the fit under it read a stiffness of a few N/m and
/// a surface metres from the tool).
#[test]
fn a_face_at_another_angle_is_found_as_itself() {
    let (mut e, _) = learnt(WALL);
    let tilt = 40f64.to_radians();
    let face = PlaneModel {
        normal: [-tilt.sin(), 0.0, tilt.cos()],
        offset: -0.05,
        stiffness: 600.0,
    };
    learn(&mut e, &face, &press(&face, 0.008, 2000)[500..1000]);
    let m = e.model().expect("a model");
    assert!(close(&m, &face, 0.1, 5e-4, 0.02), "{m:?}");
}
