//! The bilateral loop's metrics, a view of the trace rows gathered one row at a time:
//! how well the slave follows the master and the operator feels the environment, how
//! deep the tool goes, what the channel's passivity observers saw and what the control
//! dissipated. Memory is bounded: the rows a delayed value refers back to are kept in
//! a ring of [`LATE_WINDOW`] samples (a value delayed longer is not compared).

use crate::trace::TraceRow;
use serde::Serialize;
use tactile_math::vec3::{distance, norm};
use tactile_messages::samples::{Flags, LATE_WINDOW};

/// `tracking` in summary.json.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Tracking {
    /// RMS distance of the slave's tool from the master's handle where it was when the
    /// slave's input left it (delay-shifted), m; null without a comparable step.
    pub position_rms_m: Option<f64>,
    /// RMS difference of the force felt from the environment's force at the slave step
    /// it came from, N; null without an answer.
    pub force_rms_n: Option<f64>,
    /// Steps compared for `position_rms_m`.
    pub position_samples: u64,
    /// Answers compared for `force_rms_n`.
    pub force_samples: u64,
}

/// `contact` in summary.json.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Contact {
    /// Deepest the tool went into an object, m.
    pub max_penetration_m: f64,
    /// Peak-to-peak of the contact force's magnitude over the run's last
    /// [`SWING_WINDOW`] slave steps, N: near zero when the contact has settled, large
    /// when it keeps oscillating (the tool bouncing on and off a wall swings between
    /// zero and its peak force).
    pub force_swing_n: f64,
    /// The largest change of the felt force from one master sample to the next, N: a
    /// kick the operator's hand takes (a wall that moved, a model changed, a delayed
    /// force arriving).
    pub felt_step_max_n: f64,
}

/// Steps over which [`Contact::force_swing_n`] is taken: one second at 1 kHz.
pub const SWING_WINDOW: usize = 1000;

/// `passivity` in summary.json.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Passivity {
    /// Lowest value of the channel's energy over the run, J: what both ports put in
    /// minus what they took out, each side's books up to the same sample (the
    /// two-port's passivity observer, exact here because the report holds both
    /// sides). Below zero, the channel produced energy. Null without a sample.
    pub observer_min_j: Option<f64>,
    /// Lowest value either side's own observer took on any axis, J: what that side
    /// knew online (the other side's input energy as last received, minus its own
    /// output), what TDPA's controllers act on. Null without a sample.
    pub side_observer_min_j: Option<f64>,
    /// Energy the control dissipated, both sides, J.
    pub dissipated_j: f64,
    /// Largest distance of the slave's reference from the master's delay-shifted
    /// handle (the control's position drift), m.
    pub drift_max_m: f64,
    /// That distance at the last step, m.
    pub drift_final_m: f64,
}

/// `packets` in summary.json: packets put on the network per direction (samples the
/// codec sent; without a codec, every sample).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Packets {
    /// Master to slave.
    pub forward: u64,
    /// Slave to master.
    pub backward: u64,
}

/// The running sums.
#[derive(Debug, Clone)]
pub struct Bilateral {
    /// Position and force tracking.
    pub tracking: Tracking,
    /// Penetration.
    pub contact: Contact,
    /// Observers and dissipation.
    pub passivity: Passivity,
    /// The stiffness felt against the environment's.
    pub felt: crate::transparency::Felt,
    /// MMT: the energy the master's model changes had added by the last row, J.
    pub model_injected_j: f64,
    /// A URDF arm's clutch as of the next rows: where its offset puts the tool
    /// relative to the handle (the master's frame), and whether it is released.
    clutch: ([f64; 3], bool),
    last_felt: [f64; 3],
    handles: Vec<Option<(u64, [f64; 3])>>,
    forces: Vec<Option<(u64, [f64; 3])>>,
    position_sq: f64,
    force_sq: f64,
    slave_net: f64,
    recent_force: std::collections::VecDeque<f64>,
    /// The network's delay per axis as the last fresh value showed it, forward (in
    /// samples of age) and backward (receiver's sample minus sender's step).
    forward_lag: Option<[u64; 3]>,
    backward_lag: Option<[u64; 3]>,
}

impl Default for Bilateral {
    fn default() -> Self {
        Bilateral {
            tracking: Tracking::default(),
            contact: Contact::default(),
            passivity: Passivity::default(),
            felt: crate::transparency::Felt::default(),
            model_injected_j: 0.0,
            clutch: ([0.0; 3], false),
            last_felt: [0.0; 3],
            handles: vec![None; LATE_WINDOW as usize],
            forces: vec![None; LATE_WINDOW as usize],
            position_sq: 0.0,
            force_sq: 0.0,
            slave_net: 0.0,
            recent_force: std::collections::VecDeque::with_capacity(SWING_WINDOW),
            forward_lag: None,
            backward_lag: None,
        }
    }
}

fn slot(n: u64) -> usize {
    (n % LATE_WINDOW) as usize
}

/// The entry for sample `n` of a ring, if still there.
fn lookup(ring: &[Option<(u64, [f64; 3])>], n: u64) -> Option<[f64; 3]> {
    ring[slot(n)].filter(|(k, _)| *k == n).map(|(_, v)| v)
}

impl Bilateral {
    /// A URDF arm's clutch as of the next rows (see [`crate::transparency::Felt::clutch`]).
    pub fn clutch(&mut self, shift: [f64; 3], released: bool) {
        self.felt.clutch(shift, released);
        self.clutch = (shift, released);
    }

    /// Adds one row (rows come in sample order).
    pub fn add(&mut self, row: &TraceRow) {
        self.handles[slot(row.n)] = Some((row.n, row.handle));
        self.felt.add(row);
        self.model_injected_j = self.model_injected_j.max(row.model_injected_m);
        let step = distance(row.felt, self.last_felt);
        self.contact.felt_step_max_n = self.contact.felt_step_max_n.max(step);
        self.last_felt = row.felt;
        self.passivity.dissipated_j += row.dissipated_m + row.dissipated_s;
        self.observe(row.observer_m);
        if row.stepped {
            self.forces[slot(row.n)] = Some((row.n, row.h));
            self.observe(row.observer_s);
            self.slave_net = row.port_net_s;
            self.slave_row(row);
        }
        let channel = row.port_net_m + self.slave_net;
        let p = &mut self.passivity;
        p.observer_min_j = Some(p.observer_min_j.map_or(channel, |m| m.min(channel)));
        // A force the master rejected was never felt as such; one the channel held (or
        // that was not sent) is compared with the environment where a fresh one would
        // have come from: holding costs what the environment did meanwhile.
        // Released, the hand feels the clutch's spring, not the robot: not tracking.
        if row.received
            && !row.flags_m.intersects(Flags::REJECTED)
            && !row.flags_b.intersects(Flags::CORRUPTED)
            && !row.flags_f.intersects(Flags::RELEASED)
        {
            if !row.flags_b.intersects(Flags::SUBSTITUTED) {
                self.backward_lag = Some([0, 1, 2].map(|i| row.n.saturating_sub(row.q_from[i])));
            }
            let from = self
                .backward_lag
                .map(|lag| [0, 1, 2].map(|i| row.n.saturating_sub(lag[i])));
            let felt_from =
                [0, 1, 2].map(|i| from.and_then(|f| lookup(&self.forces, f[i])).map(|h| h[i]));
            if let [Some(x), Some(y), Some(z)] = felt_from {
                let d = distance(row.felt, [x, y, z]);
                self.force_sq += d * d;
                self.tracking.force_samples += 1;
            }
        }
    }

    fn observe(&mut self, w: [f64; 3]) {
        let low = w.iter().copied().fold(f64::INFINITY, f64::min);
        let p = &mut self.passivity;
        p.side_observer_min_j = Some(p.side_observer_min_j.map_or(low, |m| m.min(low)));
    }

    fn slave_row(&mut self, row: &TraceRow) {
        if self.recent_force.len() == SWING_WINDOW {
            self.recent_force.pop_front();
        }
        self.recent_force.push_back(norm(row.h));
        if row.contact_object >= 0 {
            let depth = distance(row.surface, row.tool);
            self.contact.max_penetration_m = self.contact.max_penetration_m.max(depth);
        }
        // A corrupted v(n) (the channel's flag) or a step that rejected the position it
        // received (the slave's own flag) went on from the slave's estimate, not from
        // the master's handle: left out. A rejected orientation alone
        // (ROTATION_REJECTED) is kept: the position was followed.
        if row.flags_f.intersects(Flags::CORRUPTED) || row.flags_s.intersects(Flags::REJECTED) {
            return;
        }
        // The master's handle where each value of v(n) left it; for a value the
        // channel held (or that was not sent), where a fresh one would have left it:
        // holding costs what the master did meanwhile.
        if !row.flags_f.intersects(Flags::SUBSTITUTED) {
            self.forward_lag = Some(row.delay_f.map(u64::from));
        }
        let Some(lag) = self.forward_lag else {
            return;
        };
        let at = [0, 1, 2].map(|i| {
            row.n
                .checked_sub(lag[i])
                .and_then(|k| lookup(&self.handles, k))
                .map(|h| h[i])
        });
        let [Some(x), Some(y), Some(z)] = at else {
            return;
        };
        // The tool follows the handle moved by the clutch's offset, and holds while the
        // clutch is released: those steps are not tracking (the task space's figure
        // leaves them out too). The reference is the handle's, before the offset.
        let (shift, released) = self.clutch;
        if !released {
            let d = distance(row.tool, [x + shift[0], y + shift[1], z + shift[2]]);
            self.position_sq += d * d;
            self.tracking.position_samples += 1;
        }
        let drift = distance(row.reference, [x, y, z]);
        self.passivity.drift_max_m = self.passivity.drift_max_m.max(drift);
        self.passivity.drift_final_m = drift;
    }

    /// Closes the running sums.
    pub fn finish(&mut self) {
        let (lo, hi) = self
            .recent_force
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), f| {
                (lo.min(*f), hi.max(*f))
            });
        self.contact.force_swing_n = if hi >= lo { hi - lo } else { 0.0 };
        let t = &mut self.tracking;
        if t.position_samples > 0 {
            t.position_rms_m = Some((self.position_sq / t.position_samples as f64).sqrt());
        }
        if t.force_samples > 0 {
            t.force_rms_n = Some((self.force_sq / t.force_samples as f64).sqrt());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(n: u64) -> TraceRow {
        TraceRow {
            n,
            stepped: true,
            received: true,
            contact_object: -1,
            ..TraceRow::default()
        }
    }

    #[test]
    fn compares_each_value_with_what_its_sender_had_then() {
        let mut b = Bilateral::default();
        // The handle moves 1 mm per sample along x; the slave's tool is exactly where
        // the handle was 3 samples earlier: no tracking error once delay-shifted.
        for n in 0..10u64 {
            let mut r = row(n);
            r.handle = [n as f64 * 1e-3, 0.0, 0.0];
            r.delay_f = [3; 3];
            r.tool = [n.saturating_sub(3) as f64 * 1e-3, 0.0, 0.0];
            r.reference = r.tool;
            r.h = [n as f64, 0.0, 0.0];
            // Felt: the force of the step 2 samples back, plus 0.5 N on y.
            r.q_from = [n.saturating_sub(2); 3];
            r.felt = [n.saturating_sub(2) as f64, 0.5, 0.0];
            r.observer_m = [0.0, -2e-3, 0.0];
            r.port_net_m = -(n as f64) * 1e-3;
            r.port_net_s = 0.5e-3 * n as f64;
            r.dissipated_s = 1e-4;
            if n < 3 {
                r.flags_f = Flags::SUBSTITUTED;
            }
            b.add(&r);
        }
        b.finish();
        assert_eq!(b.tracking.position_samples, 7);
        assert_eq!(b.tracking.position_rms_m, Some(0.0));
        assert_eq!(b.tracking.force_samples, 10);
        assert_eq!(b.tracking.force_rms_n, Some(0.5));
        assert_eq!(b.passivity.side_observer_min_j, Some(-2e-3));
        assert!((b.passivity.observer_min_j.unwrap_or(0.0) + 4.5e-3).abs() < 1e-15);
        assert!((b.passivity.dissipated_j - 1e-3).abs() < 1e-15);
        assert_eq!(b.passivity.drift_max_m, 0.0);
    }

    #[test]
    fn penetration_is_the_deepest_contact() {
        let mut b = Bilateral::default();
        for (n, z) in [(0u64, -0.001), (1, -0.004), (2, -0.002)] {
            let mut r = row(n);
            r.contact_object = 0;
            r.tool = [0.0, 0.0, z];
            b.add(&r);
        }
        assert!((b.contact.max_penetration_m - 0.004).abs() < 1e-15);
        // Only the last SWING_WINDOW steps count for the swing.
        for n in 3..(3 + SWING_WINDOW as u64) {
            let mut r = row(n);
            r.h = [0.0, 0.0, 1.0 + (n % 2) as f64 * 0.25];
            b.add(&r);
        }
        b.finish();
        assert_eq!(b.contact.force_swing_n, 0.25);
    }

    /// A v(n) the slave rejected is flagged on the slave's step, never on v(n) as it
    /// arrived: the step's flag is the one that keeps it out of the tracking error.
    #[test]
    fn a_step_the_slave_rejected_is_not_tracked() {
        let run = |flag_on_step: bool| {
            let mut b = Bilateral::default();
            for n in 0..6u64 {
                let mut r = row(n);
                if n == 4 {
                    // The slave held where the rejected value would have sent it 1 m off.
                    r.tool = [1.0, 0.0, 0.0];
                    if flag_on_step {
                        r.flags_s = Flags::REJECTED;
                    } else {
                        r.flags_f = Flags::REJECTED;
                    }
                }
                b.add(&r);
            }
            b.finish();
            b.tracking
        };
        let skipped = run(true);
        assert_eq!(skipped.position_samples, 5);
        assert_eq!(skipped.position_rms_m, Some(0.0));
        // The same bit on v(n) as received means nothing: that sample is tracked.
        let tracked = run(false);
        assert_eq!(tracked.position_samples, 6);
        assert!(tracked.position_rms_m.is_some_and(|e| e > 0.4));
    }
}
