//! The range check of a whole scenario, table by table; the error names the field.
//! Each table checks itself in its own module; this is the order they are checked in.

use crate::*;

/// The sampling rate, 100 Hz to 10 kHz (also checked before `_ms` keys are
/// converted at it).
pub(crate) fn check_rate(rate_hz: f64) -> Result<(), ScenarioError> {
    if !rate_hz.is_finite() || !(100.0..=10_000.0).contains(&rate_hz) {
        return Err(invalid(
            "rate_hz",
            format!(
                "{} Hz is outside 100..=10000 Hz",
                crate::shown::Num(rate_hz)
            ),
        ));
    }
    Ok(())
}

/// The longest `name`, in characters: a name labels reports, plots and sweep rows,
/// and goes into every node's record twice (a million characters made the record's
/// first entry longer than a frame may be).
pub const MAX_NAME_CHARS: usize = 256;

impl Scenario {
    /// Checks every value is in range; the error names the field.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let chars = self.name.chars().count();
        if chars > MAX_NAME_CHARS {
            return Err(invalid(
                "name",
                format!(
                    "is {chars} characters long, more than the {MAX_NAME_CHARS} a name may have"
                ),
            ));
        }
        check_rate(self.rate_hz)?;
        if self.samples == 0 || self.samples > 100_000_000 {
            return Err(invalid(
                "samples",
                format!("{} is outside 1..=100000000", self.samples),
            ));
        }
        self.cordic.config()?;
        self.device.geometry()?;
        self.operator.validate()?;
        self.master.validate()?;
        self.master.human.validate(self.rate_hz)?;
        self.control.validate()?;
        self.codec.forward.validate("codec.forward")?;
        self.codec.backward.validate("codec.backward")?;
        self.slave.validate()?;
        self.network.forward.validate("network.forward")?;
        self.network.backward.validate("network.backward")?;
        if self.faults.peer_timeout_samples == 0 {
            return Err(invalid("faults.peer_timeout_samples", "must be at least 1"));
        }
        self.environment.validate_with(self.task.as_ref())?;
        self.ros.validate(self.rate_hz)?;
        self.master
            .ros2
            .watch
            .validate_at("master.ros2.watch", self.rate_hz)?;
        self.slave
            .ros2
            .watch
            .validate_at("slave.ros2.watch", self.rate_hz)?;
        if self.mode == Mode::Lockstep
            && (self.master.backend == Backend::Ros2 || self.slave.backend == Backend::Ros2)
        {
            return Err(invalid(
                "mode",
                "a device over ROS 2 runs in real time: lockstep has no clock a device follows",
            ));
        }
        if self.master.backend == Backend::Ros2 && self.master.ros2.six_dof() {
            self.check_six_dof("the ROS 2 device has an orientation or a clutch (a 6-DoF run)")?;
        }
        self.bounded()
    }

    /// What a 6-DoF run (`why` says what makes it one) needs of the rest: an arm that
    /// can turn its tool, equal delays per direction (a pose, or a wrench back, crosses
    /// in one packet), no forward deadband (it weighs positions only).
    pub fn check_six_dof(&self, why: &str) -> Result<(), ScenarioError> {
        let bad = |field: &str, problem: &str| Err(invalid(field, format!("{why}: {problem}")));
        let equal = |d: [i64; 3]| d[0] == d[1] && d[1] == d[2];
        if self.slave.arm.is_none() {
            return bad("slave.arm", "the paper's arm has three joints and cannot turn its tool; a 6-DoF run needs [slave.arm]");
        }
        for (dir, c) in [
            ("forward", &self.network.forward),
            ("backward", &self.network.backward),
        ] {
            if !equal(c.delay) || c.schedule.iter().any(|e| !equal([e[1], e[2], e[3]])) {
                return bad(&format!("network.{dir}.delay"), "a pose (a wrench back) crosses in one packet, so the three delays (and every schedule row's) must be equal");
            }
        }
        if self.codec.forward.kind != CodecKind::None {
            return bad("codec.forward.kind", "the deadband codecs weigh positions only and would leave turns unsent; use \"none\"");
        }
        Ok(())
    }
}
