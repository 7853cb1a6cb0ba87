//! The master's renderer: nothing before a model, a model taken with the force
//! continuous (vector and all), the surface's return at a bounded rate, and the net
//! energy its changes add booked as the force limit lets it be felt.
use super::super::tests::{apart, unit, z, WALL};
use super::*;
use proptest::prelude::*;

/// A renderer that has shown `WALL` to a handle at `x`, from a force `felt`.
fn shown(x: [f64; 3], felt: [f64; 3]) -> ModelRenderer {
    let mut r = ModelRenderer::new(0.006, Update::Passive);
    assert!(r.receive(WALL, x, felt));
    r
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
