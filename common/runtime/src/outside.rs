//! Whether a node needs ROS 2 for a scenario: its real device (`master.backend =
//! "ros2"`), robot (`slave.backend = "ros2"`) or the live view (`ros.live`). The nodes
//! open these themselves (each owns its peripherals, the runtime drives what they hand
//! it); only in builds with the `zenoh` feature: without it a scenario that asks for
//! any of them is refused here, before anything starts.

use crate::args::NodeError;
use tactile_messages::Role;
use tactile_scenario::{Backend, Scenario};

/// What a node built without the `zenoh` feature says to a scenario that needs ROS 2.
pub const NO_ROS: &str = "this scenario uses ROS 2 (a ros2 backend or the live view), which this build of Tactile does not include: build with `--features zenoh` (cargo build --release --features zenoh)";

/// True if `role`'s node needs ROS 2 for the scenario.
pub fn ros_on(sc: &Scenario, role: Role) -> bool {
    match role {
        Role::Master => sc.master.backend == Backend::Ros2 || sc.ros.live.enabled,
        Role::Slave => sc.slave.backend == Backend::Ros2 || sc.ros.live.enabled,
        Role::Emulator => false,
    }
}

/// True if any node of the run needs ROS 2 (it needs the node programs: an in-process
/// run simulates both devices and has no live view).
pub fn ros_in_run(sc: &Scenario) -> bool {
    Role::ALL.iter().any(|r| ros_on(sc, *r))
}

/// Refuses a scenario that needs ROS 2 in a build without it.
pub fn check(sc: &Scenario, role: Role) -> Result<(), NodeError> {
    if ros_on(sc, role) && !cfg!(feature = "zenoh") {
        return Err(NodeError::BadInput(NO_ROS.into()));
    }
    Ok(())
}

#[cfg(all(test, not(feature = "zenoh")))]
mod tests {
    use super::*;

    #[test]
    fn a_build_without_zenoh_refuses_a_ros_scenario_and_runs_the_rest() {
        let mut sc = Scenario::default();
        assert!(check(&sc, Role::Master).is_ok(), "nothing asked");
        sc.ros.live.enabled = true;
        match check(&sc, Role::Slave) {
            Err(NodeError::BadInput(m)) => assert!(m.contains("--features zenoh"), "{m}"),
            other => panic!("{other:?}"),
        }
        assert!(check(&sc, Role::Emulator).is_ok());
    }
}
