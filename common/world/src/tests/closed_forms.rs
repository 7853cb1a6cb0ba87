//! The world against the closed forms of rigid-body friction and damping.

use super::*;
use crate::World;

const G: f64 = 9.81;

/// A table (static box, top at z = 0) and a box of `m` kg, half side 2 cm, resting on
/// it at `x`, both of friction `mu`.
pub(crate) fn table_and_box(m: f64, mu: f64, extra: &str) -> String {
    format!(
        r#"
[environment]
engine = "physics"
{extra}
[[environment.bodies]]
name = "table"
shape = {{ type = "box", half_extents = [1.0, 1.0, 0.05] }}
position = [0.0, 0.0, -0.05]
friction = {mu}

[[environment.bodies]]
name = "box"
kind = "dynamic"
shape = {{ type = "box", half_extents = [0.02, 0.02, 0.02] }}
position = [0.0, 0.0, 0.02]
mass = {m}
friction = {mu}
"#
    )
}

/// Far from everything: where the tool waits when a test does not use it.
const AWAY: [f64; 3] = [0.5, 0.5, 0.5];

#[test]
fn a_body_resting_on_a_table_is_pressed_by_its_weight() {
    let m = 0.7;
    let mut w = world(&table_and_box(m, 0.5, ""));
    hold(&mut w, AWAY, 500);
    let f = w.body_contact_wrench(1);
    let fz = f[2];
    assert!(
        (fz - m * G).abs() < 0.01 * m * G,
        "contact force {fz} N, m g {} N",
        m * G
    );
    assert!(f[0].abs() < 1e-6 && f[1].abs() < 1e-6, "{f:?}");
    // The table is pressed down by as much.
    assert!((w.body_contact_wrench(0)[2] + m * G).abs() < 0.01 * m * G);
}

/// The box on a plane tilted by `deg` about x, after 1 s: how far it slid, m.
fn slid_on_incline(deg: f64, mu: f64) -> f64 {
    let a = deg.to_radians();
    let (s, c) = ((a / 2.0).sin(), (a / 2.0).cos());
    // The plane's top face through the origin, the box resting on it.
    let n = [0.0, -a.sin(), a.cos()];
    let text = format!(
        r#"
[environment]
engine = "physics"

[[environment.bodies]]
name = "slope"
shape = {{ type = "box", half_extents = [1.0, 1.0, 0.05] }}
position = [0.0, {py}, {pz}]
rotation = [{s}, 0.0, 0.0, {c}]
friction = {mu}

[[environment.bodies]]
name = "box"
kind = "dynamic"
shape = {{ type = "box", half_extents = [0.02, 0.02, 0.02] }}
position = [0.0, {by}, {bz}]
rotation = [{s}, 0.0, 0.0, {c}]
mass = 0.5
friction = {mu}
"#,
        py = -0.05 * n[1],
        pz = -0.05 * n[2],
        by = 0.02 * n[1],
        bz = 0.02 * n[2],
    );
    let mut w = world(&text);
    let start = w.sensed().poses[1].position;
    let end = hold(&mut w, AWAY, 1000).poses[1].position;
    (0..3)
        .map(|i| (end[i] - start[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

#[test]
fn a_box_on_an_incline_stays_exactly_while_tan_angle_is_below_mu() {
    let mu: f64 = 0.5;
    let onset = mu.atan().to_degrees(); // 26.57 degrees
    let below = slid_on_incline(onset - 1.0, mu);
    let above = slid_on_incline(onset + 1.0, mu);
    assert!(below < 1e-3, "{below} m slid at {:.2} degrees", onset - 1.0);
    // One degree past the onset it accelerates at g (sin - mu cos) = 0.15 m/s^2: 7 cm in 1 s.
    assert!(above > 0.03, "{above} m slid at {:.2} degrees", onset + 1.0);
}

/// The tool's height when it pushes the box: below the box's centre (2 cm), so the
/// box slides flat instead of rocking on its front edge.
pub(crate) const PUSH_HEIGHT: f64 = 0.012;
/// Where the tool's centre starts, m: 2 mm clear of the box's face.
pub(crate) const PUSH_START: f64 = -0.032;

/// Pushes the box along x with the tool (a 1 cm ball at [`PUSH_HEIGHT`]) whose arm
/// moves at `v` m/s; the mean push force over the last `window` samples of `n`, and
/// the box's travel.
pub(crate) fn push(m: f64, mu: f64, v: f64, n: usize, window: usize) -> (f64, f64) {
    let mut force = 0.0;
    let travel = pushed(m, mu, v, n, |k, s| {
        if k >= n - window {
            // The arm feels -F; the push on the box is +x.
            force -= s.wrench[0] / window as f64;
        }
    });
    (force, travel)
}

/// [`push`]'s run, each sample's sensing (and its index) handed to `each`; the box's
/// travel.
pub(crate) fn pushed(
    m: f64,
    mu: f64,
    v: f64,
    n: usize,
    mut each: impl FnMut(usize, &Sensed),
) -> f64 {
    let extra = "tool = { shape = { type = \"sphere\", radius = 0.01 }, mass = 0.1, friction = 0.01, stiffness = 1000.0, damping = 10.0 }";
    let mut w = world(&table_and_box(m, mu, extra));
    let x0 = w.sensed().poses[1].position[0];
    for k in 0..n {
        let mut t = at([PUSH_START + v * k as f64 * DT, 0.0, PUSH_HEIGHT]);
        t.velocity = [v, 0.0, 0.0];
        each(k, w.step(&t, &[], DT));
    }
    w.sensed().poses[1].position[0] - x0
}

#[test]
fn a_box_pushed_at_constant_speed_takes_mu_m_g() {
    let (m, mu) = (0.4, 0.3);
    let (f, travel) = push(m, mu, 0.05, 2000, 1000);
    let want = mu * m * G;
    assert!(
        (f - want).abs() < 0.03 * want,
        "push {f} N, mu m g {want} N"
    );
    assert!(travel > 0.05, "the box moved {travel} m");
}

#[test]
fn a_damped_prismatic_joint_moves_at_force_over_damping() {
    let (m, b) = (1.0, 20.0);
    let text = format!(
        r#"
[environment]
engine = "physics"

[[environment.bodies]]
name = "slider"
kind = "dynamic"
shape = {{ type = "box", half_extents = [0.02, 0.02, 0.02] }}
mass = {m}

[[environment.joints]]
name = "rail"
kind = "prismatic"
body2 = "slider"
axis = [0.0, 0.0, -1.0]
damping = {b}
"#
    );
    let mut w = world(&text);
    let q1 = hold(&mut w, AWAY, 500).joint_positions[0];
    let q2 = hold(&mut w, AWAY, 100).joint_positions[0];
    let v = (q2 - q1) / (100.0 * DT);
    let want = m * G / b;
    assert!((v - want).abs() < 0.005 * want, "{v} m/s, F/b {want} m/s");
}

#[test]
fn the_same_scene_stepped_twice_is_bit_identical() {
    let run = || {
        let extra = "tool = { shape = { type = \"sphere\", radius = 0.01 } }";
        let mut w = world(&table_and_box(0.4, 0.3, extra));
        let mut trace = Vec::new();
        for k in 0..600 {
            let mut t = at([
                -0.033 + 0.05 * k as f64 * DT,
                0.001 * (k as f64 * 0.01).sin(),
                0.02,
            ]);
            t.velocity = [0.05, 0.0, 0.0];
            let s = w.step(&t, &[], DT);
            trace.extend(s.wrench.map(f64::to_bits));
            trace.extend(
                s.poses
                    .iter()
                    .flat_map(|p| p.position.into_iter().chain(p.rotation))
                    .map(f64::to_bits),
            );
        }
        trace
    };
    let a = run();
    assert!(a.iter().any(|b| *b != 0));
    assert_eq!(a, run());
}

/// A fixed joint makes two bodies one: a second mass held to the damped slider
/// above falls with it at (m1 + m2) g / b.
#[test]
fn a_fixed_joint_carries_its_body_with_the_other() {
    let (m1, m2, b) = (1.0, 0.5, 20.0);
    let text = format!(
        r#"
[environment]
engine = "physics"

[[environment.bodies]]
name = "slider"
kind = "dynamic"
shape = {{ type = "box", half_extents = [0.02, 0.02, 0.02] }}
mass = {m1}

[[environment.bodies]]
name = "weight"
kind = "dynamic"
shape = {{ type = "sphere", radius = 0.02 }}
position = [0.05, 0.0, 0.0]
mass = {m2}

[[environment.joints]]
name = "rail"
kind = "prismatic"
body2 = "slider"
axis = [0.0, 0.0, -1.0]
damping = {b}

[[environment.joints]]
name = "glue"
kind = "fixed"
body1 = "slider"
body2 = "weight"
anchor = [0.05, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
"#
    );
    let mut w = world(&text);
    let s1 = hold(&mut w, AWAY, 500);
    let s2 = hold(&mut w, AWAY, 100);
    let v = (s2.joint_positions[0] - s1.joint_positions[0]) / (100.0 * DT);
    let want = (m1 + m2) * G / b;
    assert!(
        (v - want).abs() < 0.01 * want,
        "{v} m/s, (m1 + m2) g / b {want} m/s"
    );
    // The weight kept its place beside the slider.
    let gap = [0, 1, 2].map(|k| s2.poses[1].position[k] - s2.poses[0].position[k]);
    assert!(
        (gap[0] - 0.05).abs() < 1e-4 && gap[2].abs() < 1e-4,
        "{gap:?}"
    );
    assert_eq!(s2.joint_positions[1], 0.0);
}
