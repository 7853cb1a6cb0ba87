//! The slave's peripherals, opened by the slave itself and handed to its driver: the
//! URDF of its `[slave.arm]`, read and parsed once ([`UrdfArm::read_urdf`]) and its
//! model passed down to the simulated arm, a robot over ROS 2 (`slave.backend =
//! "ros2"`: the paper-shaped robot or the arm) and the live view's arm; the live view
//! itself (`[ros.live]`). The runtime knows no arm; it drives what the slave hands it.

use crate::paper_arm::PaperArm;
use crate::slave_arm::SlaveArm;
use crate::urdf_arm::UrdfArm;
use std::path::Path;
use tactile_chain::UrdfFile;
use tactile_devices::Robot;
use tactile_math::arith::StdTrig;
use tactile_math::kernels;
use tactile_runtime::args::NodeError;
use tactile_runtime::program::Live;
use tactile_scenario::Scenario;

impl UrdfArm {
    /// The scenario's `[slave.arm]`, its URDF read (relative to `base_dir`) and
    /// checked; `None` without one (the paper's arm).
    pub fn of_scenario(scenario: &Scenario, base_dir: &Path) -> Result<Option<Self>, String> {
        match UrdfArm::read_urdf(scenario, base_dir)? {
            Some(urdf) => UrdfArm::of_urdf(scenario, &urdf),
            None => Ok(None),
        }
    }

    /// The URDF of the scenario's `[slave.arm]` (relative to `base_dir`), read and
    /// parsed: a node's one reading of it, its model passed down to the simulated arm,
    /// the robot over ROS 2 and the live view. `None` for the paper's arm.
    pub fn read_urdf(scenario: &Scenario, base_dir: &Path) -> Result<Option<UrdfFile>, String> {
        let Some(cfg) = &scenario.slave.arm else {
            return Ok(None);
        };
        tactile_chain::file::read(&base_dir.join(&cfg.urdf))
            .map(Some)
            .map_err(|e| format!("slave.arm: {e}"))
    }

    /// The scenario's `[slave.arm]` made from its URDF as read ([`UrdfArm::read_urdf`]),
    /// checked; `None` without one (the paper's arm).
    pub fn of_urdf(scenario: &Scenario, urdf: &UrdfFile) -> Result<Option<Self>, String> {
        let Some(cfg) = &scenario.slave.arm else {
            return Ok(None);
        };
        let geometry = scenario.device.geometry().map_err(|e| e.to_string())?;
        // The paper arm's tool at zero angles: where the master starts.
        let home = kernels::fk(&geometry.lengths(), &StdTrig, [0.0; 3]);
        UrdfArm::of_robot(cfg, &urdf.robot, home)
            .map(Some)
            .map_err(|e| format!("slave.arm: {}: {e}", urdf.path.display()))
    }
}

/// The scenario's arm: its `[slave.arm]` from the URDF as read (`urdf`, relative
/// paths already resolved), or the paper's.
pub fn of_scenario(
    scenario: &Scenario,
    urdf: Option<&UrdfFile>,
) -> Result<Box<dyn SlaveArm>, String> {
    match (&scenario.slave.arm, urdf) {
        (None, _) => Ok(Box::new(
            PaperArm::new(scenario).map_err(|e| e.to_string())?,
        )),
        (Some(_), Some(urdf)) => match UrdfArm::of_urdf(scenario, urdf)? {
            Some(arm) => Ok(Box::new(arm)),
            None => Err("slave.arm: not in the scenario".into()),
        },
        (Some(_), None) => Err("slave.arm: its URDF was not read".into()),
    }
}

/// The scenario's arm, its URDF (if any) read relative to `base_dir`.
pub fn read_arm(scenario: &Scenario, base_dir: &Path) -> Result<Box<dyn SlaveArm>, String> {
    let urdf = UrdfArm::read_urdf(scenario, base_dir)?;
    of_scenario(scenario, urdf.as_ref())
}

/// What the slave opened: its real robot (None: simulated) and its live view.
#[derive(Default)]
pub struct Peripherals {
    /// The real robot, over ROS 2.
    pub robot: Option<Box<dyn Robot>>,
    /// The live view.
    pub live: Option<Live>,
}

impl std::fmt::Debug for Peripherals {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Peripherals")
            .field("robot", &self.robot.as_ref().map(|r| r.describe()))
            .field("live", &self.live.is_some())
            .finish()
    }
}

/// Opens what the scenario asks of the slave (nothing for a simulated arm without the
/// live view); `urdf` is the `[slave.arm]`'s as read before anything started.
#[cfg(feature = "zenoh")]
pub fn open(
    sc: &Scenario,
    base_dir: &Path,
    urdf: Option<&UrdfFile>,
) -> Result<Peripherals, NodeError> {
    use tactile_devices::live_arm::LiveArm;
    use tactile_devices::ros_side::{live_view, session, SideError};
    use tactile_messages::Role;
    use tactile_scenario::Backend;
    if !tactile_runtime::outside::ros_on(sc, Role::Slave) {
        return Ok(Peripherals::default());
    }
    let failed = |e: tactile_devices::RosError| NodeError::Failed(e.to_string());
    let node = session(sc, base_dir, &format!("tactile_{}", Role::Slave)).map_err(|e| match e {
        SideError::BadInput(m) => NodeError::BadInput(m),
        SideError::Ros(e) => failed(e),
    })?;
    let mut out = Peripherals::default();
    let mut live_arm = None;
    match (sc.slave.backend, urdf) {
        (Backend::Ros2, Some(urdf)) => out.robot = Some(ros_arm(&node, sc, urdf)?),
        (Backend::Ros2, None) => {
            let r =
                tactile_devices::ros_devices::RosRobot::open(&node, &sc.slave.ros2, sc.t_s_ns())
                    .map_err(failed)?;
            out.robot = Some(Box::new(r));
        }
        (Backend::Simulated, Some(urdf)) => {
            let tree = tactile_chain::Tree::new(&urdf.robot).map_err(|e| arm_error(urdf, &e))?;
            live_arm = Some(LiveArm {
                urdf: urdf.text.clone(),
                tree,
            });
        }
        (Backend::Simulated, None) => {}
    }
    let topics = &tactile_ros::view::SLAVE_LIVE;
    let below_loop = tactile_runtime::sched::set_thread_other;
    out.live = live_view(node, sc, topics, live_arm, below_loop).map_err(failed)?;
    Ok(out)
}

/// The arm of `[slave.arm]` over ROS 2, from its URDF as read: the joints' names,
/// limits and speeds, and the frames a wrench may come in.
#[cfg(feature = "zenoh")]
fn ros_arm(
    node: &std::sync::Arc<tactile_devices::rmw_node::RosNode>,
    sc: &Scenario,
    urdf: &UrdfFile,
) -> Result<Box<dyn Robot>, NodeError> {
    use tactile_chain::{Chain, Tree};
    let Some(arm) = &sc.slave.arm else {
        return Err(NodeError::Failed("no [slave.arm] for its URDF".into()));
    };
    let chain = Chain::new(&urdf.robot, &arm.base, &arm.tip).map_err(|e| arm_error(urdf, &e))?;
    let tree = Tree::new(&urdf.robot).map_err(|e| arm_error(urdf, &e))?;
    let r = tactile_devices::ros_arm::RosArm::open(node, &sc.slave.ros2, &chain, tree, sc.t_s_ns())
        .map_err(|e| NodeError::Failed(e.to_string()))?;
    Ok(Box::new(r))
}

/// Bad input naming `[slave.arm]`'s field and its URDF.
#[cfg(feature = "zenoh")]
fn arm_error(urdf: &UrdfFile, e: &tactile_chain::Error) -> NodeError {
    NodeError::BadInput(format!("slave.arm: {}: {e}", urdf.path.display()))
}

/// Without Zenoh nothing can be opened: a scenario that asks for ROS 2 is refused (the
/// program's checks refused it before).
#[cfg(not(feature = "zenoh"))]
pub fn open(sc: &Scenario, _: &Path, _: Option<&UrdfFile>) -> Result<Peripherals, NodeError> {
    tactile_runtime::outside::check(sc, tactile_messages::Role::Slave)?;
    Ok(Peripherals::default())
}
