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
            let (what, at) = o.position();
            each_at_most(&format!("{f}.{what}"), &at, MAX_POSITION_M)?;
            match o {
                Object::Plane { .. } => {}
                Object::Sphere { radius, .. } => {
                    at_most(&format!("{f}.radius"), *radius, MAX_POSITION_M)?;
                }
                Object::Box { half_extents, .. } => {
                    each_at_most(&format!("{f}.half_extents"), half_extents, MAX_POSITION_M)?;
                }
            }
        }
        self.changes_bounded()
    }

    /// Every object's position after every change, in the order the slave applies
    /// them, within the bound a static object's position meets: each change's
    /// `move_by` is bounded on its own, but they add up (fifty moves of 0.9 m put a
    /// wall 44.9 m up, 45 m into the arm's space, and the slave pressed 26.9 kN).
    fn changes_bounded(&self) -> Result<(), ScenarioError> {
        let mut objects = self.environment.objects.clone();
        for (k, n, c) in self.environment.changes_in_order(self.t_s()) {
            let Some(o) = objects.get_mut(c.object) else {
                continue; // refused by `Environment::validate` before
            };
            *o = o.changed(c);
            let (what, at) = o.position();
            if let Some(i) = at.iter().position(|x| x.abs() > MAX_POSITION_M) {
                let shown: Vec<String> = at
                    .iter()
                    .map(|x| Num((x * 1e6).round() / 1e6).to_string())
                    .collect();
                return Err(invalid(
                    format!("environment.changes[{k}].move_by"),
                    format!(
                        "puts environment.objects[{}].{what} at [{}] m from sample {n} on, beyond {MAX_POSITION_M} m on axis {i} (the changes add up: an object's position after each is bounded as a static one's)",
                        c.object,
                        shown.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// 1e308 was shown as its 309 digits.
    /// Fifty changes of 0.9 m each passed (each within its 1 m), put the wall 44.9 m
    /// up and the slave saw 26.9 kN; the sum is bounded, naming the change that
    /// crosses, and changes that come back stay allowed.
    #[test]
    fn changes_that_add_up_beyond_the_bound_are_refused() {
        let wall = "[[environment.objects]]\nkind = \"plane\"\npoint = [0.0, 0.0, -0.16]\nnormal = [0.0, 0.0, 1.0]\nstiffness = [300.0, 300.0, 300.0]\n";
        let change = |at: f64, z: f64| {
            format!(
                "[[environment.changes]]\nat_s = {at:?}\nobject = 0\nmove_by = [0.0, 0.0, {z:?}]\n"
            )
        };
        let up: String = (0..50).map(|k| change(f64::from(k) * 0.1, 0.9)).collect();
        let e = crate::Scenario::from_toml_str(&format!("{wall}{up}"))
            .expect_err("44.9 m up")
            .to_string();
        assert!(
            e.contains("field `environment.changes[11].move_by`")
                && e.contains("environment.objects[0].point")
                && e.contains("axis 2"),
            "{e}"
        );
        // Listed out of order: applied by time, so up and down again stays within.
        let back: String = (0..20)
            .map(|k| change(f64::from(k) * 0.1, if k % 2 == 0 { 0.9 } else { -0.9 }))
            .rev()
            .collect();
        crate::Scenario::from_toml_str(&format!("{wall}{back}")).expect("up and down");
        // In file order the same changes would climb: the slave's order is what counts.
        let climbs: String = (0..20)
            .map(|k| {
                change(
                    if k < 12 { f64::from(k) * 0.1 } else { 5.0 },
                    if k < 12 { 0.9 } else { -0.9 },
                )
            })
            .collect();
        crate::Scenario::from_toml_str(&format!("{wall}{climbs}")).expect_err("12 up first");
    }

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
