//! The live view's cost: the iceoryx2 loop again with `ros.live` on, every node
//! publishing its state to a viewer, a Zenoh session in this process that takes every
//! message on the domain (as Foxglove's bridge or `ros2 topic echo` would).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use tactile_launch::error::Error;
use tactile_scenario::{RosConfig, Scenario};
use tactile_transport::zenoh_link::zenoh;
use zenoh::Wait as _;

/// Messages a second each node's live view publishes in the bench.
pub const LIVE_HZ: f64 = 100.0;

/// A viewer of the live view: listens on a loopback port, counts what arrives.
pub struct Viewer {
    _session: zenoh::Session,
    _sub: zenoh::pubsub::Subscriber<()>,
    received: Arc<AtomicU64>,
    /// Its endpoint, for the nodes' `ros.connect`.
    pub endpoint: String,
}

impl Viewer {
    /// Opens the viewer on a free loopback port, subscribed to domain 0.
    pub fn open() -> Result<Viewer, Error> {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map_err(Error::io("finding a free port for the live view's viewer"))?
            .port();
        let endpoint = format!("tcp/127.0.0.1:{port}");
        let failed = |e: zenoh::Error| Error::Failed(format!("the live view's viewer: {e}"));
        // The nodes' own ROS 2 session settings, listening where they connect.
        let cfg = RosConfig {
            connect: Vec::new(),
            listen: vec![endpoint.clone()],
            ..RosConfig::default()
        };
        let c = tactile_devices::rmw_node::session_config(&cfg)
            .map_err(|e| Error::Failed(format!("the live view's viewer: {e}")))?;
        let session = zenoh::open(c).wait().map_err(failed)?;
        let received = Arc::new(AtomicU64::new(0));
        let count = Arc::clone(&received);
        let sub = session
            .declare_subscriber("0/**")
            .callback(move |_| {
                count.fetch_add(1, Ordering::Relaxed);
            })
            .wait()
            .map_err(failed)?;
        Ok(Viewer {
            _session: session,
            _sub: sub,
            received,
            endpoint,
        })
    }

    /// Messages received so far.
    pub fn received(&self) -> u64 {
        self.received.load(Ordering::Relaxed)
    }

    /// `sc` with the live view on, publishing to this viewer.
    pub fn scenario(&self, sc: &Scenario) -> Scenario {
        let mut s = sc.clone();
        s.ros.live.enabled = true;
        s.ros.live.rate_hz = LIVE_HZ.min(s.rate_hz);
        s.ros.connect = vec![self.endpoint.clone()];
        s
    }
}
