//! Random scenes and random arm motions: building refuses or succeeds, stepping never
//! panics, and what is sensed is always finite.

use super::*;
use crate::World;
use proptest::prelude::*;
use std::fmt::Write as _;

fn shape() -> impl Strategy<Value = String> {
    prop_oneof![
        (0.001f64..0.3, 0.001f64..0.3, 0.001f64..0.3)
            .prop_map(|(a, b, c)| format!("{{ type = \"box\", half_extents = [{a}, {b}, {c}] }}")),
        (0.001f64..0.3).prop_map(|r| format!("{{ type = \"sphere\", radius = {r} }}")),
        (0.001f64..0.2, 0.001f64..0.1).prop_map(|(h, r)| format!(
            "{{ type = \"capsule\", half_height = {h}, radius = {r} }}"
        )),
        (0.001f64..0.2, 0.001f64..0.1).prop_map(|(h, r)| format!(
            "{{ type = \"cylinder\", half_height = {h}, radius = {r} }}"
        )),
    ]
}

fn body() -> impl Strategy<Value = (String, u8, [f64; 3], [f64; 4], f64, f64)> {
    (
        shape(),
        0u8..3,
        prop::array::uniform3(-1.0f64..1.0),
        prop::array::uniform4(-1.0f64..1.0),
        0.001f64..50.0,
        0.01f64..2.0,
    )
}

fn arm() -> impl Strategy<Value = [f64; 3]> {
    prop_oneof![
        8 => prop::array::uniform3(-1.0f64..1.0),
        1 => prop::array::uniform3(-100.0f64..100.0),
        1 => Just([f64::NAN, 0.0, f64::INFINITY]),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn any_scene_builds_or_is_refused_and_never_panics(
        bodies in prop::collection::vec(body(), 1..7),
        motion in prop::collection::vec(arm(), 1..40),
        substeps in 1u32..6,
    ) {
        let mut text = format!("[environment]\nengine = \"physics\"\nsubsteps = {substeps}\n");
        for (k, (shape, kind, p, q, mass, mu)) in bodies.iter().enumerate() {
            let kind = ["static", "dynamic", "kinematic"][*kind as usize];
            let mass = if kind == "dynamic" { format!("mass = {mass}\n") } else { String::new() };
            let _ = write!(text, "[[environment.bodies]]\nname = \"b{k}\"\nkind = \"{kind}\"\nshape = {shape}\nposition = [{}, {}, {}]\nrotation = [{}, {}, {}, {}]\n{mass}friction = {mu}\n", p[0], p[1], p[2], q[0], q[1], q[2], q[3]);
        }
        let Ok(mut w) = world_in(&text, Path::new(".")) else { return Ok(()) };
        for p in &motion {
            for _ in 0..5 {
                let s = w.step(&at(*p), &[], DT);
                prop_assert!(s.wrench.iter().all(|x| x.is_finite()));
                prop_assert!(s.poses.iter().all(|p| p.position.iter().all(|x| x.is_finite()) || s.fault));
            }
        }
    }
}
