//! A device's or robot's joints as the loop takes them: three named joints of a
//! `JointState` mapped to the paper's angles (sign, unit, offset) and checked (present,
//! finite, in range), the inverse map for commands, and a force-torque reading checked.
//! Pure: the messages come from [`crate::ros_devices`] (or a test).

use tactile_ros::msg::{Decode, JointState, WrenchStamped};
use tactile_scenario::JointMapConfig;

pub use tactile_peripheral::Reject;

/// A CDR `JointState`, decoded, each joint named once (ROS 2 leaves a repeated name
/// undefined; a driver does not send one).
pub fn joint_state_cdr(cdr: &[u8]) -> Result<JointState, Reject> {
    let js = JointState::from_cdr(cdr)?;
    let mut names: Vec<&str> = js.name.iter().map(String::as_str).collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(Reject::DuplicateJoint(w[0].to_string()));
    }
    Ok(js)
}

/// The position of the joint `name` in a `JointState` (any order, other joints
/// ignored): present and finite.
pub fn position_of(js: &JointState, name: &str) -> Result<f64, Reject> {
    let v = *js
        .name
        .iter()
        .position(|n| n == name)
        .and_then(|k| js.position.get(k))
        .ok_or_else(|| Reject::Missing(name.to_string()))?;
    match v.is_finite() {
        true => Ok(v),
        false => Err(Reject::NotFinite(name.to_string())),
    }
}

/// Three named joints of a `JointState`, in the paper's convention.
#[derive(Debug, Clone)]
pub struct JointMap {
    names: [String; 3],
    cfg: JointMapConfig,
}

impl JointMap {
    /// The map for joints `names` under `cfg`.
    pub fn new(names: [String; 3], cfg: JointMapConfig) -> JointMap {
        JointMap { names, cfg }
    }

    /// The paper's angles from a CDR `JointState`.
    pub fn angles_cdr(&self, cdr: &[u8]) -> Result<[f64; 3], Reject> {
        self.angles(&joint_state_cdr(cdr)?)
    }

    /// The paper's angles from a `JointState`: theta = sign raw unit + offset.
    pub fn angles(&self, js: &JointState) -> Result<[f64; 3], Reject> {
        let mut theta = [0.0; 3];
        for (i, name) in self.names.iter().enumerate() {
            let coupled = i == 2 && self.cfg.elbow_after_shoulder;
            let raw = js
                .name
                .iter()
                .position(|n| n == name)
                .and_then(|k| js.position.get(k))
                .ok_or_else(|| Reject::Missing(name.clone()))?;
            let mut t = self.cfg.sign[i] * raw * self.cfg.unit.radians() + self.cfg.offset[i];
            if coupled {
                t += theta[1];
            }
            if !t.is_finite() {
                return Err(Reject::NotFinite(name.clone()));
            }
            let (min, max) = (self.cfg.min[i], self.cfg.max[i]);
            if !(min..=max).contains(&t) {
                return Err(Reject::OutOfRange {
                    joint: name.clone(),
                    value: t,
                    min,
                    max,
                });
            }
            theta[i] = t;
        }
        Ok(theta)
    }

    /// The driver's values for the paper's angles (the inverse map), for commands;
    /// each angle first clamped to the joint's `min..=max`, so a robot is never
    /// commanded where its readings would be refused.
    pub fn raw(&self, theta: [f64; 3]) -> [f64; 3] {
        let t = [0, 1, 2].map(|i| theta[i].clamp(self.cfg.min[i], self.cfg.max[i]));
        self.unclamped_raw(t)
    }

    /// The driver's values of the joints' range, `(at min, at max)` per joint (either
    /// may be the larger: the sign can flip them), for the gate.
    pub fn raw_range(&self) -> ([f64; 3], [f64; 3]) {
        (
            self.unclamped_raw(self.cfg.min),
            self.unclamped_raw(self.cfg.max),
        )
    }

    /// The driver's step for a step of `rad` of the paper's angle, per joint.
    pub fn raw_step(&self, rad: [f64; 3]) -> [f64; 3] {
        rad.map(|r| (r / self.cfg.unit.radians()).abs())
    }

    fn unclamped_raw(&self, theta: [f64; 3]) -> [f64; 3] {
        let mut t = theta;
        if self.cfg.elbow_after_shoulder {
            t[2] -= t[1];
        }
        [0, 1, 2]
            .map(|i| (t[i] - self.cfg.offset[i]) / (self.cfg.sign[i] * self.cfg.unit.radians()))
    }
}

/// A force from a CDR `WrenchStamped`, N; not finite, or longer than `max_force`,
/// is rejected.
pub fn force_cdr(cdr: &[u8], max_force: f64) -> Result<[f64; 3], Reject> {
    let w = WrenchStamped::from_cdr(cdr)?;
    plausible(w.force, max_force)
}

/// A force a sensor could have measured: finite and no longer than `max`, N. Past it
/// a robot's wrench of 1e6 N went on to the slave and MMT's estimate.
pub fn plausible(force: [f64; 3], max: f64) -> Result<[f64; 3], Reject> {
    if !force.iter().all(|f| f.is_finite()) {
        return Err(Reject::ForceNotFinite);
    }
    let length = tactile_math::vec3::norm(force);
    if length > max {
        return Err(Reject::ForceImplausible { force: length, max });
    }
    Ok(force)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use tactile_ros::msg::{Header, Message};
    use tactile_scenario::AngleUnit;

    pub(crate) fn js(names: &[&str], pos: &[f64]) -> JointState {
        JointState {
            header: Header::at(1, "base"),
            name: names.iter().map(|s| s.to_string()).collect(),
            position: pos.to_vec(),
            ..JointState::default()
        }
    }

    fn map() -> JointMap {
        let cfg = JointMapConfig {
            sign: [1.0, -1.0, 1.0],
            offset: [0.0, 0.0, 0.5],
            unit: AngleUnit::Deg,
            ..JointMapConfig::default()
        };
        JointMap::new(["a".into(), "b".into(), "c".into()], cfg)
    }

    #[test]
    fn joints_are_found_by_name_and_mapped_both_ways() {
        let m = map();
        let got = m.angles(&js(&["x", "c", "b", "a"], &[9.0, 90.0, 45.0, 180.0]));
        let pi = std::f64::consts::PI;
        let want = [pi, -pi / 4.0, pi / 2.0 + 0.5];
        let t = got.expect("mapped");
        for i in 0..3 {
            assert!((t[i] - want[i]).abs() < 1e-12, "{t:?}");
        }
        let raw = m.raw(t);
        for (r, w) in raw.iter().zip([180.0, 45.0, 90.0]) {
            assert!((r - w).abs() < 1e-9, "{raw:?}");
        }
    }

    #[test]
    fn missing_non_finite_and_out_of_range_values_are_rejected() {
        let m = map();
        assert_eq!(
            m.angles(&js(&["a", "b"], &[0.0, 0.0])),
            Err(Reject::Missing("c".into()))
        );
        assert_eq!(
            m.angles(&js(&["a", "b", "c"], &[0.0, 0.0])),
            Err(Reject::Missing("c".into())),
            "a name without a position"
        );
        assert_eq!(
            m.angles(&js(&["a", "b", "c"], &[0.0, f64::NAN, 0.0])),
            Err(Reject::NotFinite("b".into()))
        );
        assert!(matches!(
            m.angles(&js(&["a", "b", "c"], &[400.0, 0.0, 0.0])),
            Err(Reject::OutOfRange { .. })
        ));
        assert!(matches!(
            m.angles_cdr(&[1, 2, 3]),
            Err(Reject::Malformed(_))
        ));
        let w = WrenchStamped {
            force: [0.0, f64::INFINITY, 0.0],
            ..WrenchStamped::default()
        };
        assert_eq!(force_cdr(&w.to_cdr(), 1000.0), Err(Reject::ForceNotFinite));
        for (force, max) in [([1e300, 0.0, 0.0], 1000.0), ([0.0, 3.0, 4.0], 4.9)] {
            let w = WrenchStamped {
                force,
                ..WrenchStamped::default()
            };
            assert!(
                matches!(
                    force_cdr(&w.to_cdr(), max),
                    Err(Reject::ForceImplausible { .. })
                ),
                "{force:?}"
            );
        }
        let w = WrenchStamped {
            force: [0.0, 3.0, 4.0],
            ..WrenchStamped::default()
        };
        assert_eq!(force_cdr(&w.to_cdr(), 5.0), Ok([0.0, 3.0, 4.0]));
    }

    /// omni_common's elbow is measured from the shoulder: the paper's theta_3 is their
    /// sum, and back.
    #[test]
    fn an_elbow_given_after_the_shoulder_is_added_to_it() {
        let cfg = JointMapConfig {
            elbow_after_shoulder: true,
            ..JointMapConfig::default()
        };
        let m = JointMap::new(["a".into(), "b".into(), "c".into()], cfg);
        let t = m
            .angles(&js(&["a", "b", "c"], &[0.1, 0.4, -0.3]))
            .expect("mapped");
        assert_eq!(t, [0.1, 0.4, 0.4 + -0.3]);
        let raw = m.raw(t);
        for (r, w) in raw.iter().zip([0.1, 0.4, -0.3]) {
            assert!((r - w).abs() < 1e-15, "{raw:?}");
        }
    }

    #[test]
    fn commands_are_clamped_to_the_joints_range() {
        let m = map();
        assert!(
            (m.raw([10.0, 0.0, 0.0])[0] - 180.0).abs() < 1e-9,
            "clamped to pi"
        );
    }
}
