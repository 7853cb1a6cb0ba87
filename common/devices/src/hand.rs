//! A 6-DoF haptic device as the master's loop takes it: the handle's point (three
//! joints in the paper's convention, or a position a driver measures) and orientation
//! (through the gimbal's own chain of the device's URDF, or a driver's `PoseStamped`),
//! and the clutch (a `Bool`, a `Joy` button, a Touch's `OmniButtonEvent`), each
//! decoded and checked; and the force in the message each driver takes. Pure: the
//! messages come from [`crate::ros_hand`] (or a test).

use crate::map::{JointMap, Reject};
use nalgebra::Matrix3;
use tactile_chain::Chain;
use tactile_ros::hand_msg::{Bool, Joy, OmniButtonEvent, OmniFeedback};
use tactile_ros::msg::{
    Decode, Float64MultiArray, Header, JointState, Message, PoseStamped, WrenchStamped,
};
use tactile_scenario::{ClutchConfig, ForceMessage, FrameRotation, OmniButton};

/// How far a driver's quaternion's norm may be from one (drivers send f64 from a
/// normalized rotation; a float32 pipeline still lands within 1e-6).
pub const UNIT_TOLERANCE: f64 = 1e-3;

/// How far a gimbal joint may read from zero, rad: any encoder's angle, wrapped or
/// offset by the driver, is within two turns; beyond is a broken value. (The
/// omni_common URDF's limits are not used: they do not cover its own driver's range.)
pub const GIMBAL_RANGE: f64 = 4.0 * std::f64::consts::PI;

/// The handle at one reading.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Hand {
    /// Three joint angles in the paper's convention (input `joints`), or the handle's
    /// position, m, in the device's base frame (input `pose`).
    pub point: [f64; 3],
    /// The handle's orientation in the master's (paper's, or the pose device's) frame,
    /// `[x, y, z, w]`; `None` for a 3-DoF device.
    pub rotation: Option<[f64; 4]>,
}

/// A device's gimbal: the chain of its URDF from its base to the link in the hand, read
/// from the driver's `JointState` by name.
#[derive(Debug, Clone)]
pub struct Gimbal {
    chain: Chain,
    names: Vec<String>,
    /// The URDF base's axes in the master's frame.
    frame: Matrix3<f64>,
}

impl Gimbal {
    /// The gimbal of the URDF text `xml` from `base` to `tip`, its base turned by
    /// `frame` into the master's.
    pub fn new(
        xml: &str,
        base: &str,
        tip: &str,
        frame: &FrameRotation,
    ) -> Result<Gimbal, tactile_chain::Error> {
        let robot = tactile_chain::Robot::parse(xml)?;
        Gimbal::of_robot(&robot, base, tip, frame)
    }

    /// The gimbal of the URDF model `robot` (read once by the master,
    /// [`tactile_chain::file::read`]) from `base` to `tip`, its base turned by `frame`.
    pub fn of_robot(
        robot: &tactile_chain::Robot,
        base: &str,
        tip: &str,
        frame: &FrameRotation,
    ) -> Result<Gimbal, tactile_chain::Error> {
        let chain = Chain::new(robot, base, tip)?;
        let names = chain.dofs.iter().map(|d| d.name.clone()).collect();
        let m = frame.matrix();
        Ok(Gimbal {
            chain,
            names,
            frame: Matrix3::from_fn(|i, j| m[i][j]),
        })
    }

    /// The chain's joints, in order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The tip's orientation for the chain's joint values `q` (the driver's), in the
    /// master's frame.
    pub fn orientation(&self, q: &[f64]) -> Matrix3<f64> {
        self.frame * self.chain.fk(q).r
    }

    /// The tip's orientation from a `JointState`: every joint of the chain present,
    /// finite and within [`GIMBAL_RANGE`].
    pub fn read(&self, js: &JointState) -> Result<[f64; 4], Reject> {
        let mut q = Vec::with_capacity(self.names.len());
        for name in &self.names {
            let v = crate::map::position_of(js, name)?;
            if v.abs() > GIMBAL_RANGE {
                return Err(Reject::OutOfRange {
                    joint: name.clone(),
                    value: v,
                    min: -GIMBAL_RANGE,
                    max: GIMBAL_RANGE,
                });
            }
            q.push(v);
        }
        Ok(quaternion(&self.orientation(&q)))
    }
}

pub use tactile_chain::spatial::quaternion;

/// How far from the device's base a pose's position may be, m: a desk device reaches a
/// few tens of centimetres; beyond two metres is a broken value or a driver in the wrong
/// unit (millimetres), refused before it can reach the robot.
pub const POSE_RANGE: f64 = 2.0;

/// A joint device's reading from a CDR `JointState`: three joints through `map`, and
/// with a `gimbal` the orientation.
pub fn joints_cdr(map: &JointMap, gimbal: Option<&Gimbal>, cdr: &[u8]) -> Result<Hand, Reject> {
    let js = crate::map::joint_state_cdr(cdr)?;
    Ok(Hand {
        point: map.angles(&js)?,
        rotation: gimbal.map(|g| g.read(&js)).transpose()?,
    })
}

/// A pose device's reading from a CDR `PoseStamped`: finite, its orientation a unit
/// quaternion (normalized).
pub fn pose_cdr(cdr: &[u8]) -> Result<Hand, Reject> {
    let p = PoseStamped::from_cdr(cdr)?;
    if !p.position.iter().all(|v| v.is_finite()) {
        return Err(Reject::BadPose("position is not finite".into()));
    }
    if p.position.iter().any(|v| v.abs() > POSE_RANGE) {
        return Err(Reject::BadPose(format!(
            "position {:?} m is more than {POSE_RANGE} m from the base",
            p.position
        )));
    }
    let q = p.orientation;
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(n.is_finite() && (n - 1.0).abs() <= UNIT_TOLERANCE) {
        return Err(Reject::BadPose(format!(
            "orientation {q:?} has norm {n}, not 1"
        )));
    }
    Ok(Hand {
        point: p.position,
        rotation: Some(q.map(|v| v / n)),
    })
}

/// The clutch's state (true: engaged) from a CDR message of the kind `cfg` names.
pub fn clutch_cdr(cfg: &ClutchConfig, cdr: &[u8]) -> Result<bool, Reject> {
    match cfg {
        ClutchConfig::None => Ok(true),
        ClutchConfig::Bool { .. } => Ok(Bool::from_cdr(cdr)?.data),
        ClutchConfig::Joy { button, .. } => {
            let j = Joy::from_cdr(cdr)?;
            j.buttons
                .get(*button as usize)
                .map(|b| *b == 1)
                .ok_or_else(|| Reject::Missing(format!("buttons[{button}]")))
        }
        ClutchConfig::OmniButton { button, .. } => {
            let b = OmniButtonEvent::from_cdr(cdr)?;
            for (field, value) in [
                ("grey_button", b.grey_button),
                ("white_button", b.white_button),
            ] {
                if value != 0 && value != 1 {
                    return Err(Reject::BadButton { field, value });
                }
            }
            Ok(match button {
                OmniButton::Grey => b.grey_button == 1,
                OmniButton::White => b.white_button == 1,
            })
        }
    }
}

/// The ROS 2 type a force goes out in.
pub fn force_type(kind: ForceMessage) -> &'static str {
    match kind {
        ForceMessage::Wrench => WrenchStamped::TYPE,
        ForceMessage::OmniFeedback => OmniFeedback::TYPE,
        ForceMessage::Float64MultiArray => Float64MultiArray::TYPE,
    }
}

/// The force `f` (N, the device's frame) in the message `kind`, stamped `ns` in `frame`
/// where the message has a header.
pub fn force_cdr(kind: ForceMessage, f: [f64; 3], ns: u64, frame: &str) -> Vec<u8> {
    match kind {
        ForceMessage::Wrench => WrenchStamped {
            header: Header::at(ns, frame),
            force: f,
            torque: [0.0; 3],
        }
        .to_cdr(),
        ForceMessage::OmniFeedback => OmniFeedback {
            force: f,
            position: [0.0; 3],
        }
        .to_cdr(),
        ForceMessage::Float64MultiArray => Float64MultiArray { data: f.to_vec() }.to_cdr(),
    }
}

#[cfg(test)]
#[path = "hand_tests.rs"]
mod tests;
