//! A node's ends of the loop's streams, each on the transport chosen for it: the
//! ordinary case is any transport on any hop (an emulator with the master over Zenoh
//! and the slave over iceoryx2, or over UDP and iceoryx2). Each transport is opened
//! once per node (one iceoryx2 node, one UDP socket, one Zenoh session) and shared by
//! the node's ends on it.

use crate::ends::{LinkError, Publish, Subscribe, Wake};
use crate::options::{LinkArgs, LinkKind};
use crate::streams::{ends, End, Kind, Stream};
use crate::wire::OnWire;
use std::fmt::Debug;
use std::rc::Rc;
use tactile_messages::samples::{Backward, Forward};
use tactile_messages::stream::{InboxStats, OutboxStats};
use tactile_messages::Role;

/// A sample every transport carries.
pub trait Sample: OnWire + iceoryx2::prelude::ZeroCopySend + Debug + Copy + 'static {}
impl Sample for Forward {}
impl Sample for Backward {}

/// A node's four possible ends: what comes in and goes out each way.
#[derive(Default)]
pub struct Ports {
    /// c(n) at the emulator, v(n) at the slave.
    pub forward_in: Option<Box<dyn Subscribe<Forward>>>,
    /// c(n) from the master, v(n) from the emulator.
    pub forward_out: Option<Box<dyn Publish<Forward>>>,
    /// h(n) at the emulator, q(n) at the master.
    pub backward_in: Option<Box<dyn Subscribe<Backward>>>,
    /// h(n) from the slave, q(n) from the emulator.
    pub backward_out: Option<Box<dyn Publish<Backward>>>,
    /// One wait per transport the node receives on.
    pub wakes: Vec<Box<dyn Wake>>,
    /// The run's iceoryx2 prefix, if the node is on iceoryx2 (it can tell dead peers).
    pub ipc_prefix: Option<String>,
}

impl Debug for Ports {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ports")
            .field("forward_in", &self.forward_in.is_some())
            .field("forward_out", &self.forward_out.is_some())
            .field("backward_in", &self.backward_in.is_some())
            .field("backward_out", &self.backward_out.is_some())
            .field("wakes", &self.wakes.len())
            .finish()
    }
}

/// What the four ends counted (zero for an end the node does not have).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PortStats {
    /// The forward stream in.
    pub forward_in: InboxStats,
    /// The forward stream out.
    pub forward_out: OutboxStats,
    /// The backward stream in.
    pub backward_in: InboxStats,
    /// The backward stream out.
    pub backward_out: OutboxStats,
}

impl Ports {
    /// What the ends counted.
    pub fn stats(&self) -> PortStats {
        PortStats {
            forward_in: self
                .forward_in
                .as_ref()
                .map(|e| e.stats())
                .unwrap_or_default(),
            forward_out: self
                .forward_out
                .as_ref()
                .map(|e| e.stats())
                .unwrap_or_default(),
            backward_in: self
                .backward_in
                .as_ref()
                .map(|e| e.stats())
                .unwrap_or_default(),
            backward_out: self
                .backward_out
                .as_ref()
                .map(|e| e.stats())
                .unwrap_or_default(),
        }
    }

    /// Names of the peers known to have died (iceoryx2 tells; the others cannot), and
    /// their resources cleaned up.
    pub fn dead_peers(&self) -> Vec<String> {
        self.ipc_prefix
            .as_deref()
            .map(|p| crate::ipc::dead_nodes(p).unwrap_or_default())
            .unwrap_or_default()
    }
}

/// Makes ends of one transport.
trait Maker {
    fn publisher<T: Sample>(&self, s: Stream) -> Result<Box<dyn Publish<T>>, LinkError>;
    fn subscriber<T: Sample>(&self, s: Stream) -> Result<Box<dyn Subscribe<T>>, LinkError>;
}

/// Puts the end `(s, e)` made by `m` in its place.
fn place(ports: &mut Ports, m: &impl Maker, s: Stream, e: End) -> Result<(), LinkError> {
    match (s.kind(), e) {
        (Kind::Forward, End::Publish) => ports.forward_out = Some(m.publisher(s)?),
        (Kind::Forward, End::Subscribe) => ports.forward_in = Some(m.subscriber(s)?),
        (Kind::Backward, End::Publish) => ports.backward_out = Some(m.publisher(s)?),
        (Kind::Backward, End::Subscribe) => ports.backward_in = Some(m.subscriber(s)?),
    }
    Ok(())
}

struct Ipc(Rc<crate::ipc::IpcNode>);

impl Maker for Ipc {
    fn publisher<T: Sample>(&self, s: Stream) -> Result<Box<dyn Publish<T>>, LinkError> {
        Ok(Box::new(crate::ipc::IpcPublisher::<T>::of(&self.0, s)?))
    }
    fn subscriber<T: Sample>(&self, s: Stream) -> Result<Box<dyn Subscribe<T>>, LinkError> {
        Ok(Box::new(crate::ipc::IpcSubscriber::<T>::open(
            &self.0,
            s.service(),
        )?))
    }
}

struct Udp(Rc<crate::udp::UdpEndpoint>, crate::udp::UdpPorts);

impl Maker for Udp {
    fn publisher<T: Sample>(&self, s: Stream) -> Result<Box<dyn Publish<T>>, LinkError> {
        Ok(Box::new(crate::udp::UdpPublisher::<T>::new(
            &self.0, &self.1, s,
        )))
    }
    fn subscriber<T: Sample>(&self, _: Stream) -> Result<Box<dyn Subscribe<T>>, LinkError> {
        Ok(Box::new(crate::udp::UdpSubscriber::<T>::new(&self.0)))
    }
}

#[cfg(feature = "zenoh")]
struct Zenoh(Rc<crate::zenoh_link::ZenohEnd>);

#[cfg(feature = "zenoh")]
impl Maker for Zenoh {
    fn publisher<T: Sample>(&self, s: Stream) -> Result<Box<dyn Publish<T>>, LinkError> {
        Ok(Box::new(crate::zenoh_link::ZenohPublisher::<T>::new(
            &self.0, s,
        )?))
    }
    fn subscriber<T: Sample>(&self, _: Stream) -> Result<Box<dyn Subscribe<T>>, LinkError> {
        Ok(Box::new(crate::zenoh_link::ZenohSubscriber::<T>::new(
            &self.0,
        )))
    }
}

/// Opens `role`'s ends, each stream on the transport `link_of` gives it; `direct`: the
/// master without an emulator. The options must have passed [`LinkArgs::check`] for
/// every transport `link_of` names.
pub fn open(
    role: Role,
    args: &LinkArgs,
    link_of: impl Fn(Stream) -> LinkKind,
    direct: bool,
) -> Result<Ports, LinkError> {
    let mut ports = Ports::default();
    let mine = ends(role, direct);
    let on = |k: LinkKind| -> Vec<(Stream, End)> {
        mine.iter()
            .copied()
            .filter(|(s, _)| link_of(*s) == k)
            .collect()
    };
    let receives = |v: &[(Stream, End)]| v.iter().any(|(_, e)| *e == End::Subscribe);
    let ipc = on(LinkKind::Iceoryx2);
    if !ipc.is_empty() {
        let node = Rc::new(crate::ipc::node(&args.prefix, role.name())?);
        if receives(&ipc) {
            ports
                .wakes
                .push(Box::new(crate::ipc::IpcWake::open(&node, role.name())?));
        }
        let m = Ipc(node);
        for (s, e) in ipc {
            place(&mut ports, &m, s, e)?;
        }
        ports.ipc_prefix = Some(args.prefix.clone());
    }
    let udp = on(LinkKind::Udp);
    if !udp.is_empty() {
        let addrs = args.udp().map_err(|e| LinkError::new("UDP", e))?;
        let kinds = subscribed_kinds(&udp);
        let ep = crate::udp::UdpEndpoint::bind(&addrs, role, &kinds)?;
        if receives(&udp) {
            ports.wakes.push(Box::new(Rc::clone(&ep)));
        }
        let m = Udp(ep, addrs);
        for (s, e) in udp {
            place(&mut ports, &m, s, e)?;
        }
    }
    open_zenoh(&mut ports, args, on(LinkKind::Zenoh))?;
    Ok(ports)
}

fn subscribed_kinds(v: &[(Stream, End)]) -> Vec<Kind> {
    v.iter()
        .filter(|(_, e)| *e == End::Subscribe)
        .map(|(s, _)| s.kind())
        .collect()
}

#[cfg(feature = "zenoh")]
fn open_zenoh(ports: &mut Ports, args: &LinkArgs, z: Vec<(Stream, End)>) -> Result<(), LinkError> {
    if z.is_empty() {
        return Ok(());
    }
    let subscribed: Vec<Stream> = z
        .iter()
        .filter(|(_, e)| *e == End::Subscribe)
        .map(|(s, _)| *s)
        .collect();
    let end = crate::zenoh_link::ZenohEnd::open(&args.zenoh(), &args.prefix, &subscribed)?;
    if !subscribed.is_empty() {
        ports.wakes.push(Box::new(Rc::clone(&end)));
    }
    let m = Zenoh(end);
    for (s, e) in z {
        place(ports, &m, s, e)?;
    }
    Ok(())
}

#[cfg(not(feature = "zenoh"))]
fn open_zenoh(_: &mut Ports, _: &LinkArgs, z: Vec<(Stream, End)>) -> Result<(), LinkError> {
    if z.is_empty() {
        Ok(())
    } else {
        Err(LinkError::new("--link zenoh", crate::options::NO_ZENOH))
    }
}

/// A loop in memory, for the in-process runner: the master's, the emulator's and the
/// slave's ends, joined as the processes' are (c and q between master and emulator, v
/// and h between emulator and slave).
pub fn in_memory() -> [Ports; 3] {
    use crate::memory::stream;
    let (c_out, c_in) = stream::<Forward>();
    let (v_out, v_in) = stream::<Forward>();
    let (h_out, h_in) = stream::<Backward>();
    let (q_out, q_in) = stream::<Backward>();
    let master = Ports {
        forward_out: Some(Box::new(c_out)),
        backward_in: Some(Box::new(q_in)),
        ..Ports::default()
    };
    let emulator = Ports {
        forward_in: Some(Box::new(c_in)),
        forward_out: Some(Box::new(v_out)),
        backward_in: Some(Box::new(h_in)),
        backward_out: Some(Box::new(q_out)),
        ..Ports::default()
    };
    let slave = Ports {
        forward_in: Some(Box::new(v_in)),
        backward_out: Some(Box::new(h_out)),
        ..Ports::default()
    };
    [master, emulator, slave]
}
