//! What a report must say before its figures are read: where a figure comes from a
//! part of the run only (a node's rows left out of the join, damaged, numbered past
//! the run, repeated), and where the trace and a node's own counters disagree. Each is
//! a line of `warnings` in `summary.json` and a `warning:` line on the terminal.

use crate::analysis::Analysis;
use crate::join::{Logs, NodeLog};
use tactile_messages::Role;
use tactile_records::device::DeviceCounters;
use tactile_records::slave::SlaveCounters;

/// The warnings of a report from its analysis, the nodes' logs and the slave's summed
/// counters; `sent` is the master's own count of samples sent. A row's number is
/// checked against the sample count the join applied ([`Logs::limit`]).
pub fn warnings(
    a: &Analysis,
    logs: &Logs,
    sent: u64,
    slave_counters: Option<&SlaveCounters>,
) -> Vec<String> {
    let mut out = Vec::new();
    let samples = logs.limit;
    for (role, claimed) in &logs.disagree {
        out.push(format!(
            "{role}: its start claims {claimed} samples where the run's count applied is {samples}: rows numbered from {samples} on were counted invalid"
        ));
    }
    left_out(Role::Master, &logs.master, samples, &mut out);
    left_out(Role::Emulator, &logs.emulator, samples, &mut out);
    left_out(Role::Slave, &logs.slave, samples, &mut out);
    let slave = &logs.slave;
    let slave_short = !slave.path.as_os_str().is_empty()
        && (slave.left_out() > 0 || slave.damaged.1 > 0)
        && a.tracked() < a.rows;
    if slave_short {
        out.push(format!(
            "tracking over {} of {} samples: {} of the slave's rows unjoined, {} invalid, {} duplicates, {} damaged stretches; the slave's columns are empty for the rest",
            a.tracked(),
            a.rows,
            slave.unjoined,
            slave.invalid,
            slave.duplicates,
            slave.damaged.1
        ));
    }
    // A master that stopped wrote its last counters as it ended: they count every
    // sample it sent (a killed one's are up to a second old, and are not compared).
    let ended = !logs.master.stops.is_empty() && logs.master.stops.iter().all(Option::is_some);
    if ended && logs.stopped_at.is_none() && sent != a.rows {
        out.push(format!(
            "the trace holds {} samples where the master's own counters say {sent} sent: its record lost or misplaced the rest",
            a.rows
        ));
    }
    out.extend(slave_counters.and_then(dynamics_failed));
    for (role, refused) in [Role::Master, Role::Slave].iter().zip(a.guesses_refused) {
        if refused > 0 {
            out.push(format!(
                "{role}: {refused} guesses of its predictor from outside the scenario (the Python API) were not physically possible (not finite, too large or too fast for a received value) and were refused: the last value was held instead (GUESS_REFUSED in the trace's flags)"
            ));
        }
    }
    out
}

/// A URDF arm whose dynamics failed in some periods stood still in each: the slave's
/// columns there are not the arm following, which its tracking and forces do not say.
/// The first failure's cause is in the slave's log.
pub fn dynamics_failed(c: &SlaveCounters) -> Option<String> {
    (c.dynamics_failed > 0).then(|| {
        format!(
            "slave.arm: the dynamics failed in {} periods and the arm stood still in each (the slave's log says why): tracking and forces include them",
            c.dynamics_failed
        )
    })
}

/// A physics world that went wrong (docs/16): what it counted, said once; the
/// record's events name each body and sample.
pub fn world_faults(w: &tactile_records::slave::WorldCounters) -> Option<String> {
    let parts: Vec<String> = [
        (w.left_bounds, "bodies left its bounds"),
        (w.energy_gains, "episodes of energy without a source"),
        (w.non_finite, "bodies became non-finite"),
        (w.bad_inputs, "samples of a non-finite tool frame"),
        (w.engine_failures, "engine failures (the world froze)"),
    ]
    .into_iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect();
    (!parts.is_empty()).then(|| {
        format!(
            "the physics world went wrong: {}; the force to the operator was ramped down over {} samples (the events say where)",
            parts.join(", "),
            w.ramped_steps
        )
    })
}

/// A real device or robot whose messages were refused (malformed, not finite, out of
/// range, a force past `max_force`): the loop went on from its last good value, which
/// the figures do not say. The first refusal's reason is in that node's log.
pub fn devices_rejected(master: &DeviceCounters, slave: Option<&DeviceCounters>) -> Vec<String> {
    [("master", "its device", Some(master)), ("slave", "its robot", slave)]
        .into_iter()
        .filter_map(|(role, what, d)| {
            let d = d.filter(|d| d.rejected > 0)?;
            Some(format!(
                "{role}: {} of {} messages from {what} were refused (malformed, not finite, out of range, or a force past max_force: the log names the first) and the loop went on from the last good one",
                d.rejected, d.messages
            ))
        })
        .collect()
}

/// A node's sample rows the join left out, if any, and why.
fn left_out<C: Clone>(role: Role, log: &NodeLog<C>, samples: u64, out: &mut Vec<String>) {
    if log.left_out() == 0 {
        return;
    }
    out.push(format!(
        "{role}: {} sample rows of {} left out of the join: {} joined no sample of the master (outside its window or out of order), {} numbered past the run's {samples} samples, {} repeated a sample already recorded",
        log.left_out(),
        log.path.display(),
        log.unjoined,
        log.invalid,
        log.duplicates
    ));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 65: a robot's wrench of 1e300 N was refused by nobody, and one refused
    /// was not said in the summary.
    #[test]
    fn refused_device_messages_are_warned_of_with_the_count() {
        let none = DeviceCounters::default();
        assert!(devices_rejected(&none, Some(&none)).is_empty());
        let robot = DeviceCounters {
            messages: 40,
            rejected: 3,
            ..DeviceCounters::default()
        };
        let w = devices_rejected(&none, Some(&robot));
        assert_eq!(w.len(), 1);
        assert!(
            w[0].starts_with("slave: 3 of 40 messages from its robot were refused"),
            "{w:?}"
        );
    }

    /// Issue 51: an arm whose dynamics failed was counted by the slave, and the report
    /// said nothing of it.
    #[test]
    fn an_arm_whose_dynamics_failed_is_warned_of_with_the_count() {
        assert_eq!(dynamics_failed(&SlaveCounters::default()), None);
        let c = SlaveCounters {
            dynamics_failed: 7,
            ..SlaveCounters::default()
        };
        let w = dynamics_failed(&c).expect("a warning");
        assert!(w.contains("failed in 7 periods"), "{w}");
    }

    #[test]
    fn a_world_that_went_wrong_is_warned_of_with_its_counts() {
        use tactile_records::slave::WorldCounters;
        assert_eq!(world_faults(&WorldCounters::default()), None);
        let w = WorldCounters {
            physics: true,
            left_bounds: 2,
            energy_gains: 1,
            ramped_steps: 150,
            ..WorldCounters::default()
        };
        assert_eq!(
            world_faults(&w).as_deref(),
            Some("the physics world went wrong: 2 bodies left its bounds, 1 episodes of energy without a source; the force to the operator was ramped down over 150 samples (the events say where)")
        );
    }
}
