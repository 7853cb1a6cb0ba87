//! The world against closed forms, its determinism, what it refuses, and what it
//! catches going wrong.

mod closed_forms;
mod mujoco;
mod random;
mod refused;
mod tasks;
mod wrong;

use crate::{LinkState, PhysicsWorld, Pose, Sensed, ToolState, World};
use std::path::Path;
use tactile_scenario::Scenario;

/// The sample period of the tests' worlds: the loop's 1 kHz.
pub(crate) const DT: f64 = 1e-3;

/// The world of a scenario's text (its files read against `dir`).
pub(crate) fn world_in(text: &str, dir: &Path) -> Result<PhysicsWorld, String> {
    let s = Scenario::from_toml_str(text).map_err(|e| e.to_string())?;
    PhysicsWorld::new(&s.environment, dir, &[], DT).map_err(|e| e.to_string())
}

pub(crate) fn world(text: &str) -> PhysicsWorld {
    world_in(text, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// The arm's tool frame held at `p`, still.
pub(crate) fn at(p: [f64; 3]) -> ToolState {
    ToolState {
        pose: Pose {
            position: p,
            ..Pose::default()
        },
        ..ToolState::default()
    }
}

/// Steps `w` `n` samples with the tool held at `p`; the last sensing.
pub(crate) fn hold(w: &mut PhysicsWorld, p: [f64; 3], n: usize) -> Sensed {
    for _ in 0..n {
        w.step(&at(p), &[] as &[LinkState], DT);
    }
    w.sensed().clone()
}
