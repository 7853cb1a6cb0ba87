//! The emulator process's edge: takes c(n) and h(n) as they arrive, passes them through
//! the channels and publishes v(n) and q(n). All channel computation is in [`Emulator`].

use crate::emulator::{Emulator, EmulatorCounters};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_common::clock::now_ns;
use tactile_common::ipc::{self, streams, Idle, Inbox, IpcError, Outbox, WaitPolicy, Waker};
use tactile_common::samples::{stage, Backward, Forward, StreamCount, FLAG_END, FLAG_PROBE};
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
    /// Channel counters.
    pub counters: EmulatorCounters,
    /// c(n) in, v(n) out.
    pub forward: StreamCount,
    /// h(n) in, q(n) out.
    pub backward: StreamCount,
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
    let mut run = EmulatorRun {
        counters: EmulatorCounters::default(),
        forward: StreamCount::default(),
        backward: StreamCount::default(),
        interrupted: false,
    };
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
                    out_v.send(c)?;
                    if flags & FLAG_END != 0 {
                        break;
                    }
                    continue;
                }
                c.stamps[stage::EMU_FWD_RECV] = now_ns();
                run.forward.saw(c.seq);
                let mut v = emu.forward(&c);
                v.stamps[stage::EMU_FWD_SEND] = now_ns();
                out_v.send(v)?;
                run.forward.sent += 1;
            }
            Ok(Arrival::Backward(mut h)) => {
                if h.signal.flags & FLAG_PROBE != 0 {
                    out_q.send(h)?;
                    continue;
                }
                h.stamps[stage::EMU_BWD_RECV] = now_ns();
                run.backward.saw(h.seq);
                let mut q = emu.backward(&h);
                q.stamps[stage::EMU_BWD_SEND] = now_ns();
                out_q.send(q)?;
                run.backward.sent += 1;
            }
            Err(Idle::Timeout) => {}
            Err(Idle::Terminate) => {
                run.interrupted = true;
                break;
            }
        }
    }
    run.counters = emu.counters();
    Ok(run)
}
