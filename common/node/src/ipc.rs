//! The iceoryx2 link: shared-memory wiring all three processes agree on (service
//! names, buffer sizes, overflow policy). Each stream is a publish-subscribe service
//! plus an event service of the same name: the sender publishes then notifies, the
//! receiver spins for a short budget and then blocks on the event. Every run (and
//! every test) has its own `prefix`, naming its shared-memory objects and its folder
//! of node and service files, so runs never see each other.

use iceoryx2::config::Config;
use iceoryx2::node::NodeWaitFailure;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{
    ipc, FileName, Node, NodeBuilder, NodeName, SemanticString, ServiceName, ZeroCopySend,
};
use std::cell::Cell;
use std::fmt::Debug;
use std::time::{Duration, Instant};
use tactile_messages::samples::Sequenced;
use tactile_messages::Role;

use crate::link::{Idle, InboxStats, LinkError, OutboxStats, WaitPolicy};

/// A process's iceoryx2 node.
pub type IpcNode = Node<ipc::Service>;

/// Samples a subscriber buffers before the oldest is overwritten (safe overflow). A
/// lost sample shows as a gap in the sequence numbers and is counted.
pub const SUBSCRIBER_BUFFER: usize = 64;

/// Root folder of the node and service files of all runs.
pub const ROOT: &str = "/tmp/tactile-iox2";

/// Stream names shared by the three processes.
pub mod streams {
    /// c(n): master to emulator.
    pub const C: &str = "forward/c";
    /// v(n): emulator to slave.
    pub const V: &str = "forward/v";
    /// h(n): slave to emulator.
    pub const H: &str = "backward/h";
    /// q(n): emulator to master.
    pub const Q: &str = "backward/q";
    /// Wake-up event of the master.
    pub const WAKE_MASTER: &str = tactile_messages::Role::Master.name();
    /// Wake-up event of the emulator.
    pub const WAKE_EMULATOR: &str = tactile_messages::Role::Emulator.name();
    /// Wake-up event of the slave.
    pub const WAKE_SLAVE: &str = tactile_messages::Role::Slave.name();
}

fn err(context: impl Into<String>) -> impl FnOnce(&dyn Debug) -> LinkError {
    let context = context.into();
    move |e| LinkError {
        context,
        detail: format!("{e:?}"),
    }
}

/// Maps any iceoryx2 error to [`LinkError`].
fn map<T, E: Debug>(r: Result<T, E>, context: impl Into<String>) -> Result<T, LinkError> {
    r.map_err(|e| err(context)(&e))
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
    Ok(cfg)
}

/// Creates this process's node; dead nodes of an earlier crashed run with the same
/// prefix are cleaned up on creation.
pub fn node(prefix: &str, name: &str) -> Result<Node<ipc::Service>, LinkError> {
    let cfg = config(prefix)?;
    let node_name = map(NodeName::new(name), format!("node name {name:?}"))?;
    let node = map(
        NodeBuilder::new()
            .name(&node_name)
            .config(&cfg)
            .create::<ipc::Service>(),
        format!("creating node {name}"),
    )?;
    // iceoryx2 installs its SIGINT/SIGTERM handlers on the first wait: do it now, so
    // a stop request is never fatal.
    let _ = node.wait(Duration::ZERO);
    Ok(node)
}

/// True once SIGINT or SIGTERM was received: by iceoryx2's handler (which consumes
/// the request) or, before iceoryx2 installed it, by the node's own stop flag.
pub fn termination_requested(node: &Node<ipc::Service>) -> bool {
    let iox = matches!(
        node.wait(Duration::ZERO),
        Err(NodeWaitFailure::TerminationRequest)
    );
    iox || crate::signals::stop_requested()
}

fn service_name(stream: &str) -> Result<ServiceName, LinkError> {
    let name = format!("tactile/{stream}");
    map(ServiceName::new(&name), format!("service name {name}"))
}

/// Sending end of a stream: a publisher, and a notifier that wakes the receiving
/// process (each process has one wake-up event, whichever stream the sample is on).
#[derive(Debug)]
pub struct Outbox<T: Debug + ZeroCopySend + 'static> {
    publisher: Publisher<ipc::Service, T, ()>,
    notifier: Notifier<ipc::Service>,
    stream: String,
    stats: Cell<OutboxStats>,
}

/// Receiving end of a stream.
#[derive(Debug)]
pub struct Inbox<T: Debug + ZeroCopySend + 'static> {
    subscriber: Subscriber<ipc::Service, T, ()>,
    stream: String,
    stats: Cell<InboxStats>,
    next_hop_seq: Cell<Option<u64>>,
}

/// A process's wake-up event: every stream into the process notifies it.
#[derive(Debug)]
pub struct Waker {
    listener: Listener<ipc::Service>,
    name: String,
}

fn open_pubsub<T: Debug + ZeroCopySend + 'static>(
    node: &Node<ipc::Service>,
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
    node: &Node<ipc::Service>,
    name: &str,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>, LinkError> {
    map(
        node.service_builder(&service_name(&format!("wake/{name}"))?)
            .event()
            .max_notifiers(8)
            .max_listeners(4)
            .max_nodes(8)
            .open_or_create(),
        format!("opening wake-up event {name}"),
    )
}

impl<T: Debug + ZeroCopySend + Copy + Sequenced + 'static> Outbox<T> {
    /// Opens (or creates) `stream` for sending; each send wakes process `wake`.
    pub fn open(node: &Node<ipc::Service>, stream: &str, wake: &str) -> Result<Self, LinkError> {
        let svc = open_pubsub::<T>(node, stream)?;
        let ev = open_event(node, wake)?;
        Ok(Outbox {
            publisher: map(
                svc.publisher_builder().max_loaned_samples(2).create(),
                format!("publisher on {stream}"),
            )?,
            notifier: map(
                ev.notifier_builder().create(),
                format!("notifier for {wake}"),
            )?,
            stream: stream.to_string(),
            stats: Cell::new(OutboxStats::default()),
        })
    }

    /// Publishes a copy of `value` (stamped with this hop's publish counter) and wakes
    /// the receiver; returns how many subscribers it reached.
    pub fn send(&self, value: T) -> Result<usize, LinkError> {
        self.publish(value, false)
    }

    /// Publishes a control sample (start-up probe, end of run): not counted, and
    /// marked so the receiver does not count it either.
    pub fn send_control(&self, value: T) -> Result<usize, LinkError> {
        self.publish(value, true)
    }

    /// Publishes, counted unless `control`.
    pub fn publish(&self, mut value: T, control: bool) -> Result<usize, LinkError> {
        let mut st = self.stats.get();
        st.stamp(&mut value, control);
        let n = map(
            self.publisher.send_copy(value),
            format!("sending on {}", self.stream),
        )?;
        st.count(n, control);
        self.stats.set(st);
        map(self.notifier.notify(), format!("notifying {}", self.stream))?;
        Ok(n)
    }

    /// Counters so far.
    pub fn stats(&self) -> OutboxStats {
        self.stats.get()
    }
}

impl<T: Debug + ZeroCopySend + Copy + Sequenced + 'static> Inbox<T> {
    /// Opens (or creates) `stream` for receiving.
    pub fn open(node: &Node<ipc::Service>, stream: &str) -> Result<Self, LinkError> {
        let svc = open_pubsub::<T>(node, stream)?;
        Ok(Inbox {
            subscriber: map(
                svc.subscriber_builder()
                    .buffer_size(SUBSCRIBER_BUFFER)
                    .create(),
                format!("subscriber on {stream}"),
            )?,
            stream: stream.to_string(),
            stats: Cell::new(InboxStats::default()),
            next_hop_seq: Cell::new(None),
        })
    }

    /// A sample if one is waiting; counts it, and any overwritten before it.
    pub fn try_recv(&self) -> Result<Option<T>, LinkError> {
        let got = map(
            self.subscriber.receive(),
            format!("receiving on {}", self.stream),
        )?
        .map(|s| *s);
        if let Some(v) = &got {
            let mut st = self.stats.get();
            let mut next = self.next_hop_seq.get();
            st.count(v, &mut next);
            self.next_hop_seq.set(next);
            self.stats.set(st);
        }
        Ok(got)
    }

    /// Counters so far.
    pub fn stats(&self) -> InboxStats {
        self.stats.get()
    }
}

impl Waker {
    /// Opens this process's wake-up event `name`.
    pub fn open(node: &Node<ipc::Service>, name: &str) -> Result<Self, LinkError> {
        let ev = open_event(node, name)?;
        Ok(Waker {
            listener: map(
                ev.listener_builder().create(),
                format!("listener for {name}"),
            )?,
            name: name.to_string(),
        })
    }

    /// Calls `poll` until it yields a value: busily for `spin`, then blocking on the
    /// wake-up event, until `deadline`. Returns [`Idle`] on timeout or a stop request.
    pub fn wait<V>(
        &self,
        node: &Node<ipc::Service>,
        spin: Duration,
        deadline: Instant,
        mut poll: impl FnMut() -> Result<Option<V>, LinkError>,
    ) -> Result<Result<V, Idle>, LinkError> {
        let start = Instant::now();
        loop {
            if let Some(v) = poll()? {
                return Ok(Ok(v));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(Err(Idle::Timeout));
            }
            if termination_requested(node) {
                return Ok(Err(Idle::Terminate));
            }
            if now.duration_since(start) < spin {
                // Yield rather than burn: on two cores three polling processes would
                // otherwise hold the core the next stage of the chain needs.
                std::thread::yield_now();
                continue;
            }
            match self.listener.timed_wait(|_| {}, deadline - now) {
                Ok(_) => {}
                Err(ListenerWaitError::InterruptSignal) => {
                    if termination_requested(node) {
                        return Ok(Err(Idle::Terminate));
                    }
                }
                Err(e) => return Err(err(format!("waiting on {}", self.name))(&e)),
            }
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

/// The master's end of the loop over iceoryx2.
#[derive(Debug)]
pub struct IoxMaster {
    node: IpcNode,
    out: Outbox<tactile_messages::samples::Forward>,
    inbox: Inbox<tactile_messages::samples::Backward>,
    waker: Waker,
    spin: Duration,
    prefix: String,
}

impl IoxMaster {
    /// Opens the master's streams of run `prefix`.
    pub fn open(prefix: &str, wait: WaitPolicy) -> Result<Self, LinkError> {
        let node = node(prefix, Role::Master.name())?;
        Ok(IoxMaster {
            out: Outbox::open(&node, streams::C, streams::WAKE_EMULATOR)?,
            inbox: Inbox::open(&node, streams::Q)?,
            waker: Waker::open(&node, streams::WAKE_MASTER)?,
            node,
            spin: wait.spin,
            prefix: prefix.to_string(),
        })
    }
}

impl crate::link::MasterLink for IoxMaster {
    fn send(&self, c: tactile_messages::samples::Forward) -> Result<(), LinkError> {
        self.out.publish(c, false).map(|_| ())
    }
    fn send_control(&self, c: tactile_messages::samples::Forward) -> Result<(), LinkError> {
        self.out.publish(c, true).map(|_| ())
    }
    fn recv(&self, deadline: Instant) -> crate::link::Wait<tactile_messages::samples::Backward> {
        self.waker
            .wait(&self.node, self.spin, deadline, || self.inbox.try_recv())
    }
    fn dead_peers(&self) -> Vec<String> {
        dead_nodes(&self.prefix).unwrap_or_default()
    }
    fn stats(&self) -> (OutboxStats, InboxStats) {
        (self.out.stats(), self.inbox.stats())
    }
}

/// The emulator's ends of the loop over iceoryx2.
#[derive(Debug)]
pub struct IoxEmulator {
    node: IpcNode,
    in_c: Inbox<tactile_messages::samples::Forward>,
    out_v: Outbox<tactile_messages::samples::Forward>,
    in_h: Inbox<tactile_messages::samples::Backward>,
    out_q: Outbox<tactile_messages::samples::Backward>,
    waker: Waker,
    spin: Duration,
}

impl IoxEmulator {
    /// Opens the emulator's streams of run `prefix`.
    pub fn open(prefix: &str, wait: WaitPolicy) -> Result<Self, LinkError> {
        let node = node(prefix, Role::Emulator.name())?;
        Ok(IoxEmulator {
            in_c: Inbox::open(&node, streams::C)?,
            out_v: Outbox::open(&node, streams::V, streams::WAKE_SLAVE)?,
            in_h: Inbox::open(&node, streams::H)?,
            out_q: Outbox::open(&node, streams::Q, streams::WAKE_MASTER)?,
            waker: Waker::open(&node, streams::WAKE_EMULATOR)?,
            node,
            spin: wait.spin,
        })
    }
}

impl crate::link::EmulatorLink for IoxEmulator {
    fn recv(&self, deadline: Instant) -> crate::link::Wait<crate::link::Arrival> {
        use crate::link::Arrival;
        self.waker.wait(&self.node, self.spin, deadline, || {
            // Backward first: it completes a round trip the master is waiting for.
            if let Some(h) = self.in_h.try_recv()? {
                return Ok(Some(Arrival::Backward(h)));
            }
            Ok(self.in_c.try_recv()?.map(Arrival::Forward))
        })
    }
    fn send_v(
        &self,
        v: tactile_messages::samples::Forward,
        control: bool,
    ) -> Result<(), LinkError> {
        self.out_v.publish(v, control).map(|_| ())
    }
    fn send_q(
        &self,
        q: tactile_messages::samples::Backward,
        control: bool,
    ) -> Result<(), LinkError> {
        self.out_q.publish(q, control).map(|_| ())
    }
    fn stats(&self) -> crate::link::EmulatorStats {
        crate::link::EmulatorStats {
            c_in: self.in_c.stats(),
            v_out: self.out_v.stats(),
            h_in: self.in_h.stats(),
            q_out: self.out_q.stats(),
        }
    }
}

/// The slave's ends of the loop over iceoryx2.
#[derive(Debug)]
pub struct IoxSlave {
    node: IpcNode,
    inbox: Inbox<tactile_messages::samples::Forward>,
    out: Outbox<tactile_messages::samples::Backward>,
    waker: Waker,
    spin: Duration,
}

impl IoxSlave {
    /// Opens the slave's streams of run `prefix`.
    pub fn open(prefix: &str, wait: WaitPolicy) -> Result<Self, LinkError> {
        let node = node(prefix, Role::Slave.name())?;
        Ok(IoxSlave {
            inbox: Inbox::open(&node, streams::V)?,
            out: Outbox::open(&node, streams::H, streams::WAKE_EMULATOR)?,
            waker: Waker::open(&node, streams::WAKE_SLAVE)?,
            node,
            spin: wait.spin,
        })
    }
}

impl crate::link::SlaveLink for IoxSlave {
    fn recv(&self, deadline: Instant) -> crate::link::Wait<tactile_messages::samples::Forward> {
        self.waker
            .wait(&self.node, self.spin, deadline, || self.inbox.try_recv())
    }
    fn send_h(
        &self,
        h: tactile_messages::samples::Backward,
        control: bool,
    ) -> Result<(), LinkError> {
        self.out.publish(h, control).map(|_| ())
    }
    fn stats(&self) -> (InboxStats, OutboxStats) {
        (self.inbox.stats(), self.out.stats())
    }
}

/// One side of an emulator whose other side is on another link: towards the master
/// (c in, q out) or towards the slave (v out, h in), over iceoryx2. The emulator polls
/// it beside its other link.
#[derive(Debug)]
pub struct IoxHalf {
    node: IpcNode,
    half: Half,
}

#[derive(Debug)]
enum Half {
    Master {
        c: Inbox<tactile_messages::samples::Forward>,
        q: Outbox<tactile_messages::samples::Backward>,
    },
    Slave {
        v: Outbox<tactile_messages::samples::Forward>,
        h: Inbox<tactile_messages::samples::Backward>,
    },
}

impl IoxHalf {
    /// Opens the master side (`master_side`) or the slave side of run `prefix`.
    pub fn open(prefix: &str, master_side: bool) -> Result<Self, LinkError> {
        let node = node(prefix, Role::Emulator.name())?;
        let half = if master_side {
            Half::Master {
                c: Inbox::open(&node, streams::C)?,
                q: Outbox::open(&node, streams::Q, streams::WAKE_MASTER)?,
            }
        } else {
            Half::Slave {
                v: Outbox::open(&node, streams::V, streams::WAKE_SLAVE)?,
                h: Inbox::open(&node, streams::H)?,
            }
        };
        Ok(IoxHalf { node, half })
    }

    /// A sample if one waits.
    pub fn try_recv(&self) -> Result<Option<crate::link::Arrival>, LinkError> {
        use crate::link::Arrival;
        Ok(match &self.half {
            Half::Master { c, .. } => c.try_recv()?.map(Arrival::Forward),
            Half::Slave { h, .. } => h.try_recv()?.map(Arrival::Backward),
        })
    }

    /// Publishes v(n) (slave side only).
    pub fn send_forward(
        &self,
        v: tactile_messages::samples::Forward,
        control: bool,
    ) -> Result<(), LinkError> {
        match &self.half {
            Half::Slave { v: out, .. } => out.publish(v, control).map(|_| ()),
            Half::Master { .. } => Err(LinkError {
                context: "sending v".into(),
                detail: "this side faces the master".into(),
            }),
        }
    }

    /// Publishes q(n) (master side only).
    pub fn send_backward(
        &self,
        q: tactile_messages::samples::Backward,
        control: bool,
    ) -> Result<(), LinkError> {
        match &self.half {
            Half::Master { q: out, .. } => out.publish(q, control).map(|_| ()),
            Half::Slave { .. } => Err(LinkError {
                context: "sending q".into(),
                detail: "this side faces the slave".into(),
            }),
        }
    }

    /// True once SIGINT or SIGTERM arrived.
    pub fn stopping(&self) -> bool {
        termination_requested(&self.node)
    }

    /// What the side's receiving and sending ends counted.
    pub fn stats(&self) -> (InboxStats, OutboxStats) {
        match &self.half {
            Half::Master { c, q } => (c.stats(), q.stats()),
            Half::Slave { v, h } => (h.stats(), v.stats()),
        }
    }
}
