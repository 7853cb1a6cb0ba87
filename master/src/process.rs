//! The master process's edge: paces the loop, moves samples through iceoryx2, stamps
//! times, and keeps one trace row per sample. All signal computation is in [`Master`].
//!
//! Realtime: sample n starts at t0 + n t_s (absolute sleep, so no drift), c(n) goes
//! out, and the master waits for q(n) until the next tick; a q(n) that has not come by
//! then is a deadline miss (if it comes later its round trip is still recorded).
//! Lockstep: c(n + 1) goes out as soon as q(n) is back.

use crate::hmd::{Master, MasterCounters};
use crate::operator::{OperatorError, OperatorSource};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use tactile_common::clock::{now_ns, sleep_until_ns};
use tactile_common::ipc::{Idle, InboxStats, IoxMaster, IpcError, OutboxStats, WaitPolicy};
use tactile_common::link::MasterLink;
use tactile_common::samples::{stage, Backward, Forward, FLAG_END, FLAG_PROBE};
use tactile_common::scenario::{Mode, Scenario, ScenarioError};
use tactile_common::trace::TraceRow;
use thiserror::Error;

/// What the master process needs to run.
#[derive(Debug, Clone)]
pub struct MasterOptions {
    /// The scenario.
    pub scenario: Scenario,
    /// Folder the scenario's relative paths are resolved against.
    pub base_dir: PathBuf,
    /// iceoryx2 prefix of this run.
    pub prefix: String,
    /// Waiting for q(n).
    pub wait: WaitPolicy,
    /// How long to wait for the other two processes to answer at start-up.
    pub startup_timeout: Duration,
    /// In lockstep, how long to wait for an answer before counting it missing.
    pub answer_timeout: Duration,
    /// Progress on stderr every this many samples (0: none).
    pub progress_every: u64,
    /// Realtime: wake this long before each tick and spin to it, ns.
    pub wake_early_ns: u64,
}

/// What went wrong in the master process.
#[derive(Debug, Error)]
pub enum MasterError {
    /// The scenario is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The trajectory file is unusable.
    #[error(transparent)]
    Operator(#[from] OperatorError),
    /// Shared memory failed.
    #[error(transparent)]
    Ipc(#[from] IpcError),
    /// The other processes did not answer.
    #[error("{0}")]
    NoAnswer(String),
}

/// Everything the master measured.
#[derive(Debug)]
pub struct MasterRun {
    /// One row per sample sent.
    pub rows: Vec<TraceRow>,
    /// Counters of the state machine.
    pub counters: MasterCounters,
    /// Samples whose q(n) was not back by the next tick (realtime only).
    pub deadline_misses: u64,
    /// Backward samples that arrived after their deadline.
    pub late: u64,
    /// Backward samples never received.
    pub missing: u64,
    /// Backward samples received out of the expected order or duplicated.
    pub unexpected: u64,
    /// Monotonic time of the first tick, ns.
    pub t0_ns: u64,
    /// True if SIGINT/SIGTERM stopped the run early.
    pub interrupted: bool,
    /// What happened to the loop, in order.
    pub events: Vec<Event>,
    /// c(n) as published.
    pub c_out: OutboxStats,
    /// q(n) as received.
    pub q_in: InboxStats,
    /// From the first tick to the end of the last sample, ns.
    pub elapsed_ns: u64,
}

/// Something that happened to the loop during a run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Event {
    /// Sample number when it happened.
    pub sample: u64,
    /// What happened.
    pub what: String,
}

fn index_of(n: u64) -> usize {
    usize::try_from(n).unwrap_or(usize::MAX)
}

fn probe(link: &impl MasterLink, timeout: Duration) -> Result<bool, MasterError> {
    let start = Instant::now();
    let mut k = 0u64;
    while start.elapsed() < timeout {
        let mut p = Forward {
            seq: k,
            ..Forward::default()
        };
        p.signal.flags = FLAG_PROBE;
        link.send_control(p)?;
        k += 1;
        let deadline = Instant::now() + Duration::from_millis(20);
        loop {
            match link.recv(deadline)? {
                Ok(b) if b.signal.flags & FLAG_PROBE != 0 => return Ok(true),
                Ok(_) => {}
                Err(Idle::Terminate) => return Ok(false),
                Err(Idle::Timeout) => break,
            }
        }
    }
    Err(MasterError::NoAnswer(format!(
        "no answer from the emulator and slave within {:.1} s: are both running with the same prefix?",
        timeout.as_secs_f64()
    )))
}

/// Runs the master process over iceoryx2 until the scenario's samples are sent (or a
/// stop request).
pub fn run(opts: &MasterOptions) -> Result<MasterRun, MasterError> {
    let link = IoxMaster::open(&opts.prefix, opts.wait)?;
    run_with(opts, &link)
}

/// Runs the master loop over any transport.
pub fn run_with(opts: &MasterOptions, link: &impl MasterLink) -> Result<MasterRun, MasterError> {
    let sc = &opts.scenario;
    let source = OperatorSource::load(&sc.operator, &opts.base_dir)?;
    let mut master = Master::new(sc, source)?;
    let mut result = MasterRun {
        rows: Vec::with_capacity(usize::try_from(sc.samples).unwrap_or(0)),
        counters: MasterCounters::default(),
        deadline_misses: 0,
        late: 0,
        missing: 0,
        unexpected: 0,
        t0_ns: 0,
        interrupted: false,
        events: Vec::new(),
        c_out: OutboxStats::default(),
        q_in: InboxStats::default(),
        elapsed_ns: 0,
    };
    if !probe(link, opts.startup_timeout)? {
        result.interrupted = true;
        return Ok(result);
    }
    // Drain probe echoes still in flight.
    let drain = Instant::now() + Duration::from_millis(5);
    while link.recv(drain)?.is_ok() {}

    let t_s = sc.t_s_ns();
    let realtime = sc.mode == Mode::Realtime;
    // First tick a little ahead so every process is settled.
    let t0 = now_ns() + 2_000_000;
    result.t0_ns = t0;
    for n in 0..sc.samples {
        // The sample's origin is its scheduled instant, not the moment the master woke:
        // a late wake-up is overhead the loop adds and must show in the round trip.
        let origin = if realtime {
            let tick = t0 + n * t_s;
            // Timer wake-ups here are late by ~100 us (timer slack plus the VM's wake
            // cost), so sleep until shortly before the tick and spin the rest; the
            // other two processes are idle at that moment, so the spin steals nothing.
            sleep_until_ns(tick.saturating_sub(opts.wake_early_ns));
            while now_ns() < tick {
                std::thread::yield_now();
            }
            tick
        } else {
            now_ns()
        };
        let (mut c, _) = master.forward(n, origin);
        c.stamps[stage::MASTER_SEND] = now_ns();
        link.send(c)?;
        result.rows.push(master.pending(&c));

        let deadline = if realtime {
            instant_at(t0 + (n + 1) * t_s)
        } else {
            Instant::now() + opts.answer_timeout
        };
        let mut done = false;
        while !done {
            let got = link.recv(deadline)?;
            match got {
                Ok(q) => match absorb(&mut master, &mut result.rows, q, &mut result.events) {
                    Some(seq) if seq == n => done = true,
                    Some(_) => result.late += 1,
                    None => result.unexpected += 1,
                },
                Err(Idle::Timeout) => {
                    let was_lost = master.peer_lost();
                    result.rows[index_of(n)] = master.missing(&c);
                    if realtime {
                        result.deadline_misses += 1;
                    }
                    if master.peer_lost() && !was_lost {
                        let dead = link.dead_peers();
                        result.events.push(Event {
                            sample: n,
                            what: if dead.is_empty() {
                                format!(
                                    "loop broken: no answer for {} samples; zero torque",
                                    sc.faults.peer_timeout_samples
                                )
                            } else {
                                format!(
                                    "loop broken: no answer for {} samples, dead: {}; zero torque",
                                    sc.faults.peer_timeout_samples,
                                    dead.join(", ")
                                )
                            },
                        });
                    }
                    break;
                }
                Err(Idle::Terminate) => {
                    result.interrupted = true;
                    break;
                }
            }
        }
        if result.interrupted {
            break;
        }
        if opts.progress_every > 0 && (n + 1) % opts.progress_every == 0 {
            eprint!("\r  master: {}/{} samples", n + 1, sc.samples);
        }
    }
    if opts.progress_every > 0 {
        eprintln!();
    }
    result.elapsed_ns = now_ns().saturating_sub(t0);
    // Collect stragglers, then tell the others to stop.
    let grace = Instant::now() + Duration::from_millis(50);
    while let Ok(Ok(q)) = link.recv(grace) {
        match absorb(&mut master, &mut result.rows, q, &mut result.events) {
            Some(_) => result.late += 1,
            None => result.unexpected += 1,
        }
    }
    let mut end = Forward::default();
    end.signal.flags = FLAG_END;
    link.send_control(end)?;
    result.missing = result.rows.iter().filter(|r| r.backward.is_none()).count() as u64;
    result.counters = master.counters();
    (result.c_out, result.q_in) = link.stats();
    Ok(result)
}

/// Stamps q's arrival, applies KFF-HMD and fills the row of the sample it answers.
/// Returns that sample's number, or None for a sample that answers nothing (a probe, a
/// duplicate, a number never sent).
fn absorb(
    master: &mut Master,
    rows: &mut [TraceRow],
    mut q: Backward,
    events: &mut Vec<Event>,
) -> Option<u64> {
    q.stamps[stage::MASTER_RECV] = now_ns();
    let index = usize::try_from(q.seq).ok().filter(|&i| {
        i < rows.len() && rows[i].backward.is_none() && q.signal.flags & FLAG_PROBE == 0
    })?;
    if master.peer_lost() {
        events.push(Event {
            sample: q.seq,
            what: "loop resumed: answers are back".into(),
        });
    }
    let sent = rows[index].forward;
    let mut row = master.backward(&sent, &q);
    if let Some(b) = row.backward.as_mut() {
        b.stamps[stage::MASTER_DONE] = now_ns();
    }
    master.account(&mut row);
    rows[index] = row;
    Some(q.seq)
}

/// The `Instant` corresponding to a CLOCK_MONOTONIC time (both are monotonic clocks).
fn instant_at(t_ns: u64) -> Instant {
    let now_i = Instant::now();
    let now = now_ns();
    if t_ns >= now {
        now_i + Duration::from_nanos(t_ns - now)
    } else {
        now_i
            .checked_sub(Duration::from_nanos(now - t_ns))
            .unwrap_or(now_i)
    }
}
