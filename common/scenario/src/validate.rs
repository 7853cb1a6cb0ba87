//! The range check of a whole scenario, table by table; the error names the field.

use crate::*;

impl Scenario {
    /// Checks every value is in range; the error names the field.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if !self.rate_hz.is_finite() || !(100.0..=10_000.0).contains(&self.rate_hz) {
            return Err(invalid(
                "rate_hz",
                format!("{} Hz is outside 100..=10000 Hz", self.rate_hz),
            ));
        }
        if self.samples == 0 || self.samples > 100_000_000 {
            return Err(invalid(
                "samples",
                format!("{} is outside 1..=100000000", self.samples),
            ));
        }
        self.cordic.config()?;
        self.device.geometry()?;
        match &self.operator {
            Operator::Paper => {}
            Operator::Circle {
                center,
                radius,
                period_s,
                plane,
            }
            | Operator::FigureEight {
                center,
                size: radius,
                period_s,
                plane,
            } => {
                finite3(center, "operator.center")?;
                if !radius.is_finite() || *radius <= 0.0 || *radius > 1.0 {
                    return Err(invalid(
                        "operator.radius",
                        format!("{radius} m is outside (0, 1] m"),
                    ));
                }
                if !period_s.is_finite() || *period_s <= 0.0 {
                    return Err(invalid(
                        "operator.period_s",
                        format!("{period_s} must be positive"),
                    ));
                }
                if !["xy", "yz", "xz"].contains(&plane.as_str()) {
                    return Err(invalid(
                        "operator.plane",
                        format!("{plane:?} is not xy, yz or xz"),
                    ));
                }
            }
            Operator::Press { from, to, move_s } => {
                finite3(from, "operator.from")?;
                finite3(to, "operator.to")?;
                if !move_s.is_finite() || *move_s <= 0.0 {
                    return Err(invalid(
                        "operator.move_s",
                        format!("{move_s} must be positive"),
                    ));
                }
            }
            Operator::Csv { path } => {
                if path.is_empty() {
                    return Err(invalid("operator.path", "is empty"));
                }
            }
        }
        self.master.hand.validate()?;
        self.master.device.validate()?;
        self.control.validate()?;
        self.codec.forward.validate("codec.forward")?;
        self.codec.backward.validate("codec.backward")?;
        self.master.predictor.validate("master.predictor")?;
        self.slave.predictor.validate("slave.predictor")?;
        self.network.forward.validate("network.forward")?;
        self.network.backward.validate("network.backward")?;
        let c = &self.slave.controller;
        positive3(&c.kp, "slave.controller.kp", true)?;
        positive3(&c.ki, "slave.controller.ki", true)?;
        positive3(&c.kd, "slave.controller.kd", true)?;
        positive3(&c.torque_limit, "slave.controller.torque_limit", false)?;
        let d = &self.slave.dynamics;
        positive3(&d.inertia, "slave.dynamics.inertia", false)?;
        positive3(&d.damping, "slave.dynamics.damping", true)?;
        // A sample shorter than the step is integrated in one step of t_s; a step
        // longer than 10 ms makes the default joints' integration unstable.
        if !d.step_s.is_finite() || d.step_s < 1e-6 || d.step_s > 0.01 {
            return Err(invalid(
                "slave.dynamics.step_s",
                format!("{} s is outside 1 us to 10 ms", d.step_s),
            ));
        }
        if !self.master.force_limit.is_finite() || self.master.force_limit <= 0.0 {
            return Err(invalid(
                "master.force_limit",
                format!("{} N must be positive", self.master.force_limit),
            ));
        }
        positive3(&self.master.torque_limit, "master.torque_limit", false)?;
        if self.faults.peer_timeout_samples == 0 {
            return Err(invalid("faults.peer_timeout_samples", "must be at least 1"));
        }
        for (k, o) in self.environment.objects.iter().enumerate() {
            let f = format!("environment.objects[{k}]");
            positive3(&o.stiffness(), &format!("{f}.stiffness"), true)?;
            for (i, h) in o.stiffness().iter().enumerate() {
                if *h > MAX_STIFFNESS {
                    return Err(invalid(
                        format!("{f}.stiffness[{i}]"),
                        format!("{h} N/m is above {MAX_STIFFNESS} N/m, ten times the device's nominal maximum"),
                    ));
                }
            }
            match o {
                Object::Plane { point, normal, .. } => {
                    finite3(point, &format!("{f}.point"))?;
                    finite3(normal, &format!("{f}.normal"))?;
                    if normal.iter().map(|v| v * v).sum::<f64>() < 1e-12 {
                        return Err(invalid(
                            format!("{f}.normal"),
                            "must not be the zero vector",
                        ));
                    }
                }
                Object::Sphere { center, radius, .. } => {
                    finite3(center, &format!("{f}.center"))?;
                    if !radius.is_finite() || *radius <= 0.0 {
                        return Err(invalid(
                            format!("{f}.radius"),
                            format!("{radius} must be positive"),
                        ));
                    }
                }
                Object::Box {
                    center,
                    half_extents,
                    ..
                } => {
                    finite3(center, &format!("{f}.center"))?;
                    positive3(half_extents, &format!("{f}.half_extents"), false)?;
                }
            }
        }
        Ok(())
    }
}
