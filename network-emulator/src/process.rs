//! The emulator process's edge: takes c(n) and h(n) as they arrive, passes them through
//! the channels and publishes v(n) and q(n). All channel computation is in [`Emulator`].

use crate::emulator::{Emulator, EmulatorCounters};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_common::clock::now_ns;
use tactile_common::ipc::{
    self, streams, Idle, Inbox, InboxStats, IpcError, Outbox, OutboxStats, WaitPolicy, Waker,
};
use tactile_common::samples::{stage, Backward, Forward, FLAG_END, FLAG_PROBE};
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

// Lives on the stack for one sample; boxing the larger variant would allocate per sample.
#[allow(clippy::large_enum_variant)]
enum Arrival {
    Forward(Forward),
    Backward(Backward),
}

/// Runs until the master's end-of-run sample or a stop request.
pub fn run(opts: &EmulatorOptions) -> Result<EmulatorRun, IpcError> {
    let mut emu = Emulator::new(&opts.scenario);
    let node = ipc::node(&opts.prefix, "emulator")?;
    let in_c: Inbox<Forward> = Inbox::open(&node, streams::C)?;
    let out_v: Outbox<Forward> = Outbox::open(&node, streams::V, streams::WAKE_SLAVE)?;
    let in_h: Inbox<Backward> = Inbox::open(&node, streams::H)?;
    let out_q: Outbox<Backward> = Outbox::open(&node, streams::Q, streams::WAKE_MASTER)?;
    let waker = Waker::open(&node, streams::WAKE_EMULATOR)?;
    let mut interrupted = false;
    loop {
        let deadline = Instant::now() + Duration::from_secs(3600);
        let got = waker.wait(&node, opts.wait.spin, deadline, || {
            // Backward first: it completes a round trip the master is waiting for.
            if let Some(h) = in_h.try_recv()? {
                return Ok(Some(Arrival::Backward(h)));
            }
            Ok(in_c.try_recv()?.map(Arrival::Forward))
        })?;
        match got {
            Ok(Arrival::Forward(mut c)) => {
                let flags = c.signal.flags;
                if flags & (FLAG_PROBE | FLAG_END) != 0 {
                    out_v.send_control(c)?;
                    if flags & FLAG_END != 0 {
                        break;
                    }
                    continue;
                }
                c.stamps[stage::EMU_FWD_RECV] = now_ns();
                if let Some(mut v) = emu.forward(&c) {
                    v.stamps[stage::EMU_FWD_SEND] = now_ns();
                    out_v.send(v)?;
                }
            }
            Ok(Arrival::Backward(mut h)) => {
                if h.signal.flags & FLAG_PROBE != 0 {
                    out_q.send_control(h)?;
                    continue;
                }
                h.stamps[stage::EMU_BWD_RECV] = now_ns();
                if let Some(mut q) = emu.backward(&h) {
                    q.stamps[stage::EMU_BWD_SEND] = now_ns();
                    out_q.send(q)?;
                }
            }
            Err(Idle::Timeout) => {}
            Err(Idle::Terminate) => {
                interrupted = true;
                break;
            }
        }
    }
    Ok(EmulatorRun {
        counters: emu.counters(),
        c_in: in_c.stats(),
        v_out: out_v.stats(),
        h_in: in_h.stats(),
        q_out: out_q.stats(),
        interrupted,
    })
}
