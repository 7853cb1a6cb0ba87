//! Upper bounds of the fields whose own checks only ask for a sign: past these a value
//! is a typo or a unit mistake (millimetres for metres, grams for kilograms), not an
//! experiment on a PHANToM Omni class arm. Each bound is written once, here, with the
//! field it bounds; the error names the field.

use crate::shown::Num;
use crate::{invalid, Object, Operator, Scenario, ScenarioError};

/// Largest magnitude of a position in the arm's space, m.
pub const MAX_POSITION_M: f64 = 10.0;

fn at_most(field: &str, v: f64, max: f64) -> Result<(), ScenarioError> {
    if v.abs() > max {
        return Err(invalid(field, format!("{} is beyond {max}", Num(v))));
    }
    Ok(())
}

fn each_at_most(field: &str, v: &[f64; 3], max: f64) -> Result<(), ScenarioError> {
    for (i, x) in v.iter().enumerate() {
        at_most(&format!("{field}[{i}]"), *x, max)?;
    }
    Ok(())
}

impl Scenario {
    /// Checks every field against its upper bound.
    pub(crate) fn bounded(&self) -> Result<(), ScenarioError> {
        let (m, s, c) = (&self.master, &self.slave, &self.control);
        let scalars = [
            ("master.force_limit", m.force_limit, 100.0),
            ("master.hand.mass", m.hand.mass, 10.0),
            ("master.hand.damping", m.hand.damping, 1000.0),
            ("master.hand.stiffness", m.hand.stiffness, 10_000.0),
            ("master.hand.approach_s", m.hand.approach_s, 60.0),
            ("control.wave_impedance", c.wave_impedance, 10_000.0),
            ("control.velocity_floor", c.velocity_floor, 1.0),
            ("control.max_damping", c.max_damping, 100_000.0),
            ("control.drift_rate", c.drift_rate, 10.0),
            ("control.mmt.contact_force", c.mmt.contact_force, 100.0),
            ("control.mmt.min_contacts", c.mmt.min_contacts.into(), 1e6),
            ("control.mmt.stiffness_change", c.mmt.stiffness_change, 10.0),
            ("control.mmt.offset_change", c.mmt.offset_change, 1.0),
            (
                "control.mmt.angle_change",
                c.mmt.angle_change,
                std::f64::consts::PI,
            ),
            ("control.mmt.force_rate", c.mmt.force_rate, 1e5),
            ("codec.forward.floor", self.codec.forward.floor, 1.0),
            ("codec.backward.floor", self.codec.backward.floor, 100.0),
            ("codec.forward.v_ref", self.codec.forward.v_ref, 100.0),
            ("codec.backward.v_ref", self.codec.backward.v_ref, 100.0),
            ("master.predictor.max_rate", m.predictor.max_rate, 1e9),
            ("slave.predictor.max_rate", s.predictor.max_rate, 1e9),
            (
                "faults.peer_timeout_samples",
                self.faults.peer_timeout_samples as f64,
                1e6,
            ),
        ];
        for (field, v, max) in scalars {
            at_most(field, v, max)?;
        }
        let triples = [
            ("master.torque_limit", &m.torque_limit, 100.0),
            ("master.device.inertia", &m.device.inertia, 1.0),
            ("master.device.damping", &m.device.damping, 100.0),
            ("master.device.friction", &m.device.friction, 100.0),
            ("slave.controller.kp", &s.controller.kp, 10_000.0),
            ("slave.controller.ki", &s.controller.ki, 10_000.0),
            ("slave.controller.kd", &s.controller.kd, 1000.0),
            (
                "slave.controller.torque_limit",
                &s.controller.torque_limit,
                100.0,
            ),
            ("slave.dynamics.inertia", &s.dynamics.inertia, 1.0),
            ("slave.dynamics.damping", &s.dynamics.damping, 100.0),
            (
                "network.forward.noise_std",
                &self.network.forward.noise_std,
                1.0,
            ),
            (
                "network.backward.noise_std",
                &self.network.backward.noise_std,
                100.0,
            ),
        ];
        for (field, v, max) in triples {
            each_at_most(field, v, max)?;
        }
        self.operator_bounded()?;
        self.objects_bounded()
    }

    fn operator_bounded(&self) -> Result<(), ScenarioError> {
        match &self.operator {
            Operator::Circle {
                center, period_s, ..
            }
            | Operator::FigureEight {
                center, period_s, ..
            } => {
                each_at_most("operator.center", center, MAX_POSITION_M)?;
                at_most("operator.period_s", *period_s, 3600.0)
            }
            Operator::Press { from, to, move_s } => {
                each_at_most("operator.from", from, MAX_POSITION_M)?;
                each_at_most("operator.to", to, MAX_POSITION_M)?;
                at_most("operator.move_s", *move_s, 3600.0)
            }
            Operator::Paper | Operator::Csv { .. } => Ok(()),
        }
    }

    fn objects_bounded(&self) -> Result<(), ScenarioError> {
        for (k, o) in self.environment.objects.iter().enumerate() {
            let f = format!("environment.objects[{k}]");
            match o {
                Object::Plane { point, .. } => {
                    each_at_most(&format!("{f}.point"), point, MAX_POSITION_M)?
                }
                Object::Sphere { center, radius, .. } => {
                    each_at_most(&format!("{f}.center"), center, MAX_POSITION_M)?;
                    at_most(&format!("{f}.radius"), *radius, MAX_POSITION_M)?;
                }
                Object::Box {
                    center,
                    half_extents,
                    ..
                } => {
                    each_at_most(&format!("{f}.center"), center, MAX_POSITION_M)?;
                    each_at_most(&format!("{f}.half_extents"), half_extents, MAX_POSITION_M)?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// 1e308 was shown as its 309 digits.
    #[test]
    fn a_huge_value_is_shown_short() {
        let text = super::at_most("master.force_limit", 1e308, 100.0)
            .expect_err("beyond")
            .to_string();
        assert!(
            text.contains("1e308 is beyond 100") && text.len() < 120,
            "{text}"
        );
    }
}
