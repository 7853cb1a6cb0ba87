//! The emulator process's edge: takes c(n) and h(n) as they arrive, passes them through
//! the channels, publishes v(n) and q(n), and records every passage. All channel
//! computation is in [`Emulator`].

use crate::emulator::{Emulator, EmulatorCounters, Passage};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_common::clock::now_ns;
use tactile_common::samples::{stage, FLAG_END, FLAG_PROBE};
use tactile_common::scenario::{Mode, Scenario};
use tactile_node::ipc::{Idle, IpcError};
use tactile_node::link::{Arrival, EmulatorLink, EmulatorStats, RunFilter};
use tactile_node::pace::{recv_paced, Pacer};
use tactile_node::runtime::{NodeError, Recorder};

/// The emulator's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EmulatorTotals {
    /// Channel counters (including drops and corruptions on purpose).
    pub counters: EmulatorCounters,
    /// What the four stream ends counted.
    pub links: EmulatorStats,
}

/// The emulator's recorder.
pub type EmulatorRecorder = Recorder<Passage, EmulatorTotals>;
/// The emulator's record type.
pub type EmulatorRecord = tactile_node::record::Record<Passage, EmulatorTotals>;

/// Why the emulator loop stopped.
#[derive(Debug, thiserror::Error)]
pub enum EmulatorError {
    /// The link failed.
    #[error(transparent)]
    Ipc(#[from] IpcError),
    /// The record could not be written.
    #[error("{0}")]
    Record(String),
}

impl From<NodeError> for EmulatorError {
    fn from(e: NodeError) -> Self {
        EmulatorError::Record(e.to_string())
    }
}

/// Runs the emulator loop over any link until the master's end-of-run sample (true) or
/// a stop request (false).
pub fn run_with<L: EmulatorLink + ?Sized>(
    scenario: &Scenario,
    link: &L,
    rec: &mut EmulatorRecorder,
    wake_early: Duration,
) -> Result<bool, EmulatorError> {
    let mut emu = Emulator::new(scenario);
    let mut filter = RunFilter::default();
    let mut seen_first = false;
    let mut last_seq = 0;
    // Realtime: sleep until just before c(n) is due (learned from its arrivals), but
    // not while h(n) is expected back from the slave, which comes within microseconds.
    let mut pacer = (scenario.mode == Mode::Realtime)
        .then(|| Pacer::new(scenario.t_s_ns(), wake_early.as_nanos() as u64));
    // The sequence number of the last v(n) forwarded whose h(n) has not come back:
    // after a stall several are in flight, and the emulator sleeps only once the
    // last of them is answered.
    let mut awaiting: Option<u64> = None;
    let totals = |emu: &Emulator, filter: &RunFilter| {
        let mut links = link.stats();
        links.c_in.foreign += filter.foreign;
        EmulatorTotals {
            counters: emu.counters(),
            links,
        }
    };
    let completed = loop {
        let deadline = Instant::now() + Duration::from_secs(3600);
        let paced = pacer.as_ref().filter(|_| awaiting.is_none());
        let (got, waiting) = recv_paced(paced, deadline, |d| link.recv(d))?;
        let arrival = match got {
            Ok(a) => a,
            Err(Idle::Timeout) => continue,
            Err(Idle::Terminate) => break false,
        };
        let (token, seq) = match &arrival {
            Arrival::Forward(c) => (c.run, c.seq),
            Arrival::Backward(h) => (h.run, h.seq),
        };
        let mut joined = None;
        if !filter.admit(token, &mut joined) {
            continue;
        }
        if let Some(t) = joined {
            rec.run(t)?;
        }
        match arrival {
            Arrival::Forward(mut c) => {
                let flags = c.signal.flags;
                if flags & (FLAG_PROBE | FLAG_END) != 0 {
                    link.send_v(c, true)?;
                    if flags & FLAG_END != 0 {
                        rec.event(last_seq, "end of run from the master")?;
                        break true;
                    }
                    continue;
                }
                if !seen_first {
                    seen_first = true;
                    rec.event(seq, "first sample from the master")?;
                }
                last_seq = seq;
                c.stamps[stage::EMU_FWD_RECV] = now_ns();
                if let Some(p) = &mut pacer {
                    let t = c.stamps[stage::EMU_FWD_RECV];
                    p.arrived(c.seq, t, waiting);
                }
                let (out, passage) = emu.forward(&c);
                if let Some(mut v) = out {
                    awaiting = Some(v.seq);
                    v.stamps[stage::EMU_FWD_SEND] = now_ns();
                    link.send_v(v, false)?;
                }
                rec.sample(passage)?;
            }
            Arrival::Backward(mut h) => {
                if h.signal.flags & FLAG_PROBE != 0 {
                    link.send_q(h, true)?;
                    continue;
                }
                h.stamps[stage::EMU_BWD_RECV] = now_ns();
                if awaiting.is_some_and(|s| h.seq >= s) {
                    awaiting = None;
                }
                let (out, passage) = emu.backward(&h);
                if let Some(mut q) = out {
                    q.stamps[stage::EMU_BWD_SEND] = now_ns();
                    link.send_q(q, false)?;
                }
                rec.sample(passage)?;
            }
        }
        if rec.counters_due() {
            rec.counters(totals(&emu, &filter))?;
        }
    };
    let reason = if completed {
        "completed"
    } else {
        "interrupted"
    };
    rec.stop(totals(&emu, &filter), reason)?;
    Ok(completed)
}
