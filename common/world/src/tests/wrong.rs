//! What the world catches going wrong: a body leaving the bounds, energy without a
//! source, non-finite inputs; none of it panics.

use super::*;
use crate::{Event, World};

const FALLING: &str = r#"
[environment]
engine = "physics"
bounds = { min = [-1.0, -1.0, -0.5], max = [1.0, 1.0, 1.0] }

[[environment.bodies]]
name = "stone"
kind = "dynamic"
shape = { type = "sphere", radius = 0.02 }
position = [0.0, 0.0, 0.0]
"#;

#[test]
fn a_body_falling_out_of_the_bounds_is_an_event_named_once() {
    let mut w = world(FALLING);
    let mut seen = Vec::new();
    for _ in 0..1000 {
        let s = w.step(&at([0.5, 0.5, 0.5]), &[], DT);
        seen.extend(s.events.iter().cloned());
    }
    // 0.5 m of free fall takes 0.32 s; once out it is taken out of the world.
    assert_eq!(
        seen,
        [Event::LeftBounds {
            body: "stone".into()
        }]
    );
    assert_eq!(w.counters().left_bounds, 1);
    assert_eq!(w.counters().energy_gains, 0, "falling is no gain");
}

#[test]
fn energy_from_nowhere_is_an_event() {
    let mut w = world(FALLING);
    hold(&mut w, [0.5, 0.5, 0.5], 10);
    assert_eq!(w.counters().energy_gains, 0);
    // What a solver failure looks like: a body thrown with no force on it.
    if let Some(r) = w.bodies.get_mut(w.handles[0]) {
        r.set_linvel(nalgebra::Vector3::new(3.0, 0.0, 0.0), true);
    }
    let s = w.step(&at([0.5, 0.5, 0.5]), &[], DT).clone();
    assert!(s.fault);
    assert!(
        matches!(s.events.as_slice(), [Event::EnergyGain { joules }] if *joules > 0.1),
        "{:?}",
        s.events
    );
    assert_eq!(w.counters().energy_gains, 1);
}

#[test]
fn the_tool_pulled_hard_is_a_source_not_an_explosion() {
    let mut w = world(FALLING);
    // The arm jumps 20 cm: the coupling pulls the tool with 200 N.
    hold(&mut w, [0.5, 0.5, 0.5], 5);
    let s = hold(&mut w, [0.7, 0.5, 0.5], 50);
    assert_eq!(w.counters().energy_gains, 0, "{:?}", s.events);
}

#[test]
fn non_finite_inputs_are_held_counted_and_never_panic() {
    let mut w = world(FALLING);
    hold(&mut w, [0.5, 0.5, 0.5], 5);
    let s = w.step(&at([f64::NAN, 0.5, 0.5]), &[], DT).clone();
    assert_eq!(s.events, [Event::BadInput]);
    assert!(s.wrench.iter().all(|x| x.is_finite()));
    let s = w.step(&at([0.5, 0.5, 0.5]), &[], f64::NAN).clone();
    assert!(s.fault && s.wrench == [0.0; 6]);
    assert_eq!(w.counters().bad_inputs, 1);
}

/// An arm's link from a URDF's `<collision>`, moved into a box resting on a table:
/// the link's contact wrench pushes it back, and the box is pushed.
#[test]
fn a_link_from_its_urdf_pushes_a_box_and_feels_it() {
    let urdf = r#"<robot name="r"><link name="paddle">
        <collision><origin xyz="0 0 0.01" rpy="0 0 0"/><geometry><box size="0.01 0.1 0.016"/></geometry></collision>
        </link></robot>"#;
    let robot = tactile_chain::Robot::parse(urdf).expect("urdf");
    let links = crate::link_shapes(&robot, &["paddle"], |_| None).expect("shapes");
    assert!(crate::link_shapes(&robot, &["arm"], |_| None).is_err());
    // The arm's friction is the tool's: a slippery paddle, so that it does not hold
    // the box up by its face (with 0.3 it carries 0.4 N of the box's weight).
    let text = super::closed_forms::table_and_box(0.4, 0.3, "tool = { friction = 0.01 }");
    let s = Scenario::from_toml_str(&text).expect("scene");
    let mut w = PhysicsWorld::new(&s.environment, Path::new("."), &links, DT).expect("world");
    let v = 0.05;
    let mut push = 0.0;
    for k in 0..2000 {
        let link = LinkState {
            pose: Pose {
                position: [-0.027 + v * k as f64 * DT, 0.0, 0.0],
                ..Pose::default()
            },
            velocity: [v, 0.0, 0.0],
            ..LinkState::default()
        };
        let s = w.step(&at([0.5, 0.5, 0.5]), &[link], DT);
        if k >= 1000 {
            push -= s.link_wrenches[0][0] / 1000.0;
        }
    }
    let want = 0.3 * 0.4 * 9.81;
    assert!(
        (push - want).abs() < 0.03 * want,
        "the link feels {push} N back, mu m g {want} N"
    );
    assert!(w.sensed().poses[1].position[0] > 0.04);
    assert_eq!(w.counters().energy_gains, 0);
}
