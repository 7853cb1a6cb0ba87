//! What the master and the slave share when they open their ROS 2 side themselves (a
//! node owns its peripherals; the runtime only drives them): the `[ros.tls]` check,
//! the node's session on rmw_zenoh, and the live view. Each node opens its own device,
//! robot or arm on the session; the session and the view only with the `zenoh`
//! feature (a scenario that needs them is refused before, in a build without it).

use std::path::Path;
use tactile_scenario::RosConfig;

/// Checks the ROS 2 session's `[ros.tls]` files (relative to `base_dir`): bad input
/// naming the field and the file. Nothing to check in a build without Zenoh, where no
/// session is ever opened.
pub fn check_tls(ros: &RosConfig, base_dir: &Path) -> Result<(), String> {
    #[cfg(feature = "zenoh")]
    crate::rmw_node::check_tls(ros, base_dir)?;
    let _ = (ros, base_dir);
    Ok(())
}

#[cfg(feature = "zenoh")]
pub use with_zenoh::*;

#[cfg(feature = "zenoh")]
mod with_zenoh {
    use crate::live_arm::LiveArm;
    use crate::live_view::{every, LiveView};
    use crate::rmw_node::RosNode;
    use crate::{LiveSink, RosError};
    use std::path::Path;
    use std::sync::Arc;
    use tactile_ros::view::SampleView;
    use tactile_scenario::Scenario;

    /// A node's live view, as its driver takes it.
    pub type Live = Box<dyn LiveSink<SampleView>>;

    /// Why a node's ROS 2 side did not open: its input, or ROS 2.
    #[derive(Debug, thiserror::Error)]
    pub enum SideError {
        /// A file the scenario names (a `[ros.tls]` file, a URDF): bad input.
        #[error("{0}")]
        BadInput(String),
        /// A session, publisher or subscription that could not be made.
        #[error(transparent)]
        Ros(#[from] RosError),
    }

    /// The node `name`'s ROS 2 session, its `[ros.tls]` files (relative to
    /// `base_dir`) checked first.
    pub fn session(sc: &Scenario, base_dir: &Path, name: &str) -> Result<Arc<RosNode>, SideError> {
        super::check_tls(&sc.ros, base_dir).map_err(SideError::BadInput)?;
        let ros = sc.resolved(base_dir).ros;
        Ok(Arc::new(RosNode::open(&ros, name)?))
    }

    /// The live view on `node` when `[ros.live]` asks for one: `topics` (the role's),
    /// a simulated URDF `arm` served as `robot_state_publisher` would, its thread put
    /// below the loop by `below_loop`.
    pub fn live_view(
        node: Arc<RosNode>,
        sc: &Scenario,
        topics: &[usize],
        arm: Option<LiveArm>,
        below_loop: fn() -> std::io::Result<()>,
    ) -> Result<Option<Live>, RosError> {
        if !sc.ros.live.enabled {
            return Ok(None);
        }
        let every = every(sc.rate_hz, sc.ros.live.rate_hz);
        let live = LiveView::start(node, every, below_loop, topics, arm)?;
        Ok(Some(Box::new(live)))
    }
}
