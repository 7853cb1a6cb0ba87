//! What a ROS 2 sample must carry before its payload is read: the type hash of its key
//! expression (`<domain>/<topic>/<type>/<hash>`) one the subscription's type has, and
//! rmw_zenoh's attachment. Pure: the subscription that asks is in
//! [`crate::rmw_node`].
//!
//! A subscription takes `<domain>/<topic>/<type>/*`, so that a Humble driver's samples
//! (its key ends in `TypeHashNotSupported`) reach it as a Jazzy driver's do; every
//! other hash is another type under the same name (another `.msg` of the same package
//! and name, whose layout need not match) and is dropped, counted, as rmw_zenoh drops
//! it by never matching its key. A sample without a well-formed attachment is not an
//! rmw_zenoh publisher's (rmw_zenoh drops it too): dropped, counted.

use crate::map::Reject;
use tactile_ros::rmw::{self, Attachment};

/// Checks a sample of `ty` that came on `key` with `attachment`.
pub fn admit(ty: &str, key: &str, attachment: Option<&[u8]>) -> Result<(), Reject> {
    let hash = key.rsplit('/').next().unwrap_or(key);
    if !rmw::hash_accepted(ty, hash) {
        return Err(Reject::WrongType(shorten(hash)));
    }
    let Some(bytes) = attachment else {
        return Err(Reject::Attachment("none".into()));
    };
    if Attachment::from_bytes(bytes).is_none() {
        return Err(Reject::Attachment(format!(
            "{} bytes, not rmw_zenoh's {} (sequence number, timestamp, gid)",
            bytes.len(),
            rmw::ATTACHMENT_LEN
        )));
    }
    Ok(())
}

/// A peer's hash for a message: at most 80 characters of it (a key chunk can be long).
fn shorten(hash: &str) -> String {
    match hash.char_indices().nth(80) {
        Some((i, _)) => format!("{}...", &hash[..i]),
        None => hash.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_ros::msg::{JointState, Message};

    fn attachment() -> [u8; rmw::ATTACHMENT_LEN] {
        Attachment {
            seq: 1,
            stamp_ns: 2,
            gid: [7; 16],
        }
        .to_bytes()
    }

    #[test]
    fn the_types_hash_and_humbles_pass_any_other_is_dropped() {
        let key = rmw::topic_key(0, "/phantom/joint_states", JointState::TYPE).expect("key");
        let a = attachment();
        assert_eq!(admit(JointState::TYPE, &key, Some(&a)), Ok(()));
        let humble = format!(
            "0/phantom/joint_states/sensor_msgs::msg::dds_::JointState_/{}",
            rmw::HUMBLE_HASH
        );
        assert_eq!(admit(JointState::TYPE, &humble, Some(&a)), Ok(()));
        let wrong = format!(
            "0/phantom/joint_states/sensor_msgs::msg::dds_::JointState_/RIHS01_{}",
            "0".repeat(64)
        );
        assert!(
            matches!(admit(JointState::TYPE, &wrong, Some(&a)), Err(Reject::WrongType(h)) if h.starts_with("RIHS01_000")),
        );
        // Another type's hash under this type's name.
        let other = rmw::type_hash("std_msgs/msg/String").expect("hash");
        let e = admit(JointState::TYPE, &format!("0/x/y/{other}"), Some(&a)).expect_err("other");
        assert!(e.to_string().contains("type hash"), "{e}");
        let long = format!("0/x/y/{}", "h".repeat(10_000));
        let e = admit(JointState::TYPE, &long, Some(&a)).expect_err("long");
        assert!(e.to_string().len() < 300, "{e}");
    }

    #[test]
    fn a_sample_without_rmw_zenohs_attachment_is_dropped() {
        let key = rmw::topic_key(0, "/j", JointState::TYPE).expect("key");
        let e = admit(JointState::TYPE, &key, None).expect_err("none");
        assert_eq!(e, Reject::Attachment("none".into()));
        let a = attachment();
        let e = admit(JointState::TYPE, &key, Some(&a[..20])).expect_err("short");
        assert!(e.to_string().contains("20 bytes"), "{e}");
        let mut bad = a;
        bad[16] = 15;
        assert!(
            admit(JointState::TYPE, &key, Some(&bad)).is_err(),
            "gid length"
        );
    }
}
