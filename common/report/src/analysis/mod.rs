//! The run report's statistics: latency histograms, per-stage times, tracking and force
//! statistics, gathered row by row from the joined records (so a run of any length is
//! reported in bounded memory).
//!
//! The same code reports a process run and an in-process simulation. Latencies are
//! reported as count, p50, p90, p99, p99.9, max and mean, exactly while a distribution
//! holds few distinct values and from an HdrHistogram past that ([`Latency`]); the full
//! distribution is written in HdrHistogram's percentile-file form (`*.hgrm`,
//! microseconds) so standard tools can plot it.

mod latency;

pub use latency::{rounding_note, us_header, us_line, Latency, Percentiles, EXACT_VALUES};

use crate::trace::TraceRow;
use serde::Serialize;
use tactile_math::vec3::{distance, norm};
use tactile_messages::samples::{stage, Flags};
use tactile_messages::Role;

/// Per-stage times of the loop, ns: compute in each process and each transport hop.
pub const STAGES: [(&str, usize, usize); 9] = [
    (
        "master_tick_to_send",
        stage::MASTER_TICK,
        stage::MASTER_SEND,
    ),
    (
        "hop_master_to_emulator",
        stage::MASTER_SEND,
        stage::EMU_FWD_RECV,
    ),
    ("emulator_forward", stage::EMU_FWD_RECV, stage::EMU_FWD_SEND),
    (
        "hop_emulator_to_slave",
        stage::EMU_FWD_SEND,
        stage::SLAVE_RECV,
    ),
    ("slave_compute", stage::SLAVE_RECV, stage::SLAVE_SEND),
    (
        "hop_slave_to_emulator",
        stage::SLAVE_SEND,
        stage::EMU_BWD_RECV,
    ),
    (
        "emulator_backward",
        stage::EMU_BWD_RECV,
        stage::EMU_BWD_SEND,
    ),
    (
        "hop_emulator_to_master",
        stage::EMU_BWD_SEND,
        stage::MASTER_RECV,
    ),
    ("master_compute_bwd", stage::MASTER_RECV, stage::MASTER_DONE),
];

/// The node that stamps `stage`: 0 master, 1 emulator, 2 slave.
pub fn stamper(stage: usize) -> usize {
    match stage {
        stage::EMU_FWD_RECV | stage::EMU_FWD_SEND | stage::EMU_BWD_RECV | stage::EMU_BWD_SEND => 1,
        stage::SLAVE_RECV | stage::SLAVE_SEND => 2,
        _ => 0,
    }
}

/// Node pairs whose clocks may be compared, with the four stamps of an exchange
/// between them: A sends, B receives, B sends back, A receives.
pub const PAIRS: [(usize, usize, [usize; 4]); 3] = [
    (
        0,
        1,
        [
            stage::MASTER_SEND,
            stage::EMU_FWD_RECV,
            stage::EMU_BWD_SEND,
            stage::MASTER_RECV,
        ],
    ),
    (
        1,
        2,
        [
            stage::EMU_FWD_SEND,
            stage::SLAVE_RECV,
            stage::SLAVE_SEND,
            stage::EMU_BWD_RECV,
        ],
    ),
    (
        0,
        2,
        [
            stage::MASTER_SEND,
            stage::SLAVE_RECV,
            stage::SLAVE_SEND,
            stage::MASTER_RECV,
        ],
    ),
];

/// The offset of one node's clock from another's, estimated from the exchanges between
/// them (an estimate: it assumes the two directions of the network take equal time).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ClockOffset {
    /// `A-B`: the offset is B's clock minus A's.
    pub between: String,
    /// B's clock minus A's, ns: an estimate from the exchange with the shortest network
    /// round trip ((t2 - t1) + (t3 - t4)) / 2, as NTP does.
    pub offset_ns_estimate: i64,
    /// The estimate is within this of the truth, ns: half that shortest round trip.
    pub uncertainty_ns: i64,
    /// The shortest network round trip seen (both hops, without B's own time), ns.
    pub min_network_round_trip_ns: i64,
    /// Exchanges used.
    pub exchanges: u64,
}

/// Gathers the best exchange between two nodes.
#[derive(Debug, Clone, Default)]
struct OffsetFinder {
    best: Option<(i64, i64)>,
    exchanges: u64,
}

impl OffsetFinder {
    fn add(&mut self, t: [u64; 4]) {
        let [t1, t2, t3, t4] = t.map(|x| x as i64);
        let network = (t4 - t1) - (t3 - t2);
        if network < 0 {
            return;
        }
        self.exchanges += 1;
        if self.best.is_none_or(|(rtt, _)| network < rtt) {
            self.best = Some((network, ((t2 - t1) + (t3 - t4)) / 2));
        }
    }
}

/// Tracking and force statistics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Motion {
    /// RMS distance of the slave's tool from the position it was asked to reach (v(n),
    /// the master's c after the network), m; `None` when the slave recorded no step.
    pub tracking_rms_m: Option<f64>,
    /// Largest such distance, m.
    pub tracking_max_m: Option<f64>,
    /// Largest contact force magnitude the slave produced, N.
    pub force_max_n: f64,
    /// RMS force the operator felt over the answered samples, N; `None` without one.
    pub felt_rms_n: Option<f64>,
    /// Largest force the operator felt, N.
    pub felt_max_n: f64,
    /// Samples with the tool in contact.
    pub contact_samples: u64,
    /// Largest master joint torque, N m.
    pub tau_max_nm: f64,
}

/// The statistics of a run's rows, gathered one row at a time (bounded memory).
#[derive(Debug, Clone)]
pub struct Analysis {
    /// Round trip, origin to torques out, on the master's clock.
    pub round_trip: Latency,
    /// Round trip minus injected delay.
    pub overhead: Latency,
    /// Round trip in samples: n minus the oldest sample q(n) started from (the
    /// measure of a lockstep run, whose wall-clock time is not the loop's).
    pub round_trip_samples: Latency,
    /// Per stage, in [`STAGES`] order.
    pub stages: Vec<Latency>,
    /// Tracking and forces.
    pub motion: Motion,
    /// The bilateral loop's metrics.
    pub bilateral: crate::metrics::Bilateral,
    /// A physics scene's task: the effort it took.
    pub task: crate::task::TaskFigures,
    /// Rows with an answer.
    pub received: u64,
    /// Rows in all.
    pub rows: u64,
    /// Samples whose predictor refused a guess from outside the scenario (the Python
    /// API) as not physically possible: the master's, the slave's.
    pub guesses_refused: [u64; 2],
    with_stages: bool,
    /// Each node's clock domain (empty: the node left no record).
    domains: [String; 3],
    offsets: [OffsetFinder; 3],
    track_sq: f64,
    tracked: u64,
    felt_sq: f64,
}

impl Analysis {
    /// An empty analysis; `with_stages`: the stamps are real (a process run);
    /// `domains`: the clock domain of master, emulator and slave.
    pub fn new(with_stages: bool, domains: [String; 3]) -> Self {
        Analysis {
            round_trip: Latency::default(),
            overhead: Latency::default(),
            round_trip_samples: Latency::default(),
            stages: vec![Latency::default(); STAGES.len()],
            motion: Motion::default(),
            bilateral: crate::metrics::Bilateral::default(),
            task: crate::task::TaskFigures::default(),
            received: 0,
            rows: 0,
            guesses_refused: [0; 2],
            with_stages,
            domains,
            offsets: Default::default(),
            track_sq: 0.0,
            tracked: 0,
            felt_sq: 0.0,
        }
    }

    /// Adds one row.
    pub fn add(&mut self, row: &TraceRow) {
        self.rows += 1;
        for (k, flags) in [row.flags_m, row.flags_s].into_iter().enumerate() {
            self.guesses_refused[k] += u64::from(flags.intersects(Flags::GUESS_REFUSED));
        }
        self.bilateral.add(row);
        self.task.add(row);
        let m = &mut self.motion;
        m.force_max_n = m.force_max_n.max(norm(row.h));
        if row.contact_object >= 0 {
            m.contact_samples += 1;
        }
        // Tracking against what the slave was asked to reach; a step that rejected the
        // position it received (implausible, not finite, refused by the IK: the slave's
        // own flag, which v(n) never carries) went on from the slave's estimate, not
        // from v(n), and is left out. A rejected orientation alone (ROTATION_REJECTED)
        // is kept: the position was followed.
        if row.stepped
            && !row.flags_s.intersects(Flags::REJECTED)
            && row.v.iter().all(|x| x.is_finite())
        {
            // The control's reference: v(n) itself without control, what TDPA or the
            // wave made of it otherwise (a wave is not a position).
            let d = distance(row.tool, row.reference);
            self.track_sq += d * d;
            self.tracked += 1;
            m.tracking_max_m = Some(m.tracking_max_m.unwrap_or(0.0).max(d));
        }
        m.tau_max_nm = m
            .tau_max_nm
            .max(row.tau.iter().fold(0.0f64, |a, t| a.max(t.abs())));
        if !row.received {
            return;
        }
        self.received += 1;
        let felt = norm(row.felt);
        self.felt_sq += felt * felt;
        m.felt_max_n = m.felt_max_n.max(felt);
        if !(row.flags_b | row.flags_f).intersects(Flags::SUBSTITUTED) {
            self.round_trip.record(row.round_trip_ns as i64);
            self.overhead.record(row.overhead_ns);
            let oldest = row.q_origin.iter().copied().min().unwrap_or(row.n);
            self.round_trip_samples
                .record(row.n.saturating_sub(oldest) as i64);
        }
        if !self.with_stages {
            return;
        }
        for (k, (_, from, to)) in STAGES.iter().enumerate() {
            let (a, z) = (row.stamps[*from], row.stamps[*to]);
            if a != 0 && z != 0 && self.same_clock(stamper(*from), stamper(*to)) {
                self.stages[k].record(z as i64 - a as i64);
            }
        }
        for (k, (a, b, st)) in PAIRS.iter().enumerate() {
            let t = st.map(|i| row.stamps[i]);
            if !self.same_clock(*a, *b) && t.iter().all(|x| *x != 0) {
                self.offsets[k].add(t);
            }
        }
    }

    /// Rows the tracking error was computed from (those with a step of the slave on
    /// a finite reference).
    pub fn tracked(&self) -> u64 {
        self.tracked
    }

    /// Each node's clock domain (empty where it left no record).
    pub fn domains(&self) -> &[String; 3] {
        &self.domains
    }

    /// True if nodes `a` and `b` stamp with one clock.
    pub fn same_clock(&self, a: usize, b: usize) -> bool {
        self.domains[a] == self.domains[b]
    }

    /// The offset estimates between nodes on different clocks that exchanged samples.
    pub fn clock_offsets(&self) -> Vec<ClockOffset> {
        PAIRS
            .iter()
            .zip(&self.offsets)
            .filter_map(|((a, b, _), f)| {
                let (rtt, offset) = f.best?;
                Some(ClockOffset {
                    between: format!("{}-{}", Role::ALL[*a], Role::ALL[*b]),
                    offset_ns_estimate: offset,
                    uncertainty_ns: rtt / 2,
                    min_network_round_trip_ns: rtt,
                    exchanges: f.exchanges,
                })
            })
            .collect()
    }

    /// Closes the running sums into the motion statistics.
    pub fn finish(&mut self) {
        self.bilateral.finish();
        if self.tracked > 0 {
            self.motion.tracking_rms_m = Some((self.track_sq / self.tracked as f64).sqrt());
        }
        if self.received > 0 {
            self.motion.felt_rms_n = Some((self.felt_sq / self.received as f64).sqrt());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tracking error leaves out a step whose v(n) the slave rejected: the slave's
    /// own flag says so (v(n) as received never carries it).
    #[test]
    fn a_step_the_slave_rejected_is_not_in_the_tracking_error() {
        let mut a = Analysis::new(false, Default::default());
        for n in 0..4u64 {
            let mut r = TraceRow {
                n,
                stepped: true,
                contact_object: -1,
                ..TraceRow::default()
            };
            if n == 2 {
                (r.tool, r.flags_s) = ([0.5, 0.0, 0.0], Flags::REJECTED);
            }
            a.add(&r);
        }
        assert_eq!(a.tracked(), 3);
    }
}
