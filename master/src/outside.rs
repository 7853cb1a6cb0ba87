//! The master's ROS 2 side, opened from the scenario: the node on rmw_zenoh, the real
//! device (`master.backend = "ros2"`) and the live view (`ros.live`). Only in builds
//! with the `zenoh` feature; without it a scenario that asks for either is refused
//! before anything starts.

use crate::process::Outside;
use tactile_node::args::NodeError;
use tactile_scenario::{Backend, Scenario};

/// True if the scenario needs ROS 2 on the master.
pub fn needs_ros(sc: &Scenario) -> bool {
    sc.master.backend == Backend::Ros2 || sc.ros.live.enabled
}

/// The master's ROS 2 parts, kept alive for the run.
#[derive(Debug, Default)]
pub struct RosParts {
    #[cfg(feature = "zenoh")]
    side: Option<
        tactile_node::live::RosSide<
            tactile_node::ros2_devices::RosHapticDevice,
            crate::live::MasterLive,
        >,
    >,
}

impl RosParts {
    /// Opens what the scenario asks for (nothing for a simulated run without the live
    /// view).
    pub fn open(sc: &Scenario) -> Result<RosParts, NodeError> {
        if !needs_ros(sc) {
            return Ok(RosParts::default());
        }
        #[cfg(feature = "zenoh")]
        {
            use tactile_node::ros2_devices::RosHapticDevice;
            let device = (sc.master.backend == Backend::Ros2)
                .then_some(|n: &_| RosHapticDevice::open(n, &sc.master.ros2, sc.t_s_ns()));
            let side = tactile_node::live::RosSide::open(sc, "tactile_master", device)
                .map_err(|e| NodeError::Failed(e.to_string()))?;
            Ok(RosParts { side: Some(side) })
        }
        #[cfg(not(feature = "zenoh"))]
        Err(NodeError::BadInput(tactile_node::args::NO_ROS.into()))
    }

    /// The parts as the loop takes them.
    pub fn outside(&mut self) -> Outside<'_> {
        #[cfg(feature = "zenoh")]
        if let Some(s) = &mut self.side {
            use tactile_node::device::{HapticDevice, LiveSink};
            return Outside {
                device: s.device.as_mut().map(|d| d as &mut dyn HapticDevice),
                live: s
                    .live
                    .as_mut()
                    .map(|l| l as &mut dyn LiveSink<crate::live::MasterLive>),
            };
        }
        Outside::default()
    }
}

#[cfg(all(test, not(feature = "zenoh")))]
mod tests {
    use super::*;

    #[test]
    fn a_build_without_zenoh_refuses_a_ros_scenario_and_runs_the_rest() {
        let mut sc = Scenario::default();
        assert!(RosParts::open(&sc).is_ok(), "nothing asked, nothing opened");
        sc.ros.live.enabled = true;
        match RosParts::open(&sc) {
            Err(NodeError::BadInput(m)) => assert!(m.contains("--features zenoh"), "{m}"),
            other => panic!("{other:?}"),
        }
    }
}
