//! The iceoryx2 transport: shared-memory wiring all three processes agree on (service
//! names, buffer sizes, overflow policy). Each stream is a publish-subscribe service;
//! each process has one wake-up event, which every publisher into it notifies, so a
//! receiver spins for a short budget and then blocks on one event whichever stream its
//! sample comes on. Every run (and every test) has its own `prefix`, naming its
//! shared-memory objects and its folder of node and service files, so runs never see
//! each other.
//!
//! A stop request is the node's to see, not iceoryx2's: its nodes do not handle
//! signals. But iceoryx2 takes SIGINT and SIGTERM over for itself the first time it
//! maps shared memory (it watches for a signal while it zeroes the memory), replacing
//! the node's own handler; [`termination_requested`] reads what it caught, and the
//! runtime's stop flag asks it, so a stop request is seen the same way either way.

use crate::ends::{LinkError, Publish, Subscribe, Wake};
use crate::streams::Stream;
use iceoryx2::config::Config;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{
    ipc, FileName, Node, NodeBuilder, NodeName, SemanticString, ServiceName, SignalHandlingMode,
    ZeroCopySend,
};
use std::fmt::Debug;
use std::rc::Rc;
use std::time::Instant;
use tactile_messages::samples::Sequenced;
use tactile_messages::stream::{InboxStats, OutboxStats};

/// A process's iceoryx2 node.
pub type IpcNode = Node<ipc::Service>;

/// Samples a subscriber buffers before the oldest is overwritten (safe overflow). A
/// lost sample shows as a gap in the sequence numbers and is counted.
pub const SUBSCRIBER_BUFFER: usize = 64;

/// The shortest wait handed to iceoryx2: its socket timeout counts whole microseconds
/// and reads zero as "for ever".
const MIN_WAIT: std::time::Duration = std::time::Duration::from_micros(1);

/// Root folder of the node and service files of all runs.
pub const ROOT: &str = "/tmp/tactile-iox2";

/// Maps any iceoryx2 error to [`LinkError`].
fn map<T, E: Debug>(r: Result<T, E>, context: impl Into<String>) -> Result<T, LinkError> {
    r.map_err(|e| LinkError {
        context: context.into(),
        detail: format!("{e:?}"),
    })
}

/// The iceoryx2 configuration of one run: its own prefix and root folder.
pub fn config(prefix: &str) -> Result<Config, LinkError> {
    let mut cfg = Config::default();
    let root = format!("{ROOT}/{prefix}/");
    cfg.global.set_root_path(&map(
        iceoryx2::prelude::Path::new(root.as_bytes()),
        format!("root path {root}"),
    )?);
    cfg.global.prefix = map(
        FileName::new(format!("{prefix}.").as_bytes()),
        format!("prefix {prefix:?}"),
    )?;
    // How long opening a service waits for another process to finish creating it.
    // iceoryx2's 1 s was too short on a loaded 2-core machine: a slave restarted after
    // SIGKILL, while CI's tests ran beside it, failed with HangsInCreation opening its
    // own wake-up event (faults::slave_killed_..., once in a fresh-clone CI run).
    cfg.global.creation_timeout = std::time::Duration::from_secs(5);
    Ok(cfg)
}

/// Set once this process made an iceoryx2 node: from then on iceoryx2's signal handler
/// may be the one that catches SIGINT and SIGTERM.
static IN_USE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// True if SIGINT or SIGTERM came while iceoryx2's handler held them, since the last
/// call (the request is taken: latch it). False in a process that never made an
/// iceoryx2 node, without touching iceoryx2's handler.
pub fn termination_requested() -> bool {
    IN_USE.load(std::sync::atomic::Ordering::Relaxed)
        && iceoryx2_bb_posix::signal::SignalHandler::termination_requested()
}

/// Creates this process's node `name`; dead nodes of an earlier crashed run with the
/// same prefix are cleaned up on creation.
pub fn node(prefix: &str, name: &str) -> Result<IpcNode, LinkError> {
    IN_USE.store(true, std::sync::atomic::Ordering::Relaxed);
    let cfg = config(prefix)?;
    let node_name = map(NodeName::new(name), format!("node name {name:?}"))?;
    map(
        NodeBuilder::new()
            .name(&node_name)
            .config(&cfg)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>(),
        format!("creating node {name}"),
    )
}

fn service_name(name: &str) -> Result<ServiceName, LinkError> {
    let name = format!("tactile/{name}");
    map(ServiceName::new(&name), format!("service name {name}"))
}

fn open_pubsub<T: Debug + ZeroCopySend + 'static>(
    node: &IpcNode,
    stream: &str,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>,
    LinkError,
> {
    map(
        node.service_builder(&service_name(stream)?)
            .publish_subscribe::<T>()
            .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
            .history_size(0)
            .max_publishers(2)
            .max_subscribers(4)
            .max_nodes(8)
            .enable_safe_overflow(true)
            .open_or_create(),
        format!("opening stream {stream}"),
    )
}

fn open_event(
    node: &IpcNode,
    name: &str,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>, LinkError> {
    map(
        node.service_builder(&service_name(&format!("wake/{name}"))?)
            .event()
            .max_notifiers(8)
            .max_listeners(4)
            .max_nodes(8)
            .open_or_create(),
        format!("opening the wake-up event of {name}"),
    )
}

/// Sending end of a stream: a publisher, and a notifier that wakes the receiving
/// process.
#[derive(Debug)]
pub struct IpcPublisher<T: Debug + ZeroCopySend + 'static> {
    publisher: Publisher<ipc::Service, T, ()>,
    notifier: Notifier<ipc::Service>,
    stream: String,
    stats: OutboxStats,
    _node: Rc<IpcNode>,
}

impl<T: Debug + ZeroCopySend + Copy + Sequenced + 'static> IpcPublisher<T> {
    /// Opens (or creates) service `stream` for sending; each send wakes the process
    /// whose wake-up event is `wake` (a node's is its role's name).
    pub fn open(node: &Rc<IpcNode>, stream: &str, wake: &str) -> Result<Self, LinkError> {
        let svc = open_pubsub::<T>(node, stream)?;
        let ev = open_event(node, wake)?;
        Ok(IpcPublisher {
            publisher: map(
                svc.publisher_builder().max_loaned_samples(2).create(),
                format!("publisher on {stream}"),
            )?,
            notifier: map(
                ev.notifier_builder().create(),
                format!("notifier for {wake}"),
            )?,
            stream: stream.to_string(),
            stats: OutboxStats::default(),
            _node: Rc::clone(node),
        })
    }

    /// Opens the publisher of a loop stream.
    pub fn of(node: &Rc<IpcNode>, stream: Stream) -> Result<Self, LinkError> {
        IpcPublisher::open(node, stream.service(), stream.receiver().name())
    }
}

impl<T: Debug + ZeroCopySend + Copy + Sequenced + 'static> Publish<T> for IpcPublisher<T> {
    fn publish(&mut self, value: &T, control: bool) -> Result<(), LinkError> {
        let mut value = *value;
        self.stats.stamp(&mut value, control);
        let n = map(
            self.publisher.send_copy(value),
            format!("sending on {}", self.stream),
        )?;
        self.stats.count(n, control);
        map(self.notifier.notify(), format!("notifying {}", self.stream))?;
        Ok(())
    }

    fn stats(&self) -> OutboxStats {
        self.stats
    }
}

/// Receiving end of a stream.
#[derive(Debug)]
pub struct IpcSubscriber<T: Debug + ZeroCopySend + 'static> {
    subscriber: Subscriber<ipc::Service, T, ()>,
    stream: String,
    stats: InboxStats,
    next_hop_seq: Option<u64>,
    _node: Rc<IpcNode>,
}

impl<T: Debug + ZeroCopySend + Copy + Sequenced + 'static> IpcSubscriber<T> {
    /// Opens (or creates) service `stream` for receiving.
    pub fn open(node: &Rc<IpcNode>, stream: &str) -> Result<Self, LinkError> {
        let svc = open_pubsub::<T>(node, stream)?;
        Ok(IpcSubscriber {
            subscriber: map(
                svc.subscriber_builder()
                    .buffer_size(SUBSCRIBER_BUFFER)
                    .create(),
                format!("subscriber on {stream}"),
            )?,
            stream: stream.to_string(),
            stats: InboxStats::default(),
            next_hop_seq: None,
            _node: Rc::clone(node),
        })
    }
}

impl<T: Debug + ZeroCopySend + Copy + Sequenced + 'static> Subscribe<T> for IpcSubscriber<T> {
    fn try_recv(&mut self) -> Result<Option<T>, LinkError> {
        let got = map(
            self.subscriber.receive(),
            format!("receiving on {}", self.stream),
        )?
        .map(|s| *s);
        if let Some(v) = &got {
            self.stats.count(v, &mut self.next_hop_seq);
        }
        Ok(got)
    }

    fn stats(&self) -> InboxStats {
        self.stats
    }
}

/// A process's wake-up event: every stream into the process notifies it.
#[derive(Debug)]
pub struct IpcWake {
    listener: Listener<ipc::Service>,
    name: String,
    _node: Rc<IpcNode>,
}

impl IpcWake {
    /// Opens the wake-up event `name` (a node's is its role's name).
    pub fn open(node: &Rc<IpcNode>, name: &str) -> Result<Self, LinkError> {
        let ev = open_event(node, name)?;
        Ok(IpcWake {
            listener: map(
                ev.listener_builder().create(),
                format!("listener for {name}"),
            )?,
            name: name.to_string(),
            _node: Rc::clone(node),
        })
    }
}

impl Wake for IpcWake {
    fn block(&self, until: Instant) -> Result<(), LinkError> {
        let left = until.saturating_duration_since(Instant::now());
        // iceoryx2 0.10 waits with SO_RCVTIMEO set from the timeout cut to whole
        // microseconds, and a zero timeval there means "no timeout": a wait with less
        // than 1 us left blocked until the next notification, which never comes when
        // the peer is gone (a master hung for ever after its slave was killed). So
        // under 1 us there is no wait: the caller polls again and sees its deadline.
        if left < MIN_WAIT {
            return Ok(());
        }
        match self.listener.timed_wait(|_| {}, left) {
            Ok(_) | Err(ListenerWaitError::InterruptSignal) => Ok(()),
            Err(e) => map(
                Err(e),
                format!("waiting on the wake-up event of {}", self.name),
            ),
        }
    }
}

/// Names of the nodes of run `prefix` whose process died; their stale resources are
/// removed on the way, so a restarted process can take their place.
pub fn dead_nodes(prefix: &str) -> Result<Vec<String>, LinkError> {
    use iceoryx2::node::{NodeState, NodeView};
    let cfg = config(prefix)?;
    let mut dead = Vec::new();
    map(
        Node::<ipc::Service>::list(&cfg, |state| {
            if let NodeState::Dead(view) = state {
                let name = view
                    .details()
                    .as_ref()
                    .map(|d| d.name().as_str().to_string())
                    .unwrap_or_else(|| "unnamed node".into());
                let _ = view.try_remove_stale_resources();
                dead.push(name);
            }
            iceoryx2::prelude::CallbackProgression::Continue
        }),
        "listing nodes",
    )?;
    Ok(dead)
}

/// Removes the shared-memory objects and files of a run (after all its processes ended).
pub fn remove_run_files(prefix: &str) {
    // `.` ends the prefix: no prefix holds one, so `exp` never matches `exp_2`'s.
    let shm_prefix = format!("{prefix}.");
    if let Ok(dir) = std::fs::read_dir("/dev/shm") {
        for entry in dir.flatten() {
            if entry.file_name().to_string_lossy().starts_with(&shm_prefix) {
                let _ = std::fs::remove_file(entry.path());
            }
        }
    }
    let _ = std::fs::remove_dir_all(format!("{ROOT}/{prefix}"));
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Waits of every length under and around a microsecond end by their deadline with
    /// nobody notifying (each ran for ever before: iceoryx2 read them as no timeout).
    #[test]
    fn a_wait_shorter_than_a_microsecond_returns() {
        let prefix = format!("ttwake{}", std::process::id());
        let (tx, rx) = std::sync::mpsc::channel();
        let p = prefix.clone();
        std::thread::spawn(move || {
            let node = Rc::new(node(&p, "waiter").expect("node"));
            let wake = IpcWake::open(&node, "waiter").expect("wake");
            for ns in [0, 1, 500, 999, 1_000, 1_500, 20_000] {
                let start = Instant::now();
                wake.block(start + Duration::from_nanos(ns)).expect("block");
                tx.send((ns, start.elapsed())).expect("send");
            }
        });
        for _ in 0..7 {
            let (ns, took) = rx
                .recv_timeout(Duration::from_secs(10))
                .expect("a wait with a deadline of at most 20 us did not return in 10 s");
            assert!(took < Duration::from_secs(1), "{ns} ns: {took:?}");
        }
        remove_run_files(&prefix);
    }
}
