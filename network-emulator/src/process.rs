//! The emulator process's edge: takes c(n) and h(n) as they arrive, passes them through
//! the channels and publishes v(n) and q(n). All channel computation is in [`Emulator`].

use crate::emulator::{Emulator, EmulatorCounters};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_common::clock::now_ns;
use tactile_common::ipc::{Idle, InboxStats, IoxEmulator, IpcError, OutboxStats, WaitPolicy};
use tactile_common::link::{Arrival, EmulatorLink};
use tactile_common::samples::{stage, FLAG_END, FLAG_PROBE};
use tactile_common::scenario::Scenario;

/// What the emulator process needs to run.
#[derive(Debug, Clone)]
pub struct EmulatorOptions {
    /// The scenario.
    pub scenario: Scenario,
    /// iceoryx2 prefix of this run.
    pub prefix: String,
    /// Waiting for the next sample.
    pub wait: WaitPolicy,
}

/// Everything the emulator measured.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct EmulatorRun {
    /// Channel counters (including drops and corruptions on purpose).
    pub counters: EmulatorCounters,
    /// c(n) as received from the master.
    pub c_in: InboxStats,
    /// v(n) as published to the slave.
    pub v_out: OutboxStats,
    /// h(n) as received from the slave.
    pub h_in: InboxStats,
    /// q(n) as published to the master.
    pub q_out: OutboxStats,
    /// True if SIGINT/SIGTERM stopped it.
    pub interrupted: bool,
}

/// Runs over iceoryx2 until the master's end-of-run sample or a stop request.
pub fn run(opts: &EmulatorOptions) -> Result<EmulatorRun, IpcError> {
    run_with(opts, &IoxEmulator::open(&opts.prefix, opts.wait)?)
}

/// Runs the emulator loop over any transport.
pub fn run_with(opts: &EmulatorOptions, link: &impl EmulatorLink) -> Result<EmulatorRun, IpcError> {
    let mut emu = Emulator::new(&opts.scenario);
    let mut interrupted = false;
    loop {
        let deadline = Instant::now() + Duration::from_secs(3600);
        match link.recv(deadline)? {
            Ok(Arrival::Forward(mut c)) => {
                let flags = c.signal.flags;
                if flags & (FLAG_PROBE | FLAG_END) != 0 {
                    link.send_v(c, true)?;
                    if flags & FLAG_END != 0 {
                        break;
                    }
                    continue;
                }
                c.stamps[stage::EMU_FWD_RECV] = now_ns();
                if let Some(mut v) = emu.forward(&c) {
                    v.stamps[stage::EMU_FWD_SEND] = now_ns();
                    link.send_v(v, false)?;
                }
            }
            Ok(Arrival::Backward(mut h)) => {
                if h.signal.flags & FLAG_PROBE != 0 {
                    link.send_q(h, true)?;
                    continue;
                }
                h.stamps[stage::EMU_BWD_RECV] = now_ns();
                if let Some(mut q) = emu.backward(&h) {
                    q.stamps[stage::EMU_BWD_SEND] = now_ns();
                    link.send_q(q, false)?;
                }
            }
            Err(Idle::Timeout) => {}
            Err(Idle::Terminate) => {
                interrupted = true;
                break;
            }
        }
    }
    let st = link.stats();
    Ok(EmulatorRun {
        counters: emu.counters(),
        c_in: st.c_in,
        v_out: st.v_out,
        h_in: st.h_in,
        q_out: st.q_out,
        interrupted,
    })
}
