//! The slave process's edge: takes v(n), runs one step of [`Slave`], publishes h(n).
//! When v(n) stops coming for the peer timeout, the slave holds its position, one
//! step per t_s, until input returns.

use crate::hsd::{Slave, SlaveCounters};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_common::clock::now_ns;
use tactile_common::ipc::{Idle, InboxStats, IoxSlave, IpcError, OutboxStats, WaitPolicy};
use tactile_common::link::SlaveLink;
use tactile_common::samples::{stage, Backward, FLAG_END, FLAG_PROBE};
use tactile_common::scenario::{Scenario, ScenarioError};
use thiserror::Error;

/// What the slave process needs to run.
#[derive(Debug, Clone)]
pub struct SlaveOptions {
    /// The scenario.
    pub scenario: Scenario,
    /// iceoryx2 prefix of this run.
    pub prefix: String,
    /// Waiting for the next sample.
    pub wait: WaitPolicy,
}

/// What went wrong in the slave process.
#[derive(Debug, Error)]
pub enum SlaveError {
    /// The scenario is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// Shared memory failed.
    #[error(transparent)]
    Ipc(#[from] IpcError),
}

/// Everything the slave measured.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct SlaveRun {
    /// State-machine counters.
    pub counters: SlaveCounters,
    /// v(n) as received.
    pub v_in: InboxStats,
    /// h(n) as published.
    pub h_out: OutboxStats,
    /// True if SIGINT/SIGTERM stopped it.
    pub interrupted: bool,
}

/// How long without input before the slave holds: the scenario's peer timeout in
/// samples, but never under 50 ms (a lockstep master may pause that long for its own
/// reasons).
pub fn hold_timeout(scenario: &Scenario) -> Duration {
    let t = Duration::from_nanos(scenario.faults.peer_timeout_samples * scenario.t_s_ns());
    t.max(Duration::from_millis(50))
}

/// Runs over iceoryx2 until the end-of-run sample or a stop request.
pub fn run(opts: &SlaveOptions) -> Result<SlaveRun, SlaveError> {
    run_with(opts, &IoxSlave::open(&opts.prefix, opts.wait)?)
}

/// Runs the slave loop over any transport.
pub fn run_with(opts: &SlaveOptions, link: &impl SlaveLink) -> Result<SlaveRun, SlaveError> {
    let mut slave = Slave::new(&opts.scenario)?;
    let timeout = hold_timeout(&opts.scenario);
    let t_s = Duration::from_nanos(opts.scenario.t_s_ns());
    let mut interrupted = false;
    // No input yet: wait as long as it takes for the first sample.
    let mut deadline: Option<Instant> = None;
    loop {
        let until = deadline.unwrap_or_else(|| Instant::now() + Duration::from_secs(3600));
        match link.recv(until)? {
            Ok(mut v) => {
                let flags = v.signal.flags;
                if flags & FLAG_END != 0 {
                    break;
                }
                if flags & FLAG_PROBE != 0 {
                    let mut echo = Backward {
                        seq: v.seq,
                        ..Backward::default()
                    };
                    echo.signal.flags = FLAG_PROBE;
                    link.send_h(echo, true)?;
                    continue;
                }
                v.stamps[stage::SLAVE_RECV] = now_ns();
                let mut h = slave.step(&v);
                h.stamps[stage::SLAVE_SEND] = now_ns();
                link.send_h(h, false)?;
                deadline = Some(Instant::now() + timeout);
            }
            Err(Idle::Timeout) => {
                if deadline.is_some() {
                    // Input went silent: hold, one step per t_s, until it returns.
                    slave.hold();
                    deadline = Some(Instant::now() + t_s);
                }
            }
            Err(Idle::Terminate) => {
                interrupted = true;
                break;
            }
        }
    }
    let (v_in, h_out) = link.stats();
    Ok(SlaveRun {
        counters: slave.counters(),
        v_in,
        h_out,
        interrupted,
    })
}
