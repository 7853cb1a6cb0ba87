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

/// A renderer that has shown `WALL` to a handle at `x`, from a force `felt`.
fn shown(x: [f64; 3], felt: [f64; 3]) -> ModelRenderer {
    let mut r = ModelRenderer::new(0.006, Update::Passive);
    assert!(r.receive(WALL, x, felt));
    r
}

fn z(f: Option<[f64; 3]>) -> f64 {
    f.expect("a model")[2]
}

#[test]
fn nothing_is_rendered_before_a_model_and_invalid_models_are_refused() {
    let mut r = ModelRenderer::new(0.006, Update::Passive);
    assert!(r.force([0.0, 0.0, -0.07]).is_none());
    let bad = PlaneModel {
        stiffness: f64::NAN,
        ..WALL
    };
    assert!(!r.receive(bad, [0.0; 3], [0.0; 3]));
    assert!(!r.receive(WALL, [f64::NAN, 0.0, 0.0], [0.0; 3]));
    assert!(r.force([0.0, 0.0, -0.07]).is_none());
}

/// The first model, arriving 1 cm deep with 2 N felt: 2 N on, not the model's 6 N; out
/// of the wall and back in, the model's own surface.
#[test]
fn the_first_model_takes_over_the_felt_force_and_the_surface_returns_outside() {
    let inside = [0.0, 0.0, -0.07];
    let mut r = shown(inside, [0.0, 0.0, 2.0]);
    assert!((z(r.force(inside)) - 2.0).abs() < 1e-9);
    // Held there: the surface stays (moving it out would add energy).
    for _ in 0..10_000 {
        r.force(inside);
    }
    assert!((z(r.force(inside)) - 2.0).abs() < 1e-9);
    // Out of the wall, where the model's surface is not past the handle: there at once.
    assert_eq!(z(r.force([0.0, 0.0, -0.064])), 0.0);
    assert_eq!(r.rendered().map(|m| m.offset), Some(-0.064));
    assert_eq!(z(r.force([0.0, 0.0, -0.05])), 0.0);
    assert_eq!(r.rendered(), Some(WALL));
    assert!((z(r.force(inside)) - 6.0).abs() < 1e-9);
}

/// A stiffer model in contact: the force stays, the slope is the new stiffness. A softer
/// one: kept for when the handle is out.
#[test]
fn stiffer_models_are_taken_at_once_and_softer_ones_outside() {
    let inside = [0.0, 0.0, -0.07];
    let mut r = shown([0.0, 0.0, -0.05], [0.0; 3]);
    let f = z(r.force(inside));
    assert!((f - 6.0).abs() < 1e-9);
    let stiff = PlaneModel {
        stiffness: 1200.0,
        ..WALL
    };
    assert!(r.receive(stiff, inside, [0.0, 0.0, f]));
    assert!((z(r.force(inside)) - 6.0).abs() < 1e-9);
    assert!((z(r.force([0.0, 0.0, -0.071])) - 6.0 - 1.2).abs() < 1e-6);
    let soft = PlaneModel {
        stiffness: 300.0,
        ..WALL
    };
    assert!(r.receive(soft, inside, [0.0, 0.0, f]));
    assert_eq!(r.rendered().map(|m| m.stiffness), Some(1200.0));
    assert_eq!(r.model(), Some(soft));
    for _ in 0..1000 {
        r.force([0.0, 0.0, -0.04]);
    }
    assert_eq!(r.rendered(), Some(soft));
    // The stiffer model at 6 N stores 6^2 / 2400 where 6^2 / 1200 was: 15 mJ taken
    // out, booked as such; the softer one came with nothing stored.
    assert!((r.injected() + 0.015).abs() < 1e-12, "{} J", r.injected());
}

proptest! {
    /// Whatever models arrive and wherever the handle goes, the force does not step
    /// when a model arrives (beyond one sample's turn or relaxation), in magnitude or
    /// direction;
    /// `Passive` adds no energy at the handle, and `Blend` no more than its relaxation
    /// can: `step p` a sample at penetration `p`.
    #[test]
    fn model_changes_do_not_kick_and_add_only_what_the_rule_allows(
        models in prop::collection::vec(
            (-0.2f64..0.2, -0.2f64..0.2, -0.08f64..-0.04, 100.0f64..3000.0, 0usize..400),
            1..12,
        ),
        wiggle in prop::collection::vec(-0.03f64..0.03, 50),
        blend in any::<bool>(),
    ) {
        let update = if blend { Update::Blend } else { Update::Passive };
        let mut r = ModelRenderer::new(0.03, update);
        let mut felt = [0.0; 3];
        let mut t = 0usize;
        let mut allowed = 0.0;
        let x = |t: usize| [0.0, 0.0, -0.06 + wiggle[(t / 40) % 50] * ((t % 40) as f64 / 40.0)];
        let render = |r: &mut ModelRenderer, t: usize, allowed: &mut f64| {
            let f = r.force(x(t)).expect("a model");
            let shown = r.rendered().expect("a model");
            *allowed += 0.03 * shown.penetration(x(t)) + 1e-15;
            f
        };
        for (nx, ny, offset, k, hold) in models {
            let m = PlaneModel { normal: unit([nx, ny, 1.0]), offset, stiffness: k };
            // What the operator feels now: the rendered model's force, or before the
            // first model what arrived (`felt`, given as such).
            let now = r.rendered().map_or(felt, |old| old.force(x(t)));
            let before = r.injected();
            prop_assert!(r.receive(m, x(t), felt));
            // A softer model taken at once (Blend) stores F^2 / 2k more at the same force;
            // Passive nothing (but rounding).
            allowed += r.injected() - before;
            prop_assert!(update == Update::Blend || r.injected() - before < 1e-12, "{} J added by {m:?}", r.injected() - before);
            // The force, vector and all: what was felt, give or take one sample's turn
            // or relaxation of 30 mN.
            felt = render(&mut r, t, &mut allowed);
            let moved = norm([0, 1, 2].map(|i| felt[i] - now[i]));
            prop_assert!(moved <= 0.03 + 1e-9, "{now:?} N to {felt:?} N");
            for _ in 0..hold {
                t += 1;
                felt = render(&mut r, t, &mut allowed);
            }
        }
        match update {
            Update::Passive => prop_assert!(r.injected() < 1e-12, "{} J", r.injected()),
            Update::Blend => prop_assert!(r.injected() <= allowed * (1.0 + 1e-9), "{} J > {allowed} J", r.injected()),
        }
    }
}

/// The wall-delay press at 200 ms: the first model arrives with the handle 13 mm deep
/// and 0.4 N felt. `Passive` keeps that (the wall stays 12 mm farther while the
/// operator presses); `Blend` moves the surface out to the model's, the force rising by
/// at most `step` (30 mN) a sample, and books what that adds.
#[test]
fn blend_brings_a_late_wall_to_its_place_without_a_kick() {
    let deep = [0.0, -0.11, -0.073];
    for (update, end) in [(Update::Passive, 0.4), (Update::Blend, 7.8)] {
        let mut r = ModelRenderer::new(0.03, update);
        assert!(r.receive(WALL, deep, [0.0, 0.0, 0.4]));
        let mut last = 0.4;
        for _ in 0..1000 {
            let f = z(r.force(deep));
            assert!(
                f >= last - 1e-12 && f - last <= 0.03 + 1e-12,
                "{last} N to {f} N"
            );
            last = f;
        }
        assert!((last - end).abs() < 1e-9, "{update:?}: {last} N");
        // What the wall stores at 13 mm, less what the 0.4 N already stored.
        let stored = 0.5 * 600.0 * 0.013f64.powi(2) - 0.4f64.powi(2) / 1200.0;
        let injected = if update == Update::Blend { stored } else { 0.0 };
        assert!((r.injected() - injected).abs() < 1e-9, "{} J", r.injected());
    }
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
fn apart(a: [f64; 3], b: [f64; 3]) -> f64 {
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

/// A model softer than what is felt (8 N where it gives 6 N): the force eases off to the
/// model's by `step` a sample, with no jump.
#[test]
fn a_force_above_the_models_eases_off() {
    let inside = [0.0, 0.0, -0.07];
    let mut r = shown(inside, [0.0, 0.0, 8.0]);
    let mut last = 8.0;
    for _ in 0..1000 {
        let f = z(r.force(inside));
        assert!(
            f <= last && last - f <= 600.0 * 1e-5 + 1e-12,
            "{last} N to {f} N"
        );
        last = f;
    }
    assert!((last - 6.0).abs() < 1e-9);
    assert_eq!(r.rendered(), Some(WALL));
}

/// Two walls at a corner: the handle pressed 1 cm into a floor (+z) when the model
/// turns to the side wall (-x). The felt force turns with the depth kept, changing by
/// at most `step` a sample, vector and all (an earlier renderer switched the normal
/// at once: a step of the whole force), and ends as the side wall's.
#[test]
fn a_turned_normal_turns_the_force_without_a_step() {
    let x = [0.0, 0.0, -0.07];
    let mut r = ModelRenderer::new(0.05, Update::Blend);
    assert!(r.receive(WALL, [0.0, 0.0, -0.05], [0.0; 3]));
    let mut last = r.force(x).expect("a model");
    assert!((last[2] - 6.0).abs() < 1e-9, "{last:?}");
    let side = PlaneModel {
        normal: [-1.0, 0.0, 0.0],
        offset: 0.01,
        stiffness: 600.0,
    };
    assert!(r.receive(side, x, last));
    let mut samples = 0;
    for _ in 0..2000 {
        let f = r.force(x).expect("a model");
        assert!(apart(f, last) <= 0.05 + 1e-12, "{last:?} N to {f:?} N");
        samples += usize::from(apart(f, last) > 0.0);
        last = f;
    }
    // 6 N along -x: 0.01 m deep in the side wall; a quarter turn of 6 N at 50 mN a
    // sample takes about 6 pi / 2 / 0.05 = 188 samples.
    assert!(apart(last, [-6.0, 0.0, 0.0]) < 1e-9, "{last:?}");
    assert!((150..400).contains(&samples), "{samples} samples");
}

/// The energy booked is the spring's as the force limit lets it be felt: the late
/// wall brought out to its place behind a 3.3 N limit books what the limited spring
/// stores at 13 mm (the limit's knee at 5.5 mm: 3.3 N x 5.5 mm / 2 + 3.3 N x 7.5 mm),
/// not the unlimited spring's 50.7 mJ.
#[test]
fn the_energy_booked_is_what_the_force_limit_lets_be_felt() {
    let deep = [0.0, -0.11, -0.073];
    let mut r = ModelRenderer::new(0.03, Update::Blend).with_force_limit(3.3);
    assert!(r.receive(WALL, deep, [0.0, 0.0, 0.4]));
    for _ in 0..1000 {
        r.force(deep);
    }
    let knee = 3.3 / 600.0;
    let stored = 0.5 * 3.3 * knee + 3.3 * (0.013 - knee) - 0.4f64.powi(2) / 1200.0;
    assert!(
        (r.injected() - stored).abs() < 1e-9,
        "{} J, not {stored} J",
        r.injected()
    );
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
