//! The benches' arms and target: the Panda (7 joints) and the UR5 (6) at a working
//! pose, and a target circling 5 cm around the tool's pose there at 1 Hz, sampled at
//! 1 kHz, as a slave follows a master.

use nalgebra::Vector3;
use tactile_chain::{Chain, Frame};

const PANDA: &str = include_str!("../../../../deploy/robots/panda.urdf");
const UR5: &str = include_str!("../../../../deploy/robots/ur5_robot.urdf");

/// Each arm's name, chain and working pose.
pub fn arms() -> Vec<(&'static str, Chain, Vec<f64>)> {
    let panda = Chain::from_urdf(PANDA, "panda_link0", "panda_hand").expect("panda");
    let ur5 = Chain::from_urdf(UR5, "base_link", "tool0").expect("ur5");
    vec![
        (
            "panda",
            panda,
            vec![0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
        ),
        ("ur5", ur5, vec![0.0, -1.2, 1.4, -1.8, -1.2, 0.0]),
    ]
}

/// The target of sample `k` on the circle around `home`.
pub fn circle(home: &Frame, k: u64) -> Frame {
    let t = (k % 1000) as f64 * 1e-3 * std::f64::consts::TAU;
    let mut target = *home;
    target.p += Vector3::new(0.05 * t.cos() - 0.05, 0.05 * t.sin(), 0.0);
    target
}
