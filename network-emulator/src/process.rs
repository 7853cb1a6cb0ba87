//! The emulator process's edge: takes c(n) and h(n) as they arrive, passes them through
//! the channels, publishes v(n) and q(n), and records every passage. All channel
//! computation is in [`Emulator`].

use crate::emulator::{Emulator, EmulatorCounters, Passage};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};
use tactile_messages::clock::now_ns;
use tactile_messages::samples::{stage, FLAG_END, FLAG_PROBE};
use tactile_node::args::NodeError;
use tactile_node::link::{Arrival, EmulatorLink, EmulatorStats, RunFilter};
use tactile_node::link::{Idle, LinkError};
use tactile_node::pace::{recv_paced, Pacer};
use tactile_node::recorder::Recorder;
use tactile_scenario::{Mode, Scenario};

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
    Ipc(#[from] LinkError),
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
    replays: [Option<tactile_netem::Replay>; 2],
    link: &L,
    rec: &mut EmulatorRecorder,
    wake_early: Duration,
) -> Result<bool, EmulatorError> {
    let mut emu = Emulator::with_replays(scenario, replays);
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
                    // The slave usually shares this CPU, polling for v(n): let it take
                    // v(n) now and write the record after, as the slave does with h(n)
                    // (measured: the hop's p50 from 3.0 to 1.6 us at 1 kHz under
                    // SCHED_FIFO, the loop's from 10.1-10.4 to 9.5-9.6 us).
                    std::thread::yield_now();
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;
    use std::collections::VecDeque;
    use tactile_messages::samples::{Backward, Forward};
    use tactile_node::link::{InboxStats, OutboxStats};

    /// A scripted link: hands out its arrivals in order and notes, for every receive,
    /// whether it was a look without waiting (the pacer's try before it sleeps) and
    /// how many h had been handed out by then.
    #[derive(Default)]
    struct Script {
        arrivals: RefCell<VecDeque<Arrival>>,
        calls: RefCell<Vec<(bool, usize)>>,
        h_given: RefCell<usize>,
    }

    impl EmulatorLink for Script {
        fn recv(&self, deadline: Instant) -> tactile_node::link::Wait<Arrival> {
            let is_try = deadline <= Instant::now();
            self.calls
                .borrow_mut()
                .push((is_try, *self.h_given.borrow()));
            match self.arrivals.borrow_mut().pop_front() {
                Some(a) => {
                    if matches!(a, Arrival::Backward(_)) {
                        *self.h_given.borrow_mut() += 1;
                    }
                    Ok(Ok(a))
                }
                None if is_try => Ok(Err(Idle::Timeout)),
                None => Ok(Err(Idle::Terminate)),
            }
        }
        fn send_v(&self, _: Forward, _: bool) -> Result<(), LinkError> {
            Ok(())
        }
        fn send_q(&self, _: Backward, _: bool) -> Result<(), LinkError> {
            Ok(())
        }
        fn stats(&self) -> EmulatorStats {
            EmulatorStats {
                c_in: InboxStats::default(),
                v_out: OutboxStats::default(),
                h_in: InboxStats::default(),
                q_out: OutboxStats::default(),
            }
        }
    }

    #[test]
    fn after_a_burst_it_sleeps_only_once_every_answer_is_back() {
        let scenario = Scenario::from_toml_str(
            "name = \"t\"\nmode = \"realtime\"\nrate_hz = 1000.0\nsamples = 10\n\n[operator]\nkind = \"paper\"\n",
        )
        .expect("scenario");
        let c = |seq| {
            Arrival::Forward(Forward {
                run: 5,
                seq,
                ..Forward::default()
            })
        };
        let h = |seq| {
            Arrival::Backward(Backward {
                run: 5,
                seq,
                ..Backward::default()
            })
        };
        let mut end = Forward {
            run: 5,
            seq: 3,
            ..Forward::default()
        };
        end.signal.flags = FLAG_END;
        // c(0) answered; then c(1) and c(2) queued after a stall, so v(1) and v(2) go
        // out back to back and two answers are due.
        let link = Script {
            arrivals: RefCell::new(VecDeque::from([
                c(0),
                h(0),
                c(1),
                c(2),
                h(1),
                h(2),
                Arrival::Forward(end),
            ])),
            ..Script::default()
        };
        let dir = tempfile::tempdir().expect("tmp");
        let mut rec = EmulatorRecorder::open(dir.path(), tactile_messages::Role::Emulator, false)
            .expect("rec");
        let done = run_with(
            &scenario,
            [None, None],
            &link,
            &mut rec,
            Duration::from_micros(200),
        )
        .expect("run");
        assert!(done);
        let calls = link.calls.borrow();
        // The receive right after h(1) (one answer still due) waits for it, with no
        // look-and-sleep; the one after h(2) is paced again (a look first).
        let after = |n: usize| calls.iter().find(|c| c.1 == n).map(|c| c.0);
        assert_eq!(after(2), Some(false), "{calls:?}");
        assert_eq!(after(3), Some(true), "{calls:?}");
    }
}
