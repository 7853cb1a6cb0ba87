//! What loads but deserves a word before anything runs: a value the run will not
//! honour as written (stiffer than the device renders, a change or a delay past the
//! run's end, a channel that lets nothing through) or a setting that does nothing
//! (a table of one `kind` under another). Each is a `warning:` line of `tactile
//! check` and `tactile run`, and a line of the run's `warnings` in `summary.json`
//! (the report reads them from the scenario its records hold).

use crate::shown::Num;
use crate::{
    ArmServo, Backend, ChannelConfig, CodecConfig, CodecKind, ControlKind, HandMode, LossModel,
    MmtSlave, Operator, PredictorConfig, PredictorKind, Scenario, NOMINAL_MAX_STIFFNESS,
};
use serde::Serialize;
use tactile_math::arith::ArithKind;

impl Scenario {
    /// Things that load but deserve a word, one sentence each naming the field.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.ros_used() {
            w.extend(self.ros.in_clear_to_other_hosts().into_iter().map(|e| {
                format!(
                    "ros endpoint {e} leaves this host in clear: joint states, forces and robot commands can be read and forged on that network (give [ros.tls] a CA, certificate and key and use tls/ endpoints for mutual TLS, or keep the router on this host, or the network trusted)"
                )
            }));
        }
        for (k, o) in self.environment.objects.iter().enumerate() {
            for (i, h) in o.stiffness().iter().enumerate() {
                if *h > NOMINAL_MAX_STIFFNESS {
                    w.push(format!(
                        "environment.objects[{k}].stiffness[{i}] = {} N/m is above the device's nominal {NOMINAL_MAX_STIFFNESS} N/m: contact may buzz",
                        Num(*h)
                    ));
                }
            }
        }
        for (name, c) in [
            ("forward", &self.network.forward),
            ("backward", &self.network.backward),
        ] {
            self.channel(name, c, &mut w);
        }
        self.after_the_end(&mut w);
        self.unused(&mut w);
        w
    }

    /// True if a node talks ROS 2 (a device, a robot or the live view).
    fn ros_used(&self) -> bool {
        self.master.backend == Backend::Ros2
            || self.slave.backend == Backend::Ros2
            || self.ros.live.enabled
    }

    /// A channel's delays and schedule rows past the run, and settings under which
    /// no valid value gets through at all.
    fn channel(&self, name: &str, c: &ChannelConfig, w: &mut Vec<String>) {
        for (i, d) in c.delay.iter().enumerate() {
            if *d > 0 && *d as u64 >= self.samples {
                w.push(format!(
                    "network.{name}.delay[{i}] = {d} samples is not shorter than the run ({} samples): no value of that signal arrives",
                    self.samples
                ));
            }
        }
        for (k, e) in c.schedule.iter().enumerate() {
            if e[0] as u64 >= self.samples {
                w.push(format!(
                    "network.{name}.schedule[{k}] starts at sample {}, after the run's last ({}): it never takes effect",
                    e[0],
                    self.samples - 1
                ));
            }
        }
        if let Some(why) = passes_nothing(c) {
            let what = match name {
                "forward" => "no valid position reaches the slave",
                _ => "no valid force reaches the master",
            };
            w.push(format!("network.{name}.{why}: {what}"));
        }
    }

    /// A change or a motion that would come after the run's last sample.
    fn after_the_end(&self, w: &mut Vec<String>) {
        let last = self.samples - 1;
        for (k, n, c) in self.environment.changes_in_order(self.t_s()) {
            if n > last {
                w.push(format!(
                    "environment.changes[{k}].at_s = {} s holds from sample {n}, after the run's last ({last}): it never takes effect",
                    Num(c.at_s)
                ));
            }
        }
        let run_s = self.samples as f64 * self.t_s();
        if let Operator::Press { move_s, .. } = &self.operator {
            if *move_s > run_s {
                w.push(format!(
                    "operator.move_s = {} s is longer than the run ({} s): the hand never reaches operator.to",
                    Num(*move_s),
                    Num(run_s)
                ));
            }
        }
        let mmt = &self.control.mmt;
        if self.control.kind == ControlKind::Mmt && u64::from(mmt.min_contacts) > last {
            w.push(format!(
                "control.mmt.min_contacts = {} samples is not shorter than the run ({} samples): no model is ever sent",
                mmt.min_contacts, self.samples
            ));
        }
    }

    /// Settings of one kind, mode or backend set under another: each applies to its
    /// own only, so the run ignores them, which a user who set them should know.
    fn unused(&self, w: &mut Vec<String>) {
        let c = &self.control;
        let d = crate::ControlConfig::default();
        let this = format!("this run has control.kind = \"{}\"", c.kind.name());
        if c.kind != ControlKind::Mmt {
            let set = changed(&c.mmt, &d.mmt, "control.mmt", &[]);
            say(w, &set, "control.kind = \"mmt\"", &this);
        }
        if c.kind != ControlKind::Wave {
            let set = changed(c, &d, "control", &["wave_impedance"]);
            say(w, &set, "control.kind = \"wave\"", &this);
        }
        let tdpa = c.kind == ControlKind::Tdpa
            || (c.kind == ControlKind::Mmt && c.mmt.slave == MmtSlave::Tdpa);
        if !tdpa {
            let keys = ["velocity_floor", "max_damping", "drift_rate"];
            let set = changed(c, &d, "control", &keys);
            let only = "control.kind = \"tdpa\" (or \"mmt\" with control.mmt.slave = \"tdpa\")";
            say(w, &set, only, &this);
        }
        for (field, codec) in [
            ("codec.forward", &self.codec.forward),
            ("codec.backward", &self.codec.backward),
        ] {
            let d = CodecConfig::default();
            let this = format!("{field}.kind is \"{}\"", kind_name(&codec.kind));
            if codec.kind == CodecKind::None {
                let set = changed(codec, &d, field, &["k", "floor"]);
                say(
                    w,
                    &set,
                    "a codec of kind \"deadband\" or \"adaptive\"",
                    &this,
                );
            }
            if codec.kind != CodecKind::Adaptive {
                let set = changed(codec, &d, field, &["v_ref"]);
                say(w, &set, "a codec of kind \"adaptive\"", &this);
            }
        }
        for (field, p) in [
            ("master.predictor", &self.master.predictor),
            ("slave.predictor", &self.slave.predictor),
        ] {
            let d = PredictorConfig::default();
            let this = format!("{field}.kind is \"{}\"", kind_name(&p.kind));
            if p.kind != PredictorKind::Kalman {
                let set = changed(p, &d, field, &["process_noise", "measurement_noise"]);
                say(w, &set, "a predictor of kind \"kalman\"", &this);
            }
            if p.kind == PredictorKind::Hold {
                let set = changed(p, &d, field, &["horizon_s"]);
                say(
                    w,
                    &set,
                    "a predictor of kind \"linear\" or \"kalman\"",
                    &this,
                );
            }
        }
        self.unused_elsewhere(w);
    }

    /// The hand's, the devices', the CORDIC's, ROS 2's and the replays' settings.
    fn unused_elsewhere(&self, w: &mut Vec<String>) {
        let d = Scenario::default();
        if self.master.hand.mode != HandMode::Impedance {
            let keys = ["mass", "damping", "stiffness"];
            let set = changed(&self.master.hand, &d.master.hand, "master.hand", &keys);
            let this = "this run's hand has master.hand.mode = \"position\"";
            say(w, &set, "master.hand.mode = \"impedance\"", this);
        }
        if self.master.backend == Backend::Ros2 {
            let set = changed(&self.master.human, &d.master.human, "master.human", &[]);
            let this = "this run's master is a real device (master.backend = \"ros2\")";
            say(w, &set, "the simulated operator", this);
        }
        let sides = [
            (
                "master",
                self.master.backend,
                changed(&self.master.ros2, &d.master.ros2, "master.ros2", &[]),
            ),
            (
                "slave",
                self.slave.backend,
                changed(&self.slave.ros2, &d.slave.ros2, "slave.ros2", &[]),
            ),
        ];
        for (side, backend, set) in sides {
            if backend != Backend::Ros2 {
                let only = format!("{side}.backend = \"ros2\"");
                say(w, &set, &only, &format!("this run's {side} is simulated"));
            }
        }
        if let Some(arm) = self
            .slave
            .arm
            .as_ref()
            .filter(|a| a.servo != ArmServo::Cartesian)
        {
            let d = crate::CartesianConfig::default();
            let set = changed(&arm.cartesian, &d, "slave.arm.cartesian", &[]);
            let this = "this run's arm has slave.arm.servo = \"joint\"";
            say(w, &set, "slave.arm.servo = \"cartesian\"", this);
        }
        if matches!(self.arithmetic, ArithKind::F64 | ArithKind::F32) {
            let set = changed(&self.cordic, &d.cordic, "cordic", &[]);
            let this = format!("this run has arithmetic = \"{}\"", self.arithmetic.name());
            say(w, &set, "arithmetic = \"hybrid\" or \"rtl\"", &this);
        }
        if !self.ros_used() {
            let set = changed(&self.ros, &d.ros, "ros", &[]);
            let only = "a node that talks ROS 2 (a backend \"ros2\" or ros.live.enabled)";
            say(w, &set, only, "none in this run does");
        } else if !self.ros.live.enabled {
            let set = changed(&self.ros.live, &d.ros.live, "ros.live", &["rate_hz"]);
            say(w, &set, "the live view", "ros.live.enabled is false");
        }
    }
}

/// A kind's name as a scenario writes it (its serde form).
fn kind_name<T: Serialize>(kind: &T) -> String {
    toml::Value::try_from(kind)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// Why a channel lets no valid value through (`None`: some get through): every
/// sample dropped or corrupted, or a loss model that in the long run loses them all.
fn passes_nothing(c: &ChannelConfig) -> Option<String> {
    if c.loss >= 1.0 {
        return Some("loss = 1 drops every sample".into());
    }
    if c.corrupt >= 1.0 {
        return Some("corrupt = 1 makes every sample NaN, which the receiver refuses".into());
    }
    match c.loss_model.as_ref()? {
        LossModel::Gemodel {
            p,
            r,
            bad_loss,
            good_loss,
        } => {
            // The share of samples lost once the two states have mixed (the chain
            // starts good, and stays there when it never moves).
            let lost = if p + r > 0.0 {
                (r * good_loss + p * bad_loss) / (p + r)
            } else {
                *good_loss
            };
            (lost >= 1.0).then(|| "loss_model (gemodel) loses every sample in the long run".into())
        }
        LossModel::State { p13, p31, p32, .. } => (*p13 > 0.0 && *p31 == 0.0 && *p32 == 0.0)
            .then(|| "loss_model (state): its burst-loss state 3 is never left (p31 = p32 = 0), so after the first burst every sample is lost".into()),
    }
}

/// The fields of `v` among `keys` (every field, for none) whose value differs from
/// `d`'s, as `prefix.key`: a setting at its default changes nothing, wherever it is.
fn changed<T: Serialize>(v: &T, d: &T, prefix: &str, keys: &[&str]) -> Vec<String> {
    let (Ok(toml::Value::Table(a)), Ok(toml::Value::Table(b))) =
        (toml::Value::try_from(v), toml::Value::try_from(d))
    else {
        return Vec::new();
    };
    let mut names: Vec<&String> = a.keys().chain(b.keys()).collect();
    names.sort();
    names.dedup();
    names
        .into_iter()
        .filter(|k| keys.is_empty() || keys.contains(&k.as_str()))
        .filter(|k| a.get(*k) != b.get(*k))
        .map(|k| format!("{prefix}.{k}"))
        .collect()
}

/// One warning for the settings `set` (none: nothing to say): `only` uses them,
/// and `this` run is not that.
fn say(w: &mut Vec<String>, set: &[String], only: &str, this: &str) {
    match set {
        [] => {}
        [one] => w.push(format!(
            "{one} is set, but only {only} uses it, and {this}: it is ignored"
        )),
        many => w.push(format!(
            "{} are set, but only {only} uses them, and {this}: they are ignored",
            crate::shown::listed(many)
        )),
    }
}

#[cfg(test)]
#[path = "warnings_tests.rs"]
mod tests;
