//! The master's peripherals, opened by the master itself and handed to its driver: a
//! real device over ROS 2 (`master.backend = "ros2"`, with the gimbal of its URDF,
//! `[master.ros2.gimbal]`) and the live view (`[ros.live]`). The runtime knows neither
//! the device nor its gimbal; it drives what the master hands it.

use std::path::Path;
use tactile_devices::hand::Gimbal;
use tactile_devices::HapticDevice;
use tactile_runtime::args::NodeError;
use tactile_runtime::program::Live;
use tactile_scenario::Scenario;

/// What the master opened: its device (None: simulated) and its live view.
#[derive(Default)]
pub struct Peripherals {
    /// The real device, over ROS 2.
    pub device: Option<Box<dyn HapticDevice>>,
    /// The live view.
    pub live: Option<Live>,
}

impl std::fmt::Debug for Peripherals {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Peripherals")
            .field("device", &self.device.as_ref().map(|d| d.describe()))
            .field("live", &self.live.is_some())
            .finish()
    }
}

/// Why the device's gimbal cannot be used; each message names the field and the file.
#[derive(Debug, thiserror::Error)]
pub enum GimbalError {
    /// Its URDF cannot be read or parsed.
    #[error("master.ros2.gimbal: {0}")]
    Read(#[from] tactile_chain::file::ReadError),
    /// Its URDF has no such chain.
    #[error("master.ros2.gimbal: {}: {source}", path.display())]
    Chain {
        /// The URDF.
        path: std::path::PathBuf,
        /// Why.
        source: tactile_chain::Error,
    },
}

/// The device's gimbal (`[master.ros2.gimbal]`, its URDF relative to `base_dir`), its
/// URDF read and parsed once and its chain checked; None without one. The message
/// names the field and the file.
pub fn gimbal(sc: &Scenario, base_dir: &Path) -> Result<Option<Gimbal>, GimbalError> {
    let Some(g) = &sc.master.ros2.gimbal else {
        return Ok(None);
    };
    let urdf = tactile_chain::file::read(&base_dir.join(&g.urdf))?;
    Gimbal::of_robot(&urdf.robot, &g.base, &g.tip, &g.frame)
        .map(Some)
        .map_err(|source| GimbalError::Chain {
            path: urdf.path,
            source,
        })
}

/// Opens what the scenario asks of the master (nothing for a simulated device without
/// the live view); `gimbal` is [`gimbal`]'s, read before anything started.
#[cfg(feature = "zenoh")]
pub fn open(
    sc: &Scenario,
    base_dir: &Path,
    gimbal: Option<Gimbal>,
) -> Result<Peripherals, NodeError> {
    use tactile_devices::ros_hand::RosHapticDevice;
    use tactile_devices::ros_side::{live_view, session, SideError};
    use tactile_messages::Role;
    if !tactile_runtime::outside::ros_on(sc, Role::Master) {
        return Ok(Peripherals::default());
    }
    let failed = |e: tactile_devices::RosError| NodeError::Failed(e.to_string());
    let node =
        session(sc, base_dir, &format!("tactile_{}", Role::Master)).map_err(|e| match e {
            SideError::BadInput(m) => NodeError::BadInput(m),
            SideError::Ros(e) => failed(e),
        })?;
    let mut out = Peripherals::default();
    if sc.master.backend == tactile_scenario::Backend::Ros2 {
        let (limit, t_s_ns) = (sc.master.force_limit, sc.t_s_ns());
        let d =
            RosHapticDevice::open(&node, &sc.master.ros2, gimbal, t_s_ns, limit).map_err(failed)?;
        out.device = Some(Box::new(d));
    }
    let topics = &tactile_ros::view::MASTER_LIVE;
    let below_loop = tactile_runtime::sched::set_thread_other;
    out.live = live_view(node, sc, topics, None, below_loop).map_err(failed)?;
    Ok(out)
}

/// Without Zenoh nothing can be opened: a scenario that asks for ROS 2 is refused (the
/// program's checks refused it before).
#[cfg(not(feature = "zenoh"))]
pub fn open(sc: &Scenario, _: &Path, _: Option<Gimbal>) -> Result<Peripherals, NodeError> {
    tactile_runtime::outside::check(sc, tactile_messages::Role::Master)?;
    Ok(Peripherals::default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// The gimbal's error keeps the chain's fault, with the field and the file above it.
    #[test]
    fn a_gimbal_error_keeps_the_chains_fault() {
        let robot = tactile_chain::Robot::parse("<robot name=\"r\"><link name=\"a\"/></robot>")
            .expect("a robot of one link");
        let source =
            Gimbal::of_robot(&robot, "a", "tip", &Default::default()).expect_err("no link tip");
        let e = GimbalError::Chain {
            path: "hand.urdf".into(),
            source,
        };
        assert!(
            e.to_string()
                .starts_with("master.ros2.gimbal: hand.urdf: chain from `a` to `tip`"),
            "{e}"
        );
        assert!(matches!(
            e.source()
                .and_then(|c| c.downcast_ref::<tactile_chain::Error>()),
            Some(tactile_chain::Error::Chain { .. })
        ));
    }
}
