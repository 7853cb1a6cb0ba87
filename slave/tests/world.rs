//! The slave in a physics world, through its public API.

use std::path::Path;
use tactile_math::arith::StdTrig;
use tactile_math::joints::Joints;
use tactile_math::kernels;
use tactile_messages::samples::Forward;
use tactile_scenario::Scenario;
use tactile_slave::hsd::{Measured, Slave};
use tactile_slave::world::SlaveWorld;

/// A real robot without a force-torque sensor in a physics world: the world's
/// coupling is h(n) (a sensor's reading would win; without either, the analytic
/// scene's FBF).
#[test]
fn a_robot_without_a_sensor_feels_the_physics_world() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/scenarios");
    let text = std::fs::read_to_string(dir.join("push-box.toml")).expect("push-box");
    let sc = Scenario::from_toml_str(&text).expect("scenario");
    let arm = tactile_slave::peripherals::read_arm(&sc, &dir).expect("arm");
    let world = SlaveWorld::of_scenario(&sc, &dir).expect("world");
    let mut slave = Slave::new(&sc, arm, world).expect("slave");
    // The robot's tool 1 cm into the box's top: the ball is pushed out of it.
    let inside = [0.0, -0.11, -0.06];
    let lengths = sc.device.geometry().expect("device").lengths();
    let q = kernels::ik(&lengths, &StdTrig, inside);
    let mut force = 0.0f64;
    for n in 0..50 {
        slave.measure(Measured {
            joints: Joints::from(q.theta),
            force: None,
            torque: [0.0; 3],
        });
        let mut v = Forward {
            seq: n,
            ..Forward::default()
        };
        v.signal.value = inside;
        let mut h = None;
        let step = slave.step(&v, &mut h);
        force = force.max(step.force.iter().map(|f| f * f).sum::<f64>().sqrt());
    }
    assert!(force > 0.1, "h(n) peaked at {force} N");
}
