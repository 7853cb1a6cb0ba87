//! The slave process's edge: takes v(n), runs one step of [`Slave`], publishes h(n).

use crate::hsd::{Slave, SlaveCounters};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_common::clock::now_ns;
use tactile_common::ipc::{self, streams, Idle, Inbox, IpcError, Outbox, WaitPolicy, Waker};
use tactile_common::samples::{stage, Backward, Forward, StreamCount, FLAG_END, FLAG_PROBE};
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
    /// v(n) in, h(n) out.
    pub stream: StreamCount,
    /// True if SIGINT/SIGTERM stopped it.
    pub interrupted: bool,
}

/// Runs until the end-of-run sample or a stop request.
pub fn run(opts: &SlaveOptions) -> Result<SlaveRun, SlaveError> {
    let mut slave = Slave::new(&opts.scenario)?;
    let node = ipc::node(&opts.prefix, "slave")?;
    let inbox: Inbox<Forward> = Inbox::open(&node, streams::V)?;
    let out: Outbox<Backward> = Outbox::open(&node, streams::H, streams::WAKE_EMULATOR)?;
    let waker = Waker::open(&node, streams::WAKE_SLAVE)?;
    let mut run = SlaveRun {
        counters: SlaveCounters::default(),
        stream: StreamCount::default(),
        interrupted: false,
    };
    loop {
        let deadline = Instant::now() + Duration::from_secs(3600);
        match waker.wait(&node, opts.wait.spin, deadline, || inbox.try_recv())? {
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
                    out.send(echo)?;
                    continue;
                }
                v.stamps[stage::SLAVE_RECV] = now_ns();
                run.stream.saw(v.seq);
                let mut h = slave.step(&v);
                h.stamps[stage::SLAVE_SEND] = now_ns();
                out.send(h)?;
                run.stream.sent += 1;
            }
            Err(Idle::Timeout) => {}
            Err(Idle::Terminate) => {
                run.interrupted = true;
                break;
            }
        }
    }
    run.counters = slave.counters();
    Ok(run)
}
