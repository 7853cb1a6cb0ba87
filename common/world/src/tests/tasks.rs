//! Tasks evaluated on a running world: met, held, completed.

use super::*;
use crate::{TaskMonitor, World};
use tactile_scenario::TaskConfig;

const SLIDER: &str = r#"
[environment]
engine = "physics"

[[environment.bodies]]
name = "slider"
kind = "dynamic"
shape = { type = "box", half_extents = [0.02, 0.02, 0.02] }
mass = 1.0

[[environment.joints]]
name = "rail"
kind = "prismatic"
body2 = "slider"
axis = [0.0, 0.0, 1.0]
limits = [-0.1, 0.0]
damping = 20.0

[task]
kind = "joint"
joint = "rail"
position = -0.05
hold_s = 0.2
"#;

#[test]
fn a_joint_opened_and_held_completes_when_the_hold_ends() {
    let s = Scenario::from_toml_str(SLIDER).expect("scene");
    let mut w = PhysicsWorld::new(&s.environment, Path::new("."), &[], DT).expect("world");
    let task = s.task.expect("a task");
    let mut m = TaskMonitor::new(&task, &w).expect("monitor");
    let mut first_met = None;
    let mut last = f64::INFINITY;
    for k in 1..=1000 {
        let sensed = w.step(&at([0.5, 0.5, 0.5]), &[], DT).clone();
        let p = m.update(&sensed, k as f64 * DT);
        assert!(p.distance <= last + 1e-9, "the slider only falls");
        last = p.distance;
        if p.met && first_met.is_none() {
            first_met = Some(k as f64 * DT);
        }
    }
    let p = m.progress();
    let met = first_met.expect("met");
    // It falls toward m g / b = 0.49 m/s with the time constant m / b = 0.05 s:
    // x(t) = v (t - tau (1 - e^(-t / tau))) reaches 5 cm at 0.151 s; then held 0.2 s.
    assert!((0.145..0.157).contains(&met), "met at {met} s");
    assert!(p.success, "{p:?}");
    assert!(
        (p.completion_s.expect("completed") - (met + 0.2)).abs() < 1.5 * DT,
        "{p:?}"
    );
}

#[test]
fn a_box_pushed_to_its_target_is_a_pose_task_met() {
    let (_, travel) = super::closed_forms::push(0.4, 0.3, 0.05, 1500, 1);
    let task = TaskConfig::Pose {
        body: "box".into(),
        position: [travel, 0.0, 0.02],
        tolerance: 0.005,
        rotation: None,
        angle_tolerance_deg: None,
        hold_s: 0.0,
    };
    let w = world(&super::closed_forms::table_and_box(0.4, 0.3, ""));
    let mut m = TaskMonitor::new(&task, &w).expect("monitor");
    let start = m.update(w.sensed(), 0.0);
    assert!(!start.met && start.distance > 0.05, "{start:?}");
    // The same push again, monitored.
    super::closed_forms::pushed(0.4, 0.3, 0.05, 1500, |k, s| {
        m.update(s, (k + 1) as f64 * DT);
    });
    assert!(m.progress().success, "{:?}", m.progress());
    let mut wrong = task.clone();
    if let TaskConfig::Pose { body, .. } = &mut wrong {
        *body = "crate".into();
    }
    assert!(TaskMonitor::new(&wrong, &w).is_none());
}

#[test]
fn an_insertion_is_met_past_the_depth_and_on_the_axis() {
    let s = Scenario::from_toml_str(SLIDER).expect("scene");
    let w = PhysicsWorld::new(&s.environment, Path::new("."), &[], DT).expect("world");
    let task = TaskConfig::Insert {
        peg: "tool".into(),
        mouth: [0.0, 0.0, 0.1],
        axis: [0.0, 0.0, -1.0],
        depth: 0.02,
        radial_tolerance: 0.001,
        hold_s: 0.0,
    };
    let mut m = TaskMonitor::new(&task, &w).expect("monitor");
    let mut sensed = Sensed::default();
    let cases = [
        ([0.0, 0.0, 0.09], false, 0.01),
        ([0.0, 0.0, 0.07], true, 0.0),
        ([0.003, 0.0, 0.07], false, 0.002),
    ];
    for (p, met, distance) in cases {
        sensed.tool.position = p;
        let r = m.update(&sensed, 0.0);
        assert_eq!(r.met, met, "{p:?}");
        assert!((r.distance - distance).abs() < 1e-12, "{p:?}: {r:?}");
    }
}
