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

/// The device's gimbal (`[master.ros2.gimbal]`, its URDF relative to `base_dir`), its
/// URDF read and parsed once and its chain checked; None without one. The message
/// names the field and the file.
pub fn gimbal(sc: &Scenario, base_dir: &Path) -> Result<Option<Gimbal>, String> {
    let Some(g) = &sc.master.ros2.gimbal else {
        return Ok(None);
    };
    let field = "master.ros2.gimbal";
    let urdf =
        tactile_chain::file::read(&base_dir.join(&g.urdf)).map_err(|e| format!("{field}: {e}"))?;
    Gimbal::of_robot(&urdf.robot, &g.base, &g.tip, &g.frame)
        .map(Some)
        .map_err(|e| format!("{field}: {}: {e}", urdf.path.display()))
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
