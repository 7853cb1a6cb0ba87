//! A simulated URDF arm in the live view as `robot_state_publisher` serves a robot: its
//! URDF on `/robot_description` and its fixed joints on `/tf_static`, both
//! transient-local (kept for a viewer that starts later, as rmw_zenoh keeps a durable
//! publisher's messages), and its moving joints on `/tf` with every view sample. A real
//! arm's own stack runs `robot_state_publisher`, so only the simulated arm is served.

use crate::rmw_node::{wall_ns, RosLatched, RosNode, RosPublisher};
use crate::RosError;
use tactile_chain::{Frame, Tree};
use tactile_ros::msg::{Header, Message, StringMsg, TfMessage, TransformStamped};
use tactile_ros::view::ArmSample;

/// What the live view needs of a URDF arm: its URDF as written, and its tree.
#[derive(Debug, Clone)]
pub struct LiveArm {
    /// The URDF's text, served as it is.
    pub urdf: String,
    /// Its joints, every link's transform.
    pub tree: Tree,
}

/// The arm's publishers: the description and the fixed joints, put once and kept,
/// and `/tf`.
#[derive(Debug)]
pub struct ArmPublishers {
    _description: RosLatched,
    _fixed: RosLatched,
    tf: RosPublisher,
    tree: Tree,
}

impl ArmPublishers {
    /// Declares the three topics in `node`'s namespace and puts the description and
    /// the fixed joints (stamped now).
    pub fn start(node: &RosNode, arm: LiveArm) -> Result<ArmPublishers, RosError> {
        let topic = |t: &str| node.in_namespace(t);
        let description =
            node.latched_publisher(&topic("/robot_description"), StringMsg::TYPE, 1)?;
        let fixed = node.latched_publisher(&topic("/tf_static"), TfMessage::TYPE, 1)?;
        let tf = node.publisher(&topic("/tf"), TfMessage::TYPE)?;
        let stamp = wall_ns();
        description.put(&StringMsg { data: arm.urdf }.to_cdr());
        let transforms = arm
            .tree
            .fixed()
            .map(|(p, c, f)| transform(p, c, &f, stamp))
            .collect();
        fixed.put(&TfMessage { transforms }.to_cdr());
        Ok(ArmPublishers {
            _description: description,
            _fixed: fixed,
            tf,
            tree: arm.tree,
        })
    }

    /// `/tf` for the sample `s` (its joints by name; the others at rest), stamped
    /// `stamp`; true if it was put.
    pub fn put_tf(&self, stamp: u64, s: &ArmSample) -> bool {
        let value = |name: &str| {
            s.names
                .iter()
                .position(|n| n == name)
                .and_then(|k| s.q.get(k).copied())
        };
        let transforms = self
            .tree
            .moving(&value)
            .map(|(p, c, f)| transform(p, c, &f, stamp))
            .collect();
        self.tf.put(&TfMessage { transforms }.to_cdr())
    }
}

/// One joint's transform, `child` in `parent`.
fn transform(parent: &str, child: &str, f: &Frame, stamp: u64) -> TransformStamped {
    TransformStamped {
        header: Header::at(stamp, parent),
        child_frame_id: child.to_string(),
        translation: f.p.into(),
        rotation: tactile_chain::spatial::quaternion(&f.r),
    }
}
