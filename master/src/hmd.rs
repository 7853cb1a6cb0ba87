//! The master side's per-sample logic (OP + MD + HMD) as a pure state machine.
//!
//! [`Master::forward`] turns sample n of the operator's motion into c(n): the master
//! device's joint encoders b(n) (the MD model), then FK-HMD. [`Master::backward`] turns
//! a received q(n) into joint torques p(n) = J(b)^T q (KFF-HMD) and builds the trace
//! row. The process edge and the in-process simulation call the same functions.

use crate::operator::{OperatorSource, Target};
use serde::{Deserialize, Serialize};
use tactile_common::arith::StdTrig;
use tactile_common::engine::Engine;
use tactile_common::geometry::Lengths;
use tactile_common::kernels::{self, IkStatus};
use tactile_common::samples::{stage, Backward, Forward, FLAG_REJECTED};
use tactile_common::scenario::{Scenario, ScenarioError};
use tactile_common::trace::TraceRow;

/// What the master counted over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct MasterCounters {
    /// Forward samples produced.
    pub sent: u64,
    /// Backward samples used.
    pub received: u64,
    /// Operator targets outside the master's workspace (MD angles clamped).
    pub operator_clamped: u64,
    /// Backward samples with a NaN or infinite force, rejected (zero torque).
    pub rejected: u64,
}

/// The master: operator source, device model and HMD kernels.
#[derive(Debug)]
pub struct Master {
    engine: Engine,
    truth: Lengths<f64>,
    truth_engine: Engine,
    source: OperatorSource,
    t_s: f64,
    t_s_ns: u64,
    theta_md: [f64; 3],
    counters: MasterCounters,
}

impl Master {
    /// A master for the scenario with a loaded operator source.
    pub fn new(scenario: &Scenario, source: OperatorSource) -> Result<Master, ScenarioError> {
        let geometry = scenario.device.geometry()?;
        let cordic = scenario.cordic.config()?;
        let bad = |e: tactile_common::cordic::CordicError| ScenarioError::Invalid {
            field: "cordic".into(),
            problem: e.to_string(),
        };
        Ok(Master {
            engine: Engine::new(scenario.arithmetic, geometry, cordic).map_err(bad)?,
            truth: geometry.lengths(),
            truth_engine: Engine::new(tactile_common::arith::ArithKind::F64, geometry, cordic)
                .map_err(bad)?,
            source,
            t_s: scenario.t_s(),
            t_s_ns: scenario.t_s_ns(),
            theta_md: [0.0; 3],
            counters: MasterCounters::default(),
        })
    }

    /// Counters so far.
    pub fn counters(&self) -> MasterCounters {
        self.counters
    }

    /// Sample n forward: operator a(n) -> MD encoders b(n) -> FK-HMD c(n).
    /// `now_ns` is the tick time; it becomes the origin timestamp of all three values.
    pub fn forward(&mut self, n: u64, now_ns: u64) -> (Forward, [f64; 3]) {
        let target = match self.source.target(n, self.t_s) {
            Target::Joints(theta) => {
                self.theta_md = theta;
                kernels::fk(&self.truth, &StdTrig, theta)
            }
            Target::Position(p) => {
                // The hand puts the handle at p; the encoders read the joint angles the
                // real device takes there (f64: physics, not the HMD datapath).
                let s = self.truth_engine.ik(p);
                match s.status {
                    IkStatus::Reachable => self.theta_md = s.theta,
                    IkStatus::Clamped => {
                        self.counters.operator_clamped += 1;
                        self.theta_md = s.theta;
                    }
                    IkStatus::Invalid => self.counters.operator_clamped += 1,
                }
                p
            }
        };
        let c = self.engine.fk(self.theta_md);
        let mut f = Forward {
            seq: n,
            target,
            ..Forward::default()
        };
        f.signal.value = c;
        f.signal.origin_seq = [n; 3];
        f.signal.origin_ns = [now_ns; 3];
        f.stamps[stage::MASTER_TICK] = now_ns;
        self.counters.sent += 1;
        (f, self.theta_md)
    }

    /// q(n) back: KFF-HMD torques on the current master angles, and the trace row.
    /// `forward` is the sample this tick sent; `q` has its `MASTER_DONE` stamp set by
    /// the caller after this returns (the row's round trip is filled in then).
    pub fn backward(&mut self, forward: &Forward, q: &Backward) -> TraceRow {
        self.counters.received += 1;
        let mut felt = q.signal.value;
        let mut tau = [0.0; 3];
        if felt.iter().all(|f| f.is_finite()) {
            tau = self.engine.kff(self.theta_md, felt);
        } else {
            self.counters.rejected += 1;
            felt = [0.0; 3];
        }
        let mut q = *q;
        if !q.signal.value.iter().all(|f| f.is_finite()) {
            q.signal.flags |= FLAG_REJECTED;
        }
        TraceRow {
            n: forward.seq,
            target: forward.target,
            theta_md: self.theta_md,
            forward: *forward,
            backward: Some(q),
            tau,
            felt,
            round_trip_ns: 0,
            overhead_ns: 0,
        }
    }

    /// A row for a sample whose backward sample never came (deadline missed or lost).
    pub fn missing(&self, forward: &Forward) -> TraceRow {
        TraceRow {
            n: forward.seq,
            target: forward.target,
            theta_md: self.theta_md,
            forward: *forward,
            ..TraceRow::default()
        }
    }

    /// Fills the row's round trip and overhead from its final stamps: round trip is
    /// done-time minus the oldest origin among q's values, on the master's clock alone.
    pub fn account(&self, row: &mut TraceRow) {
        let Some(b) = row.backward else { return };
        let done = b.stamps[stage::MASTER_DONE];
        let (i, origin) = (0..3)
            .map(|i| (i, b.signal.origin_ns[i]))
            .min_by_key(|&(_, t)| t)
            .unwrap_or((0, 0));
        row.round_trip_ns = done.saturating_sub(origin);
        let injected = u64::from(b.signal.delay_samples[i]) * self.t_s_ns;
        row.overhead_ns = row.round_trip_ns as i64 - injected as i64;
    }
}
