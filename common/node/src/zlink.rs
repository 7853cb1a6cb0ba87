//! The loop across hosts, over Zenoh: the engine ROS 2's rmw_zenoh, dora-rs and
//! copper-rs use to leave the host. iceoryx2 stays for the hops inside one host.
//!
//! Each node opens one Zenoh session in peer mode, listening and connecting on the
//! endpoints it is given (multicast and gossip scouting off unless asked for, so a
//! node talks to exactly the peers named: peers do not route for each other, so each
//! node connects to the nodes it exchanges samples with). Every stream is a key, `tactile/<prefix>/<c|v|h|q>`;
//! every payload is one frame of the wire format ([`crate::wire`]). Set for latency by
//! measurement (docs/03-across-hosts.md): the low-latency unicast transport, and
//! publishers with `express` (no batching: a 1 kHz sample must not wait for company;
//! batching put 15 ms in the p99.9), priority `RealTime` (it matters only where QoS is
//! on) and congestion control `Block` (`Drop` measured no faster, and a sample must
//! not vanish unseen). Received payloads go from Zenoh's threads into one bounded queue
//! per node, which the node's loop polls and then blocks on, like the other links.

use crate::link::{Arrival, EmulatorLink, EmulatorStats, MasterLink, SlaveLink, Wait};
use crate::link::{Idle, InboxStats, LinkError, OutboxStats, WaitPolicy};
use crate::wire::{self, backward, count, forward, Frame, In};
use crate::zconfig::tuning;
pub use crate::zconfig::{default_runtime, TlsFiles, ZenohOptions, RUNTIME};
use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, TrySendError};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactile_messages::samples::{Backward, Forward, Sequenced};
/// The Zenoh crate this link is built on, for tools and tests that talk to the nodes.
pub use zenoh;
use zenoh::qos::{CongestionControl, Priority};
use zenoh::Wait as _;

/// Frames a node's receive queue holds before it drops (and counts) new ones.
pub const QUEUE: usize = 1024;

fn err(context: &str, e: impl std::fmt::Display) -> LinkError {
    LinkError {
        context: context.to_string(),
        detail: e.to_string(),
    }
}

/// The streams, by key suffix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// c(n): master to emulator.
    C,
    /// v(n): emulator (or a master without emulator) to slave.
    V,
    /// h(n): slave to emulator (or to a master without emulator).
    H,
    /// q(n): emulator to master.
    Q,
}

impl Stream {
    fn name(self) -> &'static str {
        match self {
            Stream::C => "c",
            Stream::V => "v",
            Stream::H => "h",
            Stream::Q => "q",
        }
    }
}

/// The key of `stream` in run `prefix`.
pub fn key(prefix: &str, stream: Stream) -> String {
    format!("tactile/{prefix}/{}", stream.name())
}

/// Opens a Zenoh session with the options.
pub fn open_session(opts: &ZenohOptions) -> Result<zenoh::Session, LinkError> {
    tracing::info!(
        "Zenoh runtimes: {}",
        std::env::var("ZENOH_RUNTIME").unwrap_or_else(|_| "Zenoh's defaults".into())
    );
    zenoh::open(opts.config()?)
        .wait()
        .map_err(|e| err("opening the Zenoh session", e))
}

/// One node's Zenoh session: its publishers, and one queue for everything it
/// subscribes to.
pub struct ZenohEnd {
    session: zenoh::Session,
    publishers: Vec<(Stream, zenoh::pubsub::Publisher<'static>)>,
    _subscribers: Vec<zenoh::pubsub::Subscriber<()>>,
    rx: Receiver<Vec<u8>>,
    overflow: Arc<AtomicU64>,
    stop: Arc<AtomicBool>,
    buf: RefCell<Vec<u8>>,
    spin: Duration,
}

impl std::fmt::Debug for ZenohEnd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ZenohEnd")
            .field("session", &self.session.zid())
            .finish_non_exhaustive()
    }
}

impl ZenohEnd {
    /// Opens the session, publishes `publish` and subscribes to `subscribe` in run
    /// `prefix`.
    pub fn open(
        opts: &ZenohOptions,
        prefix: &str,
        publish: &[Stream],
        subscribe: &[Stream],
        wait: WaitPolicy,
    ) -> Result<ZenohEnd, LinkError> {
        let session = open_session(opts)?;
        let mut publishers = Vec::new();
        for &s in publish {
            let t = tuning();
            let p = session
                .declare_publisher(key(prefix, s))
                .express(!t.contains(&"batched"))
                .priority(if t.contains(&"data") {
                    Priority::Data
                } else {
                    Priority::RealTime
                })
                .congestion_control(if t.contains(&"drop") {
                    CongestionControl::Drop
                } else {
                    CongestionControl::Block
                })
                .wait()
                .map_err(|e| err(&format!("declaring the publisher of {}", s.name()), e))?;
            publishers.push((s, p));
        }
        let (tx, rx) = sync_channel::<Vec<u8>>(QUEUE);
        let overflow = Arc::new(AtomicU64::new(0));
        let mut subscribers = Vec::new();
        for &s in subscribe {
            let tx = tx.clone();
            let overflow = Arc::clone(&overflow);
            let sub = session
                .declare_subscriber(key(prefix, s))
                .callback(move |sample| {
                    let bytes = sample.payload().to_bytes().into_owned();
                    if let Err(TrySendError::Full(_)) = tx.try_send(bytes) {
                        overflow.fetch_add(1, Ordering::Relaxed);
                    }
                })
                .wait()
                .map_err(|e| err(&format!("declaring the subscriber of {}", s.name()), e))?;
            subscribers.push(sub);
        }
        let stop = crate::signals::stop_flag().map_err(|e| err("installing signal handlers", e))?;
        Ok(ZenohEnd {
            session,
            publishers,
            _subscribers: subscribers,
            rx,
            overflow,
            stop,
            buf: RefCell::new(Vec::with_capacity(wire::MAX_FRAME)),
            spin: wait.spin,
        })
    }

    /// Publishes a frame on `stream`.
    pub fn put<T: Sequenced + Copy>(
        &self,
        stream: Stream,
        value: T,
        control: bool,
        stats: &Cell<OutboxStats>,
        encode: fn(&T, &mut Vec<u8>) -> Result<(), String>,
    ) -> Result<(), LinkError> {
        let publisher = self
            .publishers
            .iter()
            .find(|(s, _)| *s == stream)
            .map(|(_, p)| p)
            .ok_or_else(|| err("publishing", format!("no publisher for {}", stream.name())))?;
        let mut buf = self.buf.borrow_mut();
        wire::send_counted(value, control, stats, &mut buf, encode, |frame| {
            publisher
                .put(frame)
                .wait()
                .map(|()| 1)
                .map_err(|e| err(&format!("publishing on {}", stream.name()), e))
        })
    }

    /// A received frame if one waits (decoded: a rejected one is `Err`).
    pub fn try_take(&self) -> Option<Result<Frame, wire::Reject>> {
        self.rx.try_recv().ok().map(|b| wire::decode(&b))
    }

    /// True once SIGINT or SIGTERM arrived.
    pub fn stopping(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Blocks until a frame arrives (returned) or `until`; wakes every 50 ms to see a
    /// stop request.
    pub fn block(&self, until: Instant) -> Option<Result<Frame, wire::Reject>> {
        let now = Instant::now();
        if now >= until {
            return None;
        }
        let step = (until - now).min(Duration::from_millis(50));
        match self.rx.recv_timeout(step) {
            Ok(b) => Some(wire::decode(&b)),
            Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => None,
        }
    }

    /// Frames dropped because the receive queue was full.
    pub fn overflow(&self) -> u64 {
        self.overflow.load(Ordering::Relaxed)
    }

    /// Waits for a frame that `take` accepts: polls (yielding) for the spin budget,
    /// then blocks on the queue, until `deadline` or a stop request. Polling measured
    /// faster here than blocking at once (all-Zenoh loop across two namespaces, 1 kHz:
    /// p50 137 us against 336 us): it spares the futex wake-up of the hand-over from
    /// Zenoh's thread.
    fn wait<R>(
        &self,
        deadline: Instant,
        mut take: impl FnMut(Result<Frame, wire::Reject>) -> Option<R>,
    ) -> Wait<R> {
        let start = Instant::now();
        loop {
            if let Some(f) = self.try_take() {
                if let Some(r) = take(f) {
                    return Ok(Ok(r));
                }
                continue;
            }
            if self.stopping() {
                return Ok(Err(Idle::Terminate));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(Err(Idle::Timeout));
            }
            if now.duration_since(start) < self.spin {
                std::thread::yield_now();
                continue;
            }
            if let Some(f) = self.block(deadline) {
                if let Some(r) = take(f) {
                    return Ok(Ok(r));
                }
            }
        }
    }
}

/// The master's end over Zenoh. Without an emulator (`direct`) it publishes v(n) and
/// takes h(n) straight from the slave: the real network is then the only delay.
#[derive(Debug)]
pub struct ZenohMaster {
    end: ZenohEnd,
    out: Stream,
    out_stats: Cell<OutboxStats>,
    inn: In,
}

impl ZenohMaster {
    /// Opens the master's streams of run `prefix`.
    pub fn open(
        opts: &ZenohOptions,
        prefix: &str,
        direct: bool,
        wait: WaitPolicy,
    ) -> Result<Self, LinkError> {
        let (out, inn) = if direct {
            (Stream::V, Stream::H)
        } else {
            (Stream::C, Stream::Q)
        };
        Ok(ZenohMaster {
            end: ZenohEnd::open(opts, prefix, &[out], &[inn], wait)?,
            out,
            out_stats: Cell::default(),
            inn: In::default(),
        })
    }
}

impl MasterLink for ZenohMaster {
    fn send(&self, c: Forward) -> Result<(), LinkError> {
        self.end
            .put(self.out, c, false, &self.out_stats, wire::encode_forward)
    }
    fn send_control(&self, c: Forward) -> Result<(), LinkError> {
        self.end
            .put(self.out, c, true, &self.out_stats, wire::encode_forward)
    }
    fn recv(&self, deadline: Instant) -> Wait<Backward> {
        self.end.wait(deadline, |f| {
            count(f, backward, &self.inn.stats, &self.inn.next)
        })
    }
    fn dead_peers(&self) -> Vec<String> {
        Vec::new()
    }
    fn stats(&self) -> (OutboxStats, InboxStats) {
        let mut i = self.inn.stats.get();
        i.overwritten += self.end.overflow();
        (self.out_stats.get(), i)
    }
}

/// The slave's end over Zenoh.
#[derive(Debug)]
pub struct ZenohSlave {
    end: ZenohEnd,
    out_stats: Cell<OutboxStats>,
    inn: In,
}

impl ZenohSlave {
    /// Opens the slave's streams of run `prefix`.
    pub fn open(opts: &ZenohOptions, prefix: &str, wait: WaitPolicy) -> Result<Self, LinkError> {
        Ok(ZenohSlave {
            end: ZenohEnd::open(opts, prefix, &[Stream::H], &[Stream::V], wait)?,
            out_stats: Cell::default(),
            inn: In::default(),
        })
    }
}

impl SlaveLink for ZenohSlave {
    fn recv(&self, deadline: Instant) -> Wait<Forward> {
        self.end.wait(deadline, |f| {
            count(f, forward, &self.inn.stats, &self.inn.next)
        })
    }
    fn send_h(&self, h: Backward, control: bool) -> Result<(), LinkError> {
        self.end.put(
            Stream::H,
            h,
            control,
            &self.out_stats,
            wire::encode_backward,
        )
    }
    fn stats(&self) -> (InboxStats, OutboxStats) {
        let mut i = self.inn.stats.get();
        i.overwritten += self.end.overflow();
        (i, self.out_stats.get())
    }
}

/// How the emulator reaches each of its two neighbours.
#[derive(Debug)]
enum Side {
    /// Over this node's Zenoh session.
    Zenoh,
    /// Over iceoryx2 on this host.
    Iox(Box<crate::ipc::IoxHalf>),
}

/// The emulator's ends with Zenoh on one side or both: towards the master (c in, q
/// out) and towards the slave (v out, h in), so the emulator can sit on either host.
#[derive(Debug)]
pub struct ZenohEmulator {
    end: ZenohEnd,
    master: Side,
    slave: Side,
    c_in: In,
    h_in: In,
    v_out: Cell<OutboxStats>,
    q_out: Cell<OutboxStats>,
}

impl ZenohEmulator {
    /// Opens the emulator's streams; `iox_master` / `iox_slave` put that side on
    /// iceoryx2 (the neighbour is on this host), the rest goes over Zenoh.
    pub fn open(
        opts: &ZenohOptions,
        prefix: &str,
        iox_master: bool,
        iox_slave: bool,
        wait: WaitPolicy,
    ) -> Result<Self, LinkError> {
        let mut publish = Vec::new();
        let mut subscribe = Vec::new();
        if !iox_master {
            publish.push(Stream::Q);
            subscribe.push(Stream::C);
        }
        if !iox_slave {
            publish.push(Stream::V);
            subscribe.push(Stream::H);
        }
        let end = ZenohEnd::open(opts, prefix, &publish, &subscribe, wait)?;
        let side = |iox: bool, master_side: bool| -> Result<Side, LinkError> {
            Ok(if iox {
                Side::Iox(Box::new(crate::ipc::IoxHalf::open(prefix, master_side)?))
            } else {
                Side::Zenoh
            })
        };
        Ok(ZenohEmulator {
            master: side(iox_master, true)?,
            slave: side(iox_slave, false)?,
            end,
            c_in: In::default(),
            h_in: In::default(),
            v_out: Cell::default(),
            q_out: Cell::default(),
        })
    }

    fn take(&self, f: Result<Frame, wire::Reject>) -> Option<Arrival> {
        match f {
            Ok(Frame::Backward(_)) => {
                count(f, backward, &self.h_in.stats, &self.h_in.next).map(Arrival::Backward)
            }
            _ => count(f, forward, &self.c_in.stats, &self.c_in.next).map(Arrival::Forward),
        }
    }

    fn poll_iox(&self) -> Result<Option<Arrival>, LinkError> {
        // Backward first: it completes a round trip the master is waiting for.
        if let Side::Iox(s) = &self.slave {
            if let Some(a) = s.try_recv()? {
                return Ok(Some(a));
            }
        }
        if let Side::Iox(s) = &self.master {
            return s.try_recv();
        }
        Ok(None)
    }

    fn any_iox(&self) -> Option<&crate::ipc::IoxHalf> {
        match (&self.master, &self.slave) {
            (Side::Iox(s), _) | (_, Side::Iox(s)) => Some(s),
            _ => None,
        }
    }
}

/// How often a emulator that waits on both Zenoh and iceoryx2 looks at iceoryx2 while
/// it blocks on Zenoh (only when the loop has been idle for the spin budget).
pub const MIXED_POLL: Duration = Duration::from_micros(200);

impl EmulatorLink for ZenohEmulator {
    fn recv(&self, deadline: Instant) -> Wait<Arrival> {
        let start = Instant::now();
        loop {
            if let Some(a) = self.poll_iox()? {
                return Ok(Ok(a));
            }
            if let Some(f) = self.end.try_take() {
                if let Some(a) = self.take(f) {
                    return Ok(Ok(a));
                }
                continue;
            }
            let iox_stop = self.any_iox().is_some_and(|s| s.stopping());
            if self.end.stopping() || iox_stop {
                return Ok(Err(Idle::Terminate));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(Err(Idle::Timeout));
            }
            if now.duration_since(start) < self.end.spin {
                std::thread::yield_now();
                continue;
            }
            let until = if self.any_iox().is_some() {
                deadline.min(now + MIXED_POLL)
            } else {
                deadline
            };
            if let Some(f) = self.end.block(until) {
                if let Some(a) = self.take(f) {
                    return Ok(Ok(a));
                }
            }
        }
    }
    fn send_v(&self, v: Forward, control: bool) -> Result<(), LinkError> {
        match &self.slave {
            Side::Iox(s) => s.send_forward(v, control),
            Side::Zenoh => self
                .end
                .put(Stream::V, v, control, &self.v_out, wire::encode_forward),
        }
    }
    fn send_q(&self, q: Backward, control: bool) -> Result<(), LinkError> {
        match &self.master {
            Side::Iox(s) => s.send_backward(q, control),
            Side::Zenoh => self
                .end
                .put(Stream::Q, q, control, &self.q_out, wire::encode_backward),
        }
    }
    fn stats(&self) -> EmulatorStats {
        let mut st = EmulatorStats {
            c_in: self.c_in.stats.get(),
            v_out: self.v_out.get(),
            h_in: self.h_in.stats.get(),
            q_out: self.q_out.get(),
        };
        st.c_in.overwritten += self.end.overflow();
        if let Side::Iox(s) = &self.master {
            (st.c_in, st.q_out) = s.stats();
        }
        if let Side::Iox(s) = &self.slave {
            (st.h_in, st.v_out) = s.stats();
        }
        st
    }
}
