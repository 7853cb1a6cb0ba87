//! A robot arm from its URDF as the loop takes it over ROS 2: its chain's joints read
//! by name from a `JointState` (any order, other joints ignored) and checked (present,
//! finite, within the URDF's limits), the gate's range and step from the same limits,
//! and a measured wrench turned from the frame it is in (a flange, a sensor: any link
//! of the URDF) into the base's. Pure: the messages come from [`crate::ros_arm`] (or a
//! test).

use crate::map::Reject;
use tactile_chain::{Chain, Frame, Tree};
use tactile_math::joints::{Joints, TooManyJoints};
use tactile_ros::msg::{Decode, JointState, WrenchStamped};
use tactile_scenario::TorqueAbout;

/// How far past a URDF limit a reading may be and still be taken, rad or m: encoders
/// report a little beyond the limit a controller stops at.
pub const LIMIT_MARGIN: f64 = 0.01;

/// The fastest a joint is commanded where the URDF gives no velocity limit, rad/s or
/// m/s.
pub const DEFAULT_VELOCITY: f64 = 2.0;

/// A chain's joints, by name.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmJointMap {
    /// The chain's joint names, in its order (the commands' order).
    pub names: Vec<String>,
    lower: Joints,
    upper: Joints,
    velocity: Joints,
}

impl ArmJointMap {
    /// The joints of `chain`, if it has no more than a [`Joints`] holds.
    pub fn of(chain: &Chain) -> Result<ArmJointMap, TooManyJoints> {
        let each = |f: fn(&tactile_chain::Dof) -> f64| {
            let v: Vec<f64> = chain.dofs.iter().map(f).collect();
            Joints::from_slice(&v)
        };
        Ok(ArmJointMap {
            names: chain.dofs.iter().map(|d| d.name.clone()).collect(),
            lower: each(|d| d.lower)?,
            upper: each(|d| d.upper)?,
            velocity: each(|d| {
                if d.velocity.is_finite() {
                    d.velocity
                } else {
                    DEFAULT_VELOCITY
                }
            })?,
        })
    }

    /// The chain's joint values from a CDR `JointState`.
    pub fn positions_cdr(&self, cdr: &[u8]) -> Result<Joints, Reject> {
        self.positions(&crate::map::joint_state_cdr(cdr)?)
    }

    /// The chain's joint values from a `JointState`, in the chain's order.
    pub fn positions(&self, js: &JointState) -> Result<Joints, Reject> {
        let mut q = self.lower;
        for (i, name) in self.names.iter().enumerate() {
            let v = crate::map::position_of(js, name)?;
            let (min, max) = (self.lower[i] - LIMIT_MARGIN, self.upper[i] + LIMIT_MARGIN);
            if !(min..=max).contains(&v) {
                return Err(Reject::OutOfRange {
                    joint: name.clone(),
                    value: v,
                    min,
                    max,
                });
            }
            q[i] = v;
        }
        Ok(q)
    }

    /// The gate's range (the URDF's limits) and largest step in `t_s` seconds (its
    /// velocity limits).
    pub fn gate(&self, t_s: f64) -> crate::gate::JointGate<Joints> {
        let mut step = self.velocity;
        step.iter_mut().for_each(|v| *v *= t_s);
        crate::gate::JointGate::new(self.lower, self.upper, step)
    }
}

/// A measured wrench, force (N) and torque (N m) about the frame's origin, and the
/// frame it is in.
pub type FramedForce = ([f64; 3], [f64; 3], String);

/// The wrench of a CDR `WrenchStamped` and its frame, if `tree` has it (an empty frame
/// is taken as the base's); not finite, or in a frame the URDF lacks, is rejected.
pub fn framed_force_cdr(
    cdr: &[u8],
    tree: &Tree,
    base: &str,
    max_force: f64,
) -> Result<FramedForce, Reject> {
    let w = WrenchStamped::from_cdr(cdr)?;
    if !w.torque.iter().all(|f| f.is_finite()) {
        return Err(Reject::ForceNotFinite);
    }
    crate::map::plausible(w.force, max_force)?;
    let frame = match w.header.frame_id.as_str() {
        "" => base.to_string(),
        f => f.to_string(),
    };
    let none = |_: &str| None;
    if tree.pose(&frame, &none).is_none() {
        return Err(Reject::UnknownFrame(frame));
    }
    Ok((w.force, w.torque, frame))
}

/// The wrench `(f, t, frame)` turned into `base`'s axes, the arm's joints at `q`
/// (named by `names`): the force, and the torque about the tool `tip`'s origin
/// (`t + (sensor - tool) x f` for a torque about the frame's origin; turned only for
/// one already about the tool), as the loop's h(n) carries them.
pub fn in_base(
    tree: &Tree,
    (base, tip, about): (&str, &str, TorqueAbout),
    names: &[String],
    q: &[f64],
    (f, t, frame): &FramedForce,
) -> ([f64; 3], [f64; 3]) {
    let value = |n: &str| {
        names
            .iter()
            .position(|m| m == n)
            .and_then(|k| q.get(k).copied())
    };
    let poses = (
        tree.pose(base, &value),
        tree.pose(frame, &value),
        tree.pose(tip, &value),
    );
    let (Some(b), Some(s), Some(tool)) = poses else {
        return (*f, *t);
    };
    let (sensor, tool): (Frame, Frame) = (b.inverse().then(&s), b.inverse().then(&tool));
    let force = sensor.r * nalgebra::Vector3::from(*f);
    let lever = match about {
        TorqueAbout::Frame => sensor.p - tool.p,
        TorqueAbout::Tool => nalgebra::Vector3::zeros(),
    };
    let torque = sensor.r * nalgebra::Vector3::from(*t) + lever.cross(&force);
    (force.into(), torque.into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_chain::Robot;
    use tactile_ros::msg::{Header, Message};

    const PANDA: &str = include_str!("../../../deploy/robots/panda.urdf");

    fn panda() -> (Chain, Tree) {
        let r = Robot::parse(PANDA).expect("urdf");
        (
            Chain::new(&r, "panda_link0", "panda_hand").expect("chain"),
            Tree::new(&r).expect("tree"),
        )
    }

    #[test]
    fn joints_are_read_by_name_in_any_order_and_checked() {
        let (chain, _) = panda();
        let m = ArmJointMap::of(&chain).expect("seven joints");
        let mut names: Vec<String> = m.names.iter().rev().cloned().collect();
        names.push("panda_finger_joint1".into());
        let mut js = JointState {
            header: Header::at(1, ""),
            name: names,
            position: vec![0.1, 1.0, 0.0, -1.5, 0.0, -0.5, 0.2, 0.04],
            ..JointState::default()
        };
        assert_eq!(
            m.positions_cdr(&js.to_cdr()),
            Ok(Joints::from_slice(&[0.2, -0.5, 0.0, -1.5, 0.0, 1.0, 0.1]).expect("seven"))
        );
        js.position[3] = 0.5; // panda_joint4 is in [-3.0718, -0.0698]
        assert!(
            matches!(m.positions(&js), Err(Reject::OutOfRange { joint, .. }) if joint == "panda_joint4")
        );
        js.position[3] = f64::NAN;
        assert_eq!(
            m.positions(&js),
            Err(Reject::NotFinite("panda_joint4".into()))
        );
        js.position[3] = -1.5;
        js.name.remove(0);
        js.position.remove(0);
        assert_eq!(
            m.positions(&js),
            Err(Reject::Missing("panda_joint7".into()))
        );
        // A joint named twice drops the message (issue 51).
        js.name.push("panda_joint6".into());
        js.position.push(0.3);
        assert_eq!(
            m.positions_cdr(&js.to_cdr()),
            Err(Reject::DuplicateJoint("panda_joint6".into()))
        );
    }

    #[test]
    fn a_wrench_in_the_hand_turns_into_the_base() {
        let (chain, tree) = panda();
        let names = ArmJointMap::of(&chain).expect("seven joints").names;
        // The shipped Panda scenario's home: franka_ros' ready pose.
        let sc = include_str!("../../../deploy/scenarios/panda.toml");
        let sc = tactile_scenario::Scenario::from_toml_str(sc).expect("scenario");
        let q = sc.slave.arm.expect("arm").home;
        let w = WrenchStamped {
            header: Header::at(1, "panda_hand"),
            force: [0.0, 0.0, 5.0],
            torque: [0.0; 3],
        };
        let framed = framed_force_cdr(&w.to_cdr(), &tree, "panda_link0", 1000.0).expect("framed");
        let (f, t) = in_base(
            &tree,
            ("panda_link0", "panda_hand", TorqueAbout::Frame),
            &names,
            &q,
            &framed,
        );
        // At the ready pose the hand's z points down; no torque about the hand itself.
        let hand = chain.fk(&q).r * nalgebra::Vector3::new(0.0, 0.0, 5.0);
        assert!((f[2] - hand.z).abs() < 1e-12 && f[2] < -4.99, "{f:?}");
        assert_eq!(t, [0.0; 3]);
        // The same wrench measured in the base (its torque about the base's origin):
        // about the hand the torque is the base's minus p_hand x f, zero again.
        let p = chain.fk(&q).p;
        let fb = nalgebra::Vector3::from(f);
        let at_base = WrenchStamped {
            header: Header::at(1, ""),
            force: f,
            torque: p.cross(&fb).into(),
        };
        let framed =
            framed_force_cdr(&at_base.to_cdr(), &tree, "panda_link0", 1000.0).expect("framed");
        let (f2, t2) = in_base(
            &tree,
            ("panda_link0", "panda_hand", TorqueAbout::Frame),
            &names,
            &q,
            &framed,
        );
        assert!(
            f2.iter().zip(&f).all(|(a, b)| (a - b).abs() < 1e-12),
            "{f2:?}"
        );
        assert!(t2.iter().all(|x| x.abs() < 1e-12), "{t2:?}");
        // A torque measured in the hand turns with it.
        let twist = WrenchStamped {
            header: Header::at(1, "panda_hand"),
            force: [0.0; 3],
            torque: [0.2, 0.0, 0.0],
        };
        let framed =
            framed_force_cdr(&twist.to_cdr(), &tree, "panda_link0", 1000.0).expect("framed");
        let (_, t3) = in_base(
            &tree,
            ("panda_link0", "panda_hand", TorqueAbout::Frame),
            &names,
            &q,
            &framed,
        );
        let want = chain.fk(&q).r * nalgebra::Vector3::new(0.2, 0.0, 0.0);
        assert!(
            (nalgebra::Vector3::from(t3) - want).norm() < 1e-12,
            "{t3:?}"
        );
        // Franka's base-frame wrench has its torque about the tool already: turned
        // only, not moved (the force's moment about the base would otherwise add in).
        let franka = WrenchStamped {
            header: Header::at(1, ""),
            force: f,
            torque: [0.1, 0.0, 0.0],
        };
        let framed =
            framed_force_cdr(&franka.to_cdr(), &tree, "panda_link0", 1000.0).expect("framed");
        let about = ("panda_link0", "panda_hand", TorqueAbout::Tool);
        let (_, t4) = in_base(&tree, about, &names, &q, &framed);
        assert_eq!(t4, [0.1, 0.0, 0.0]);
        let mut bad = w.clone();
        bad.header.frame_id = "tool0_controller".into();
        assert_eq!(
            framed_force_cdr(&bad.to_cdr(), &tree, "panda_link0", 1000.0),
            Err(Reject::UnknownFrame("tool0_controller".into()))
        );
        bad.header.frame_id = String::new();
        bad.force[0] = f64::INFINITY;
        assert_eq!(
            framed_force_cdr(&bad.to_cdr(), &tree, "panda_link0", 1000.0),
            Err(Reject::ForceNotFinite)
        );
        // A force no sensor measures: refused past max_force, taken at it.
        bad.force = [0.0, 0.0, 1e6];
        assert_eq!(
            framed_force_cdr(&bad.to_cdr(), &tree, "panda_link0", 1000.0),
            Err(Reject::ForceImplausible {
                force: 1e6,
                max: 1000.0
            })
        );
        bad.force = [0.0, 600.0, 800.0];
        assert!(framed_force_cdr(&bad.to_cdr(), &tree, "panda_link0", 1000.0).is_ok());
        bad.torque[0] = f64::NAN;
        assert_eq!(
            framed_force_cdr(&bad.to_cdr(), &tree, "panda_link0", 1000.0),
            Err(Reject::ForceNotFinite)
        );
    }
}
