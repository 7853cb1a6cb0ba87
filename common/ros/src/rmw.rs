//! What ROS 2's Zenoh middleware (rmw_zenoh, `docs/design.md`) puts on the wire besides
//! the CDR payload, so that `ros2 topic list/echo` on a host running rmw_zenoh sees a
//! Tactile node and ROS 2 publishers reach it. Pure: strings and bytes only; the Zenoh
//! session that uses them is in `tactile-devices`.
//!
//! - Data key expression: `<domain>/<topic without its leading and trailing
//!   slash>/<pkg>::msg::dds_::<Type>_/RIHS01_<sha256 hex>`.
//! - Attachment of every sample, as zenoh-ext serializes `(i64, i64, [u8; 16])`:
//!   sequence number (from 1 per publisher), source timestamp (ns since the Unix
//!   epoch), LEB128 length 16, the publisher's 16-byte gid. 33 bytes.
//! - Liveliness tokens under `@ros2_lv/`: a node's and each of its publishers' and
//!   subscriptions', with `/` in names written `%` and empty parts as `%`.

/// The RIHS01 type hashes (ROS 2 Jazzy) of the types Tactile publishes and takes, as
/// `rosidl` generates them: sha256 of the type description. Checked against rosbags'
/// own computation from the definitions by the stand-ins of `tests/ros2.rs`
/// (`tests/ros2_standin.py` parses Tactile's tokens and compares their hashes).
pub const TYPE_HASHES: &[(&str, &str)] = &[
    (
        "std_msgs/msg/String",
        "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    ),
    (
        "sensor_msgs/msg/JointState",
        "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
    ),
    (
        "geometry_msgs/msg/PoseStamped",
        "RIHS01_10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8",
    ),
    (
        "std_msgs/msg/Bool",
        "RIHS01_feb91e995ff9ebd09c0cb3d2aed18b11077585839fb5db80193b62d74528f6c9",
    ),
    (
        "sensor_msgs/msg/Joy",
        "RIHS01_0d356c79cad3401e35ffeb75a96a96e08be3ef896b8b83841d73e890989372c5",
    ),
    (
        "omni_msgs/msg/OmniButtonEvent",
        "RIHS01_3d8e3c256b4d68ef6679f98b28e039d4dc1a01fe243d8b286137c73157937d78",
    ),
    (
        "omni_msgs/msg/OmniFeedback",
        "RIHS01_ba84a6b698946ddb497c4d4b2062955836546f699b10724f3357b0a82c41dfff",
    ),
    (
        "geometry_msgs/msg/WrenchStamped",
        "RIHS01_8dc3deaf06b2ab281f9f9a742a8961c328ca7cec16e3fd6586d3a5c83fa78f77",
    ),
    (
        "std_msgs/msg/Float64MultiArray",
        "RIHS01_1025ddc6b9552d191f89ef1a8d2f60f3d373e28b283d8891ddcc974e8c55397f",
    ),
    (
        "trajectory_msgs/msg/JointTrajectory",
        "RIHS01_179b33eba59d676f6d967ac71fe35e7ca2f64b2f3928f4a018cec115e213796e",
    ),
    (
        "tf2_msgs/msg/TFMessage",
        "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    ),
    (
        "visualization_msgs/msg/MarkerArray",
        "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
    ),
    (
        "tactile_msgs/msg/SampleTiming",
        "RIHS01_8161fc73d1a4857e4cd208d0e09767eb51a86909b46e9a78ff2f7fa9c623558d",
    ),
];

/// What Humble's rmw_zenoh writes where a type hash goes (Humble has none; its
/// messages' layouts are Jazzy's).
pub const HUMBLE_HASH: &str = "TypeHashNotSupported";

/// True if `hash`, the last chunk of a sample's key, is one `ty` is published under:
/// its RIHS01 hash, or Humble's [`HUMBLE_HASH`].
pub fn hash_accepted(ty: &str, hash: &str) -> bool {
    hash == HUMBLE_HASH || type_hash(ty) == Some(hash)
}

/// The RIHS01 hash of `ty` (`pkg/msg/Type`).
pub fn type_hash(ty: &str) -> Option<&'static str> {
    TYPE_HASHES.iter().find(|(t, _)| *t == ty).map(|(_, h)| *h)
}

/// The DDS-mangled type name rmw_zenoh uses: `std_msgs/msg/String` ->
/// `std_msgs::msg::dds_::String_`.
pub fn dds_type(ty: &str) -> Option<String> {
    let mut parts = ty.split('/');
    let (Some(pkg), Some(kind), Some(name), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return None;
    };
    Some(format!("{pkg}::{kind}::dds_::{name}_"))
}

/// The data key expression of `topic` (absolute) carrying `ty` in `domain`.
pub fn topic_key(domain: u32, topic: &str, ty: &str) -> Option<String> {
    let name = topic.strip_prefix('/').unwrap_or(topic);
    let name = name.strip_suffix('/').unwrap_or(name);
    Some(format!(
        "{domain}/{name}/{}/{}",
        dds_type(ty)?,
        type_hash(ty)?
    ))
}

/// A name in a liveliness token: every `/` as `%`, and `%` for an empty one.
pub fn mangle(name: &str) -> String {
    if name.is_empty() {
        "%".into()
    } else {
        name.replace('/', "%")
    }
}

/// The QoS of a token for reliable, volatile, keep-last `depth` delivery (every other
/// setting rmw_zenoh's default, left empty): `::,10:,:,:,,` for depth 10.
pub fn qos_reliable(depth: u32) -> String {
    format!("::,{depth}:,:,:,,")
}

/// The QoS of a token for reliable, transient-local (durability 1), keep-last `depth`
/// delivery, what `robot_state_publisher` gives `/robot_description` and
/// `/tf_static`: `:1:,1:,:,:,,` for depth 1.
pub fn qos_latched(depth: u32) -> String {
    format!(":1:,{depth}:,:,:,,")
}

/// Where a token's node is: domain, session id (Zenoh's id as it prints), node id,
/// namespace and name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeId {
    /// ROS_DOMAIN_ID.
    pub domain: u32,
    /// The Zenoh session id, as `ZenohId` displays it (lowercase hex).
    pub zid: String,
    /// The node's id within its session.
    pub nid: u32,
    /// Namespace, `""` or `/name`.
    pub namespace: String,
    /// Node name.
    pub name: String,
}

/// A publisher's or subscription's kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntityKind {
    /// `MP`.
    Publisher,
    /// `MS`.
    Subscription,
}

impl NodeId {
    fn prefix(&self, eid: u32, kind: &str) -> String {
        format!(
            "@ros2_lv/{}/{}/{}/{eid}/{kind}/%/{}/{}",
            self.domain,
            self.zid,
            self.nid,
            mangle(&self.namespace),
            mangle(&self.name)
        )
    }

    /// The node's own token: `@ros2_lv/<domain>/<zid>/<nid>/<nid>/NN/%/<ns>/<name>`.
    pub fn node_token(&self) -> String {
        self.prefix(self.nid, "NN")
    }

    /// A publisher's or subscription's token, reliable, volatile, depth 10.
    pub fn entity_token(
        &self,
        eid: u32,
        kind: EntityKind,
        topic: &str,
        ty: &str,
    ) -> Option<String> {
        self.entity_token_qos(eid, kind, (topic, ty), &qos_reliable(10))
    }

    /// A publisher's or subscription's token with the QoS `qos` (as [`qos_reliable`]
    /// or [`qos_latched`] write it).
    pub fn entity_token_qos(
        &self,
        eid: u32,
        kind: EntityKind,
        (topic, ty): (&str, &str),
        qos: &str,
    ) -> Option<String> {
        let k = match kind {
            EntityKind::Publisher => "MP",
            EntityKind::Subscription => "MS",
        };
        Some(format!(
            "{}/{}/{}/{}/{}",
            self.prefix(eid, k),
            mangle(topic),
            dds_type(ty)?,
            type_hash(ty)?,
            qos
        ))
    }
}

/// A publisher's gid: 16 bytes, stable for its token (128-bit FNV-1a of it; rmw_zenoh
/// hashes the token too, with XXH3, and peers only compare gids for equality).
pub fn gid(token: &str) -> [u8; 16] {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    let h = token
        .bytes()
        .fold(OFFSET, |h, b| (h ^ u128::from(b)).wrapping_mul(PRIME));
    h.to_le_bytes()
}

/// A sample's attachment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Attachment {
    /// The publisher's sequence number, from 1.
    pub seq: i64,
    /// When it was published, ns since the Unix epoch.
    pub stamp_ns: i64,
    /// The publisher's gid.
    pub gid: [u8; 16],
}

/// Bytes of an attachment.
pub const ATTACHMENT_LEN: usize = 33;

impl Attachment {
    /// The 33 bytes: i64 LE, i64 LE, LEB128 16, the gid.
    pub fn to_bytes(&self) -> [u8; ATTACHMENT_LEN] {
        let mut b = [0u8; ATTACHMENT_LEN];
        b[..8].copy_from_slice(&self.seq.to_le_bytes());
        b[8..16].copy_from_slice(&self.stamp_ns.to_le_bytes());
        b[16] = 16;
        b[17..].copy_from_slice(&self.gid);
        b
    }

    /// Reads an attachment (bytes after the 33rd are ignored, as rmw_zenoh does).
    pub fn from_bytes(b: &[u8]) -> Option<Attachment> {
        if b.len() < ATTACHMENT_LEN || b[16] != 16 {
            return None;
        }
        let i64_at = |k: usize| {
            let mut a = [0u8; 8];
            a.copy_from_slice(&b[k..k + 8]);
            i64::from_le_bytes(a)
        };
        let mut gid = [0u8; 16];
        gid.copy_from_slice(&b[17..33]);
        Some(Attachment {
            seq: i64_at(0),
            stamp_ns: i64_at(8),
            gid,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_match_rmw_zenohs_design_document() {
        // The example of rmw_zenoh's docs/design.md.
        assert_eq!(
            topic_key(0, "/chatter", "std_msgs/msg/String").as_deref(),
            Some("0/chatter/std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18")
        );
        assert_eq!(
            topic_key(3, "/robot1/joint_states", "sensor_msgs/msg/JointState").map(|k| k
                .starts_with("3/robot1/joint_states/sensor_msgs::msg::dds_::JointState_/RIHS01_")),
            Some(true)
        );
        assert_eq!(topic_key(0, "/x", "foo/msg/Bar"), None, "no hash, no key");
        let node = NodeId {
            domain: 0,
            zid: "aac3178e146ba6f1fc6e6a4085e77f21".into(),
            nid: 0,
            namespace: String::new(),
            name: "listener".into(),
        };
        assert_eq!(
            node.node_token(),
            "@ros2_lv/0/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"
        );
        assert_eq!(
            node.entity_token(10, EntityKind::Subscription, "/chatter", "std_msgs/msg/String").as_deref(),
            Some("@ros2_lv/0/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18/::,10:,:,:,,")
        );
    }

    #[test]
    fn an_attachment_is_33_bytes_and_reads_back() {
        let a = Attachment {
            seq: 1,
            stamp_ns: -2,
            gid: gid("@ros2_lv/0/x"),
        };
        let b = a.to_bytes();
        assert_eq!(&b[..8], &[1, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(b[16], 16);
        assert_eq!(Attachment::from_bytes(&b), Some(a));
        assert_eq!(Attachment::from_bytes(&b[..32]), None);
        assert_ne!(gid("@ros2_lv/0/x"), gid("@ros2_lv/0/y"));
    }

    #[test]
    fn every_topic_and_device_type_has_a_hash() {
        for t in crate::topics::TOPICS {
            assert!(type_hash(t.ty).is_some(), "{}", t.ty);
        }
        assert!(type_hash("std_msgs/msg/Float64MultiArray").is_some());
    }
}
