//! The UDP transport: what most teleoperation stacks use, measured beside iceoryx2
//! and Zenoh by `tactile bench`.
//!
//! Each process binds one socket at its own address, shared by its UDP ends; a
//! datagram is one frame of the wire format ([`crate::wire`]), and the frames that come
//! in are sorted into the node's streams by their kind ([`crate::wire::Demux`]). A
//! send refused by the operating system (no socket bound at the peer's port) counts as
//! published with no receiver: UDP cannot tell a dead peer otherwise. A datagram that
//! is not a whole frame of this build's format is counted and dropped.

use crate::ends::{LinkError, Publish, Subscribe, Wake};
use crate::streams::{Kind, Stream};
use crate::wire::{self, Demux, OnWire};
use std::cell::RefCell;
use std::io::ErrorKind;
use std::marker::PhantomData;
use std::net::{IpAddr, SocketAddr, UdpSocket};
use std::rc::Rc;
use std::time::{Duration, Instant};
use tactile_messages::stream::{InboxStats, OutboxStats};
use tactile_messages::Role;

/// Ports of the three processes, and their hosts' addresses (loopback by default).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UdpPorts {
    /// The master's, the emulator's and the slave's ports.
    pub ports: [u16; 3],
    /// Addresses of the master's, the emulator's and the slave's hosts.
    pub hosts: [IpAddr; 3],
}

const LOOPBACK: IpAddr = IpAddr::V4(std::net::Ipv4Addr::LOCALHOST);

impl UdpPorts {
    /// Three ports free right now (bound to port 0 and released).
    pub fn free() -> Result<UdpPorts, LinkError> {
        let pick = || -> Result<u16, LinkError> {
            let e = |e| LinkError::new("picking a UDP port", e);
            let s = UdpSocket::bind("127.0.0.1:0").map_err(e)?;
            Ok(s.local_addr().map_err(e)?.port())
        };
        Ok(UdpPorts {
            ports: [pick()?, pick()?, pick()?],
            hosts: [LOOPBACK; 3],
        })
    }

    /// `m,e,s` as on the command line.
    pub fn parse(text: &str) -> Option<UdpPorts> {
        let v: Vec<u16> = text
            .split(',')
            .map(|p| p.trim().parse().ok())
            .collect::<Option<_>>()?;
        Some(UdpPorts {
            ports: v.try_into().ok()?,
            hosts: [LOOPBACK; 3],
        })
    }

    /// The same ports on the hosts `a,b,c` (master, emulator, slave) as on the
    /// command line.
    pub fn on_hosts(mut self, text: &str) -> Option<UdpPorts> {
        let v: Vec<IpAddr> = text
            .split(',')
            .map(|p| p.trim().parse().ok())
            .collect::<Option<_>>()?;
        self.hosts = v.try_into().ok()?;
        Some(self)
    }

    /// `m,e,s` for the command line.
    pub fn arg(&self) -> String {
        let [m, e, s] = self.ports;
        format!("{m},{e},{s}")
    }

    /// Where `role` receives.
    pub fn addr(&self, role: Role) -> SocketAddr {
        SocketAddr::new(self.hosts[role.index()], self.ports[role.index()])
    }
}

/// One process's socket, shared by its UDP ends.
#[derive(Debug)]
pub struct UdpEndpoint {
    socket: UdpSocket,
    demux: RefCell<Demux>,
    buf: RefCell<Vec<u8>>,
}

impl UdpEndpoint {
    /// Binds `role`'s address; the node takes the streams of kinds `wanted`.
    pub fn bind(ports: &UdpPorts, role: Role, wanted: &[Kind]) -> Result<Rc<Self>, LinkError> {
        let at = ports.addr(role);
        let socket =
            UdpSocket::bind(at).map_err(|e| LinkError::new(&format!("binding UDP {at}"), e))?;
        socket
            .set_nonblocking(true)
            .map_err(|e| LinkError::new("making the UDP socket non-blocking", e))?;
        Ok(Rc::new(UdpEndpoint {
            socket,
            demux: RefCell::new(Demux::new(wanted)),
            buf: RefCell::new(Vec::with_capacity(wire::MAX_FRAME + 1)),
        }))
    }

    fn take<T: OnWire>(&self) -> Option<T> {
        let mut buf = self.buf.borrow_mut();
        self.demux.borrow_mut().take(&mut buf, |b| {
            b.resize(wire::MAX_FRAME + 1, 0);
            match self.socket.recv(b) {
                Ok(n) => {
                    b.truncate(n);
                    true
                }
                // Nothing waiting (or an ICMP error of an earlier send): done.
                Err(_) => false,
            }
        })
    }
}

impl Wake for Rc<UdpEndpoint> {
    /// Waits for the socket to be readable (poll(2)), up to `until`.
    fn block(&self, until: Instant) -> Result<(), LinkError> {
        use rustix::event::{poll, PollFd, PollFlags, Timespec};
        let left = until.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Ok(());
        }
        let left = left.max(Duration::from_micros(1));
        let timeout = Timespec {
            tv_sec: left.as_secs() as _,
            tv_nsec: left.subsec_nanos() as _,
        };
        let mut fds = [PollFd::new(&self.socket, PollFlags::IN)];
        match poll(&mut fds, Some(&timeout)) {
            Ok(_) | Err(rustix::io::Errno::INTR) => Ok(()),
            Err(e) => Err(LinkError::new("waiting for a datagram", e)),
        }
    }
}

/// Sending end of a stream over UDP.
#[derive(Debug)]
pub struct UdpPublisher<T> {
    ep: Rc<UdpEndpoint>,
    to: SocketAddr,
    stats: OutboxStats,
    buf: Vec<u8>,
    _t: PhantomData<fn(T)>,
}

impl<T> UdpPublisher<T> {
    /// Sends `stream` from `ep` to its receiver's address.
    pub fn new(ep: &Rc<UdpEndpoint>, ports: &UdpPorts, stream: Stream) -> Self {
        UdpPublisher {
            ep: Rc::clone(ep),
            to: ports.addr(stream.receiver()),
            stats: OutboxStats::default(),
            buf: Vec::with_capacity(wire::MAX_FRAME),
            _t: PhantomData,
        }
    }
}

impl<T: OnWire> Publish<T> for UdpPublisher<T> {
    fn publish(&mut self, value: &T, control: bool) -> Result<(), LinkError> {
        let (socket, to) = (&self.ep.socket, self.to);
        wire::send_counted(value, control, &mut self.stats, &mut self.buf, |frame| {
            match socket.send_to(frame, to) {
                Ok(_) => Ok(1),
                Err(e) if e.kind() == ErrorKind::ConnectionRefused => Ok(0),
                // A full socket buffer: the datagram is lost, as on any network.
                Err(e) if e.kind() == ErrorKind::WouldBlock => Ok(0),
                Err(e) => Err(LinkError::new("sending a datagram", e)),
            }
        })
    }

    fn stats(&self) -> OutboxStats {
        self.stats
    }
}

/// Receiving end of a stream over UDP.
#[derive(Debug)]
pub struct UdpSubscriber<T> {
    ep: Rc<UdpEndpoint>,
    _t: PhantomData<fn() -> T>,
}

impl<T> UdpSubscriber<T> {
    /// Takes `T`'s stream from `ep`.
    pub fn new(ep: &Rc<UdpEndpoint>) -> Self {
        UdpSubscriber {
            ep: Rc::clone(ep),
            _t: PhantomData,
        }
    }
}

impl<T: OnWire> Subscribe<T> for UdpSubscriber<T> {
    fn try_recv(&mut self) -> Result<Option<T>, LinkError> {
        Ok(self.ep.take())
    }

    fn stats(&self) -> InboxStats {
        self.ep.demux.borrow().stats(T::KIND)
    }
}
