//! A node as an rmw_zenoh node: its own Zenoh session (ROS 2's settings, apart from the
//! loop's link), its liveliness tokens, and publishers and subscriptions whose key
//! expressions and attachments are rmw_zenoh's (`tactile_ros::rmw`), so ROS 2 tools and
//! drivers on rmw_zenoh and Tactile's nodes see each other.
//!
//! Subscriptions listen on `<domain>/<topic>/<type>/*` and take a Jazzy driver's
//! RIHS01 hash and a Humble one's `TypeHashNotSupported` alike, the message layouts
//! being the same; a sample of any other hash, or without rmw_zenoh's attachment, is
//! dropped and counted ([`crate::admit`]). Publishers use the exact Jazzy key, as
//! Jazzy subscribers expect.
//! Publications do not wait: congestion control `Drop` with no wait before dropping,
//! like ROS 2 sensor streams.

use crate::admit::admit;
use crate::watch::Inbox;
use crate::{Reject, RosError};
use std::sync::atomic::{AtomicI64, AtomicU32, Ordering};
use std::sync::Arc;
use tactile_ros::rmw::{self, Attachment, EntityKind, NodeId};
use tactile_scenario::RosConfig;
use tactile_transport::zenoh_link::TlsFiles;
use zenoh::liveliness::LivelinessToken;
use zenoh::qos::CongestionControl;
use zenoh::Wait as _;

fn err(context: &str, e: impl std::fmt::Display) -> RosError {
    RosError::new(context, e)
}

/// Nanoseconds since the Unix epoch (ROS time for stamps and attachments).
pub fn wall_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// The `[ros.tls]` identity as the loop's Zenoh link takes one, its relative paths
/// against `base_dir` (the scenario's folder); none without `[ros.tls]`.
pub fn tls_files(cfg: &RosConfig, base_dir: &std::path::Path) -> Option<TlsFiles> {
    let t = cfg.tls.as_ref()?;
    Some(TlsFiles {
        ca: base_dir.join(&t.ca),
        cert: base_dir.join(&t.cert),
        key: base_dir.join(&t.key),
    })
}

/// Checks the `[ros.tls]` files before the session opens, as the loop's are checked:
/// readable, PEM, the key the certificate's, the certificate the CA's; the error
/// names the field and the file (Zenoh reads them only when a link is made, and would
/// say nothing).
pub fn check_tls(cfg: &RosConfig, base_dir: &std::path::Path) -> Result<(), String> {
    let Some(f) = tls_files(cfg, base_dir) else {
        return Ok(());
    };
    let names = ["ros.tls.ca", "ros.tls.cert", "ros.tls.key"];
    tactile_transport::tls_files::check_as(&f.ca, &f.cert, &f.key, names)
}

/// The session's Zenoh configuration: peer mode, the `[ros]` endpoints, no multicast
/// scouting, mutual TLS with `[ros.tls]` (the loop link's settings), otherwise Zenoh's
/// defaults, which rmw_zenoh's router and nodes use (the loop link's low-latency
/// transport would not connect to them). Relative TLS paths are the working folder's:
/// a node resolves its scenario first.
pub fn session_config(cfg: &RosConfig) -> Result<zenoh::Config, RosError> {
    let mut c = zenoh::Config::default();
    let list = |v: &[String]| {
        let quoted: Vec<String> = v.iter().map(|e| format!("{e:?}")).collect();
        format!("[{}]", quoted.join(","))
    };
    for (key, value) in [
        ("mode", "\"peer\"".to_string()),
        ("connect/endpoints", list(&cfg.connect)),
        ("listen/endpoints", list(&cfg.listen)),
        ("scouting/multicast/enabled", "false".into()),
        ("connect/timeout_ms", "-1".into()),
        ("connect/exit_on_failure", "false".into()),
        // A full queue drops a message at once instead of waiting up to 1 ms (Zenoh's
        // default) for room: the loop publishes, and must not wait.
        (
            "transport/link/tx/queue/congestion_control/drop/wait_before_drop",
            "0".into(),
        ),
    ] {
        c.insert_json5(key, &value)
            .map_err(|e| err(&format!("ROS 2 Zenoh setting {key} = {value}"), e))?;
    }
    if let Some(t) = tls_files(cfg, std::path::Path::new("")) {
        t.apply(&mut c).map_err(|e| err("ROS 2 TLS (ros.tls)", e))?;
    }
    Ok(c)
}

/// One node on ROS 2: a Zenoh session and its node token.
pub struct RosNode {
    session: zenoh::Session,
    /// The `[ros]` endpoints it connects to, for messages.
    connect: Vec<String>,
    id: NodeId,
    next_id: AtomicU32,
    _token: LivelinessToken,
}

impl std::fmt::Debug for RosNode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RosNode")
            .field("id", &self.id)
            .finish_non_exhaustive()
    }
}

impl RosNode {
    /// Opens the session and declares node `name` in `[ros]`'s domain and namespace.
    pub fn open(cfg: &RosConfig, name: &str) -> Result<RosNode, RosError> {
        let session = zenoh::open(session_config(cfg)?)
            .wait()
            .map_err(|e| err("opening the ROS 2 Zenoh session", e))?;
        let id = NodeId {
            domain: cfg.domain_id,
            zid: session.zid().to_string(),
            nid: 0,
            namespace: cfg.namespace.clone(),
            name: name.to_string(),
        };
        let token = session
            .liveliness()
            .declare_token(id.node_token())
            .wait()
            .map_err(|e| err("declaring the ROS 2 node's liveliness token", e))?;
        Ok(RosNode {
            session,
            connect: cfg.connect.clone(),
            id,
            next_id: AtomicU32::new(1),
            _token: token,
        })
    }

    /// Whether the session reached anyone (a router or a peer); if not, what to check:
    /// a wait for a device that never began to connect says so instead of blaming the
    /// driver.
    pub fn unreached(&self) -> Option<String> {
        let info = self.session.info();
        if info.routers_zid().wait().next().is_some() || info.peers_zid().wait().next().is_some() {
            return None;
        }
        Some(if self.connect.is_empty() {
            "the ROS 2 session connects to no endpoint (ros.connect is empty) and no peer reached it".into()
        } else {
            format!(
                "the ROS 2 session reached none of ros.connect {:?}: is the router running there (ros2 run rmw_zenoh_cpp rmw_zenohd), are the address and port right, does a firewall let it through?",
                self.connect
            )
        })
    }

    /// `name` under the node's namespace (the live view's topics).
    pub fn in_namespace(&self, name: &str) -> String {
        format!("{}{name}", self.id.namespace)
    }

    fn token(
        &self,
        kind: EntityKind,
        topic: &str,
        ty: &str,
        qos: &str,
    ) -> Result<(String, LivelinessToken), RosError> {
        let eid = self.next_id.fetch_add(1, Ordering::Relaxed);
        let key = self
            .id
            .entity_token_qos(eid, kind, (topic, ty), qos)
            .ok_or_else(|| err(topic, format!("no type hash for {ty}")))?;
        let token = self
            .session
            .liveliness()
            .declare_token(key.clone())
            .wait()
            .map_err(|e| err(&format!("declaring the liveliness token of {topic}"), e))?;
        Ok((key, token))
    }

    /// A publisher of `ty` on `topic`.
    pub fn publisher(&self, topic: &str, ty: &str) -> Result<RosPublisher, RosError> {
        let (key, id) = self.announce(topic, ty, &rmw::qos_reliable(10))?;
        let publisher = self
            .session
            .declare_publisher(key)
            .congestion_control(CongestionControl::Drop)
            .express(true)
            .wait()
            .map_err(|e| err(&format!("declaring the publisher of {topic}"), e))?;
        Ok(RosPublisher {
            publisher,
            session: self.session.clone(),
            id,
        })
    }

    /// A publisher's data key expression and its identity on the graph: its token
    /// (with QoS `qos`) declared, its gid, its sequence numbers from 1.
    fn announce(&self, topic: &str, ty: &str, qos: &str) -> Result<(String, Announced), RosError> {
        let key = rmw::topic_key(self.id.domain, topic, ty)
            .ok_or_else(|| err(topic, format!("no type hash for {ty}")))?;
        let (token_key, token) = self.token(EntityKind::Publisher, topic, ty, qos)?;
        let id = Announced {
            gid: rmw::gid(&token_key),
            seq: AtomicI64::new(0),
            topic: topic.to_string(),
            _token: token,
        };
        Ok((key, id))
    }

    /// A transient-local publisher of `ty` on `topic`, as rmw_zenoh makes one for a
    /// durable QoS (`robot_state_publisher`'s `/robot_description`, `/tf_static`): an
    /// AdvancedPublisher that keeps its last `depth` messages for subscribers that come
    /// later, detectable by them, with sporadic heartbeats so a missed message is
    /// fetched again; its token says durability transient-local.
    pub fn latched_publisher(
        &self,
        topic: &str,
        ty: &str,
        depth: usize,
    ) -> Result<RosLatched, RosError> {
        use zenoh_ext::{AdvancedPublisherBuilderExt, CacheConfig, MissDetectionConfig};
        let (key, id) = self.announce(topic, ty, &rmw::qos_latched(depth as u32))?;
        let heartbeat = MissDetectionConfig::default().sporadic_heartbeat(LATCHED_HEARTBEAT);
        let publisher = self
            .session
            .declare_publisher(key)
            .congestion_control(CongestionControl::Drop)
            .cache(CacheConfig::default().max_samples(depth))
            .publisher_detection()
            .sample_miss_detection(heartbeat)
            .wait()
            .map_err(|e| err(&format!("declaring the publisher of {topic}"), e))?;
        Ok(RosLatched { publisher, id })
    }

    /// Offers `inbox` every message of `ty` on `topic`, from Zenoh's threads, as
    /// `decode` reads its CDR payload, with its arrival (ns on CLOCK_MONOTONIC); a
    /// sample of another type hash or without rmw_zenoh's attachment is offered as its
    /// rejection, never decoded.
    pub fn subscribe<T: Clone + Send + 'static>(
        &self,
        topic: &str,
        ty: &'static str,
        inbox: &Arc<Inbox<T>>,
        decode: impl Fn(&[u8]) -> Result<T, Reject> + Send + Sync + 'static,
    ) -> Result<RosSubscription, RosError> {
        let dds = rmw::dds_type(ty).ok_or_else(|| err(topic, format!("bad type {ty}")))?;
        let name = topic.trim_matches('/');
        let key = format!("{}/{name}/{dds}/*", self.id.domain);
        let (_, token) = self.token(EntityKind::Subscription, topic, ty, &rmw::qos_reliable(10))?;
        let fill = Arc::clone(inbox);
        let sub = self
            .session
            .declare_subscriber(key)
            .callback(move |sample| {
                let at = tactile_messages::clock::now_ns();
                let attachment = sample.attachment().map(|a| a.to_bytes());
                let got = admit(ty, sample.key_expr().as_str(), attachment.as_deref())
                    .and_then(|()| decode(&sample.payload().to_bytes()));
                fill.offer(got, at);
            })
            .wait()
            .map_err(|e| err(&format!("subscribing to {topic}"), e))?;
        Ok(RosSubscription {
            _sub: sub,
            _token: token,
        })
    }
}

/// A ROS 2 publisher: each put carries rmw_zenoh's attachment.
pub struct RosPublisher {
    publisher: zenoh::pubsub::Publisher<'static>,
    /// For the last message, put reliably (congestion control `Block`).
    session: zenoh::Session,
    id: Announced,
}

impl std::fmt::Debug for RosPublisher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RosPublisher")
            .field("topic", &self.id.topic)
            .finish_non_exhaustive()
    }
}

/// A publisher as the ROS 2 graph knows it: its token, its gid, its messages' count.
struct Announced {
    gid: [u8; 16],
    seq: AtomicI64,
    topic: String,
    _token: LivelinessToken,
}

impl Announced {
    /// rmw_zenoh's attachment of the next message: its sequence number (from 1), the
    /// wall clock, the gid.
    fn attachment(&self) -> Vec<u8> {
        let a = Attachment {
            seq: self.seq.fetch_add(1, Ordering::Relaxed) + 1,
            stamp_ns: wall_ns() as i64,
            gid: self.gid,
        };
        a.to_bytes().to_vec()
    }
}

/// rmw_zenoh's heartbeat period for a reliable transient-local publisher's sample miss
/// detection (its `SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD`, sporadic: only after a put).
const LATCHED_HEARTBEAT: std::time::Duration = std::time::Duration::from_millis(500);

/// A transient-local ROS 2 publisher ([`RosNode::latched_publisher`]).
pub struct RosLatched {
    publisher: zenoh_ext::AdvancedPublisher<'static>,
    id: Announced,
}

impl std::fmt::Debug for RosLatched {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RosLatched")
            .field("topic", &self.id.topic)
            .finish_non_exhaustive()
    }
}

impl RosLatched {
    /// Publishes one CDR message and keeps it for subscribers that come later; false
    /// if Zenoh refused it.
    pub fn put(&self, cdr: &[u8]) -> bool {
        self.publisher
            .put(cdr)
            .attachment(self.id.attachment())
            .wait()
            .is_ok()
    }
}

impl RosPublisher {
    /// Publishes one CDR message, dropped rather than waited for if the network is
    /// behind; false if Zenoh refused it.
    pub fn put(&self, cdr: &[u8]) -> bool {
        self.publisher
            .put(cdr)
            .attachment(self.id.attachment())
            .wait()
            .is_ok()
    }

    /// Publishes one CDR message that must arrive (the zero force at the end, a
    /// robot's hold): congestion control `Block`, so Zenoh waits for room rather than
    /// dropping it. Returns whether it was put, and whether a subscriber was matched.
    pub fn put_reliably(&self, cdr: &[u8]) -> (bool, bool) {
        let matched = self
            .publisher
            .matching_status()
            .wait()
            .is_ok_and(|m| m.matching());
        let put = self
            .session
            .put(self.publisher.key_expr().clone(), cdr)
            .congestion_control(CongestionControl::Block)
            .express(true)
            .attachment(self.id.attachment())
            .wait()
            .is_ok();
        (put, matched)
    }
}

/// A subscription, alive as long as this is.
pub struct RosSubscription {
    _sub: zenoh::pubsub::Subscriber<()>,
    _token: LivelinessToken,
}

impl std::fmt::Debug for RosSubscription {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RosSubscription").finish_non_exhaustive()
    }
}
