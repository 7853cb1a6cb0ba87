//! A node's ROS 2 side, opened from the scenario: its session on rmw_zenoh, the real
//! device (`master.backend = "ros2"`) or robot (`slave.backend = "ros2"`), and the live
//! view (`ros.live`). Only in builds with the `zenoh` feature; without it a scenario
//! that asks for any of them is refused before anything starts.

use crate::args::NodeError;
use tactile_devices::{HapticDevice, LiveSink, Robot};
use tactile_messages::Role;
use tactile_ros::view::SampleView;
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

/// Checks the ROS 2 session's `[ros.tls]` files (relative to `base_dir`) when the run
/// uses ROS 2: bad input naming the field and the file, before anything starts.
pub fn check_ros_tls(sc: &Scenario, base_dir: &std::path::Path) -> Result<(), NodeError> {
    #[cfg(feature = "zenoh")]
    if ros_in_run(sc) {
        tactile_devices::rmw_node::check_tls(&sc.ros, base_dir).map_err(NodeError::BadInput)?;
    }
    let _ = (sc, base_dir);
    Ok(())
}

/// What a node touches besides its link, opened for the run.
#[derive(Default)]
pub struct Outside {
    /// The master's device.
    pub haptic: Option<Box<dyn HapticDevice>>,
    /// The slave's robot.
    pub robot: Option<Box<dyn Robot>>,
    /// The slave's robot when it is an arm from its URDF (`[slave.arm]`).
    pub arm_robot: Option<Box<dyn Robot<Vec<f64>>>>,
    /// The live view.
    pub live: Option<Box<dyn LiveSink<SampleView>>>,
}

impl std::fmt::Debug for Outside {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Outside")
            .field("haptic", &self.haptic.as_ref().map(|d| d.describe()))
            .field("robot", &self.robot.as_ref().map(|d| d.describe()))
            .field("arm_robot", &self.arm_robot.as_ref().map(|d| d.describe()))
            .field("live", &self.live.is_some())
            .finish()
    }
}

impl Outside {
    /// Opens what the scenario asks of `role` (nothing for a simulated run without the
    /// live view); the scenario's files (an arm's URDF) are relative to `base_dir`.
    pub fn open(
        sc: &Scenario,
        role: Role,
        base_dir: &std::path::Path,
    ) -> Result<Outside, NodeError> {
        if !ros_on(sc, role) {
            return Ok(Outside::default());
        }
        open_ros(sc, role, base_dir)
    }
}

#[cfg(feature = "zenoh")]
fn open_ros(sc: &Scenario, role: Role, base_dir: &std::path::Path) -> Result<Outside, NodeError> {
    use std::sync::Arc;
    use tactile_devices::live_view::{every, LiveView};
    use tactile_devices::rmw_node::RosNode;
    use tactile_devices::ros_devices::RosRobot;
    use tactile_devices::ros_hand::RosHapticDevice;
    let failed = |e: tactile_devices::RosError| NodeError::Failed(e.to_string());
    check_ros_tls(sc, base_dir)?;
    let ros = sc.resolved(base_dir).ros;
    let node = Arc::new(RosNode::open(&ros, &format!("tactile_{role}")).map_err(failed)?);
    let mut out = Outside::default();
    if role == Role::Master && sc.master.backend == Backend::Ros2 {
        let limit = sc.master.force_limit;
        let gimbal = gimbal(sc, base_dir)?;
        let d = RosHapticDevice::open(&node, &sc.master.ros2, gimbal, sc.t_s_ns(), limit)
            .map_err(failed)?;
        out.haptic = Some(Box::new(d));
    }
    if role == Role::Slave && sc.slave.backend == Backend::Ros2 {
        match &sc.slave.arm {
            Some(arm) => out.arm_robot = Some(open_arm(&node, sc, arm, base_dir)?),
            None => {
                let r = RosRobot::open(&node, &sc.slave.ros2, sc.t_s_ns()).map_err(failed)?;
                out.robot = Some(Box::new(r));
            }
        }
    }
    if sc.ros.live.enabled {
        let topics: &[usize] = match role {
            Role::Master => &tactile_ros::view::MASTER_LIVE,
            _ => &tactile_ros::view::SLAVE_LIVE,
        };
        let every = every(sc.rate_hz, sc.ros.live.rate_hz);
        let arm = match (role, &sc.slave.arm) {
            (Role::Slave, Some(arm)) if sc.slave.backend != Backend::Ros2 => {
                Some(live_arm(arm, base_dir)?)
            }
            _ => None,
        };
        let live = LiveView::start(node, every, crate::sched::set_thread_other, topics, arm)
            .map_err(failed)?;
        out.live = Some(Box::new(live));
    }
    Ok(out)
}

/// The device's gimbal (`[master.ros2.gimbal]`), its URDF read and its chain checked.
pub fn gimbal(
    sc: &Scenario,
    base_dir: &std::path::Path,
) -> Result<Option<tactile_devices::hand::Gimbal>, NodeError> {
    let Some(g) = &sc.master.ros2.gimbal else {
        return Ok(None);
    };
    let path = base_dir.join(&g.urdf);
    let xml = crate::files::read_text(&path, "URDF", 16 << 20).map_err(NodeError::BadInput)?;
    tactile_devices::hand::Gimbal::new(&xml, &g.base, &g.tip, &g.frame)
        .map(Some)
        .map_err(|e| NodeError::BadInput(format!("master.ros2.gimbal: {}: {e}", path.display())))
}

/// A simulated `[slave.arm]` for the live view: its URDF as written and its tree.
#[cfg(feature = "zenoh")]
fn live_arm(
    arm: &tactile_scenario::ArmConfig,
    base_dir: &std::path::Path,
) -> Result<tactile_devices::live_arm::LiveArm, NodeError> {
    use tactile_chain::{Robot as Urdf, Tree};
    let path = base_dir.join(&arm.urdf);
    let bad = |e: String| NodeError::BadInput(format!("slave.arm: {}: {e}", path.display()));
    let urdf = crate::files::read_text(&path, "URDF", 16 << 20).map_err(NodeError::BadInput)?;
    let robot = Urdf::parse(&urdf).map_err(|e| bad(e.to_string()))?;
    let tree = Tree::new(&robot).map_err(|e| bad(e.to_string()))?;
    Ok(tactile_devices::live_arm::LiveArm { urdf, tree })
}

/// The arm of `[slave.arm]` over ROS 2: its URDF read for the joints' names, limits and
/// speeds, and the frames a wrench may come in.
#[cfg(feature = "zenoh")]
fn open_arm(
    node: &std::sync::Arc<tactile_devices::rmw_node::RosNode>,
    sc: &Scenario,
    arm: &tactile_scenario::ArmConfig,
    base_dir: &std::path::Path,
) -> Result<Box<dyn Robot<Vec<f64>>>, NodeError> {
    use tactile_chain::{Chain, Robot as Urdf, Tree};
    let path = base_dir.join(&arm.urdf);
    let bad = |e: String| NodeError::BadInput(format!("slave.arm: {}: {e}", path.display()));
    let xml = crate::files::read_text(&path, "URDF", 16 << 20).map_err(NodeError::BadInput)?;
    let robot = Urdf::parse(&xml).map_err(|e| bad(e.to_string()))?;
    let chain = Chain::new(&robot, &arm.base, &arm.tip).map_err(|e| bad(e.to_string()))?;
    let tree = Tree::new(&robot).map_err(|e| bad(e.to_string()))?;
    let r = tactile_devices::ros_arm::RosArm::open(node, &sc.slave.ros2, &chain, tree, sc.t_s_ns())
        .map_err(|e| NodeError::Failed(e.to_string()))?;
    Ok(Box::new(r))
}

#[cfg(not(feature = "zenoh"))]
fn open_ros(_: &Scenario, _: Role, _: &std::path::Path) -> Result<Outside, NodeError> {
    Err(NodeError::BadInput(NO_ROS.into()))
}

#[cfg(all(test, not(feature = "zenoh")))]
mod tests {
    use super::*;

    #[test]
    fn a_build_without_zenoh_refuses_a_ros_scenario_and_runs_the_rest() {
        let mut sc = Scenario::default();
        assert!(
            Outside::open(&sc, Role::Master, std::path::Path::new(".")).is_ok(),
            "nothing asked, nothing opened"
        );
        sc.ros.live.enabled = true;
        match Outside::open(&sc, Role::Slave, std::path::Path::new(".")) {
            Err(NodeError::BadInput(m)) => assert!(m.contains("--features zenoh"), "{m}"),
            other => panic!("{other:?}"),
        }
        assert!(check(&sc, Role::Emulator).is_ok());
    }
}
