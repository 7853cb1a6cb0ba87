//! The Zenoh transport, across hosts: the engine ROS 2's rmw_zenoh, dora-rs and
//! copper-rs use to leave the host. iceoryx2 stays for the hops inside one host.
//!
//! Each node opens one Zenoh session in peer mode, listening and connecting on the
//! endpoints it is given (multicast and gossip scouting off unless asked for, so a
//! node talks to exactly the peers named: peers do not route for each other, so each
//! node connects to the nodes it exchanges samples with). Every stream is a key,
//! `tactile/<prefix>/<c|v|h|q>`; every payload is one frame of the wire format
//! ([`crate::wire`]). Set for latency by measurement (docs/03-across-hosts.md): the
//! low-latency unicast transport, and publishers with `express` (no batching: a 1 kHz
//! sample must not wait for company; batching put 15 ms in the p99.9), priority
//! `RealTime` (it matters only where QoS is on) and congestion control `Block` (`Drop`
//! measured no faster, and a sample must not vanish unseen). Received payloads go from
//! Zenoh's threads into one bounded queue per node, which the node's loop polls and
//! then blocks on, like the other transports, sorted into its streams by kind.

use crate::ends::{LinkError, Publish, Subscribe, Wake};
use crate::streams::{key, Kind, Stream};
use crate::wire::{self, Demux, OnWire};
use crate::zenoh_config::tuning;
pub use crate::zenoh_config::{default_runtime, TlsFiles, ZenohOptions, RUNTIME};
use std::cell::RefCell;
use std::marker::PhantomData;
use std::rc::Rc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, TrySendError};
use std::sync::Arc;
use std::time::Instant;
use tactile_messages::stream::{InboxStats, OutboxStats};
/// The Zenoh crate this transport is built on, for tools and tests that talk to the
/// nodes.
pub use zenoh;
use zenoh::qos::{CongestionControl, Priority};
use zenoh::Wait as _;

/// Frames a node's receive queue holds before it drops (and counts) new ones.
pub const QUEUE: usize = 1024;

/// Opens a Zenoh session with the options.
pub fn open_session(opts: &ZenohOptions) -> Result<zenoh::Session, LinkError> {
    tracing::info!(
        "Zenoh runtimes: {}",
        std::env::var("ZENOH_RUNTIME").unwrap_or_else(|_| "Zenoh's defaults".into())
    );
    zenoh::open(opts.config()?)
        .wait()
        .map_err(|e| LinkError::new("opening the Zenoh session", e))
}

/// One node's Zenoh session, shared by its Zenoh ends: its subscriptions feed one
/// queue, sorted into the node's streams on the loop's thread.
pub struct ZenohEnd {
    session: zenoh::Session,
    _subscribers: Vec<zenoh::pubsub::Subscriber<()>>,
    rx: Receiver<Vec<u8>>,
    /// A payload taken by a blocking wait, for the next take.
    held: RefCell<Option<Vec<u8>>>,
    /// Payloads dropped because the queue was full, by the kind of their stream.
    overflow: [Arc<AtomicU64>; 2],
    demux: RefCell<Demux>,
    buf: RefCell<Vec<u8>>,
    prefix: String,
}

impl std::fmt::Debug for ZenohEnd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ZenohEnd")
            .field("session", &self.session.zid())
            .finish_non_exhaustive()
    }
}

impl ZenohEnd {
    /// Opens the session and subscribes to `subscribe` in run `prefix`.
    pub fn open(
        opts: &ZenohOptions,
        prefix: &str,
        subscribe: &[Stream],
    ) -> Result<Rc<ZenohEnd>, LinkError> {
        let session = open_session(opts)?;
        let (tx, rx) = sync_channel::<Vec<u8>>(QUEUE);
        let overflow = [Arc::new(AtomicU64::new(0)), Arc::new(AtomicU64::new(0))];
        let mut subscribers = Vec::new();
        for &s in subscribe {
            let tx = tx.clone();
            let lost = Arc::clone(&overflow[s.kind() as usize]);
            let sub = session
                .declare_subscriber(key(prefix, s))
                .callback(move |sample| {
                    let bytes = sample.payload().to_bytes().into_owned();
                    if let Err(TrySendError::Full(_)) = tx.try_send(bytes) {
                        lost.fetch_add(1, Ordering::Relaxed);
                    }
                })
                .wait()
                .map_err(|e| {
                    LinkError::new(&format!("declaring the subscriber of {}", s.name()), e)
                })?;
            subscribers.push(sub);
        }
        let kinds: Vec<Kind> = subscribe.iter().map(|s| s.kind()).collect();
        Ok(Rc::new(ZenohEnd {
            session,
            _subscribers: subscribers,
            rx,
            held: RefCell::new(None),
            overflow,
            demux: RefCell::new(Demux::new(&kinds)),
            buf: RefCell::new(Vec::with_capacity(wire::MAX_FRAME)),
            prefix: prefix.to_string(),
        }))
    }

    fn take<T: OnWire>(&self) -> Option<T> {
        let mut buf = self.buf.borrow_mut();
        self.demux.borrow_mut().take(&mut buf, |b| {
            let got = self
                .held
                .borrow_mut()
                .take()
                .or_else(|| self.rx.try_recv().ok());
            match got {
                Some(bytes) => {
                    *b = bytes;
                    true
                }
                None => false,
            }
        })
    }
}

impl Wake for Rc<ZenohEnd> {
    /// Waits for a payload from Zenoh's threads (kept for the next take), up to
    /// `until`.
    fn block(&self, until: Instant) -> Result<(), LinkError> {
        if self.held.borrow().is_some() {
            return Ok(());
        }
        let left = until.saturating_duration_since(Instant::now());
        match self.rx.recv_timeout(left) {
            Ok(b) => *self.held.borrow_mut() = Some(b),
            Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => {}
        }
        Ok(())
    }
}

/// Sending end of a stream over Zenoh.
pub struct ZenohPublisher<T> {
    publisher: zenoh::pubsub::Publisher<'static>,
    stream: Stream,
    stats: OutboxStats,
    buf: Vec<u8>,
    _end: Rc<ZenohEnd>,
    _t: PhantomData<fn(T)>,
}

impl<T> std::fmt::Debug for ZenohPublisher<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ZenohPublisher")
            .field("stream", &self.stream)
            .finish_non_exhaustive()
    }
}

impl<T> ZenohPublisher<T> {
    /// Declares the publisher of `stream` on `end`'s session.
    pub fn new(end: &Rc<ZenohEnd>, stream: Stream) -> Result<Self, LinkError> {
        let t = tuning();
        let publisher = end
            .session
            .declare_publisher(key(&end.prefix, stream))
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
            .map_err(|e| {
                LinkError::new(&format!("declaring the publisher of {}", stream.name()), e)
            })?;
        Ok(ZenohPublisher {
            publisher,
            stream,
            stats: OutboxStats::default(),
            buf: Vec::with_capacity(wire::MAX_FRAME),
            _end: Rc::clone(end),
            _t: PhantomData,
        })
    }
}

impl<T: OnWire> Publish<T> for ZenohPublisher<T> {
    fn publish(&mut self, value: &T, control: bool) -> Result<(), LinkError> {
        let (publisher, name) = (&self.publisher, self.stream.name());
        wire::send_counted(value, control, &mut self.stats, &mut self.buf, |frame| {
            publisher
                .put(frame)
                .wait()
                .map(|()| 1)
                .map_err(|e| LinkError::new(&format!("publishing on {name}"), e))
        })
    }

    fn stats(&self) -> OutboxStats {
        self.stats
    }
}

/// Receiving end of a stream over Zenoh.
#[derive(Debug)]
pub struct ZenohSubscriber<T> {
    end: Rc<ZenohEnd>,
    _t: PhantomData<fn() -> T>,
}

impl<T> ZenohSubscriber<T> {
    /// Takes `T`'s stream from `end` (which subscribed to it when it opened).
    pub fn new(end: &Rc<ZenohEnd>) -> Self {
        ZenohSubscriber {
            end: Rc::clone(end),
            _t: PhantomData,
        }
    }
}

impl<T: OnWire> Subscribe<T> for ZenohSubscriber<T> {
    fn try_recv(&mut self) -> Result<Option<T>, LinkError> {
        Ok(self.end.take())
    }

    fn stats(&self) -> InboxStats {
        let mut s = self.end.demux.borrow().stats(T::KIND);
        s.overwritten += self.end.overflow[T::KIND as usize].load(Ordering::Relaxed);
        s
    }
}
