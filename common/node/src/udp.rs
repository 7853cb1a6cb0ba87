//! The same loop over UDP: the transport most teleoperation stacks use, measured beside
//! iceoryx2 and Zenoh by `tactile bench`.
//!
//! Each process binds one socket at its own address; a datagram is one frame of the
//! wire format ([`crate::wire`]). Receives block with a timeout (what a typical stack
//! does), waking every 50 ms at most to notice a stop request. A send refused by the
//! operating system (no socket bound at the peer's port) counts as published with no
//! receiver; UDP cannot tell a dead peer otherwise. A datagram that is not a whole
//! frame of this build's format is counted and dropped.

use crate::link::{Arrival, EmulatorLink, EmulatorStats, MasterLink, SlaveLink, Wait};
use crate::link::{Idle, InboxStats, LinkError, OutboxStats, WaitPolicy};
use crate::wire::{self, backward, count as take, forward, Frame};
use std::cell::{Cell, RefCell};
use std::io::ErrorKind;
use std::net::{IpAddr, SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactile_messages::samples::{Backward, Forward, Sequenced};

fn err(context: &str, e: impl std::fmt::Display) -> LinkError {
    LinkError {
        context: context.to_string(),
        detail: e.to_string(),
    }
}

/// Ports of the three processes, and their hosts' addresses (loopback by default).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UdpPorts {
    /// The master's port.
    pub master: u16,
    /// The emulator's port.
    pub emulator: u16,
    /// The slave's port.
    pub slave: u16,
    /// Addresses of the master's, the emulator's and the slave's hosts.
    pub hosts: [IpAddr; 3],
}

const LOOPBACK: IpAddr = IpAddr::V4(std::net::Ipv4Addr::LOCALHOST);

impl UdpPorts {
    /// Three ports free right now (bound to port 0 and released).
    pub fn free() -> Result<UdpPorts, LinkError> {
        let pick = || -> Result<u16, LinkError> {
            let s = UdpSocket::bind("127.0.0.1:0").map_err(|e| err("picking a UDP port", e))?;
            Ok(s.local_addr()
                .map_err(|e| err("picking a UDP port", e))?
                .port())
        };
        Ok(UdpPorts {
            master: pick()?,
            emulator: pick()?,
            slave: pick()?,
            hosts: [LOOPBACK; 3],
        })
    }

    /// `m,e,s` as on the command line.
    pub fn parse(text: &str) -> Option<UdpPorts> {
        let v: Vec<u16> = text
            .split(',')
            .map(|p| p.trim().parse().ok())
            .collect::<Option<_>>()?;
        match v[..] {
            [master, emulator, slave] => Some(UdpPorts {
                master,
                emulator,
                slave,
                hosts: [LOOPBACK; 3],
            }),
            _ => None,
        }
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
        format!("{},{},{}", self.master, self.emulator, self.slave)
    }

    fn master_addr(&self) -> SocketAddr {
        SocketAddr::new(self.hosts[0], self.master)
    }

    fn emulator_addr(&self) -> SocketAddr {
        SocketAddr::new(self.hosts[1], self.emulator)
    }

    fn slave_addr(&self) -> SocketAddr {
        SocketAddr::new(self.hosts[2], self.slave)
    }
}

/// One process's socket, with the counting every link does.
#[derive(Debug)]
struct Endpoint {
    socket: UdpSocket,
    /// Poll budget before a blocking receive, as the other links have.
    spin: Duration,
    stop: Arc<AtomicBool>,
    buf: RefCell<Vec<u8>>,
}

impl Endpoint {
    fn bind(at: SocketAddr, wait: WaitPolicy) -> Result<Endpoint, LinkError> {
        let socket = UdpSocket::bind(at).map_err(|e| err(&format!("binding UDP {at}"), e))?;
        let stop = crate::signals::stop_flag().map_err(|e| err("installing signal handlers", e))?;
        Ok(Endpoint {
            socket,
            spin: wait.spin,
            stop,
            buf: RefCell::new(Vec::with_capacity(wire::MAX_FRAME)),
        })
    }

    fn send<T: Sequenced + Copy>(
        &self,
        to: SocketAddr,
        value: T,
        control: bool,
        stats: &Cell<OutboxStats>,
        encode: fn(&T, &mut Vec<u8>) -> Result<(), String>,
    ) -> Result<(), LinkError> {
        let mut buf = self.buf.borrow_mut();
        wire::send_counted(value, control, stats, &mut buf, encode, |frame| match self
            .socket
            .send_to(frame, to)
        {
            Ok(_) => Ok(1),
            Err(e) if e.kind() == ErrorKind::ConnectionRefused => Ok(0),
            Err(e) => Err(err("sending a datagram", e)),
        })
    }

    /// Waits for one datagram until `deadline` and hands its decoded frame to `take`
    /// (`Err` for a rejected one, which `take` counts): looks without waiting (and
    /// yields) for the poll budget, like the other links, then blocks in the kernel.
    fn recv<R>(
        &self,
        deadline: Instant,
        mut take: impl FnMut(Result<Frame, wire::Reject>) -> Option<R>,
    ) -> Result<Result<R, Idle>, LinkError> {
        let mut buf = self.buf.borrow_mut();
        buf.resize(wire::MAX_FRAME + 1, 0);
        let start = Instant::now();
        loop {
            if self.stop.load(Ordering::Relaxed) {
                return Ok(Err(Idle::Terminate));
            }
            // One look without waiting: a receive whose deadline is past still takes
            // what is already there.
            let flags = rustix::net::RecvFlags::DONTWAIT;
            if let Ok((n, _)) = rustix::net::recv(&self.socket, &mut buf[..], flags) {
                // A rejected datagram falls through to the deadline check, so junk
                // arriving without pause cannot hold a receive past its deadline.
                if let Some(r) = take(wire::decode(&buf[..n])) {
                    return Ok(Ok(r));
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(Err(Idle::Timeout));
            }
            if now.duration_since(start) < self.spin {
                std::thread::yield_now();
                continue;
            }
            let wait = (deadline - now)
                .min(Duration::from_millis(50))
                .max(Duration::from_micros(1));
            self.socket
                .set_read_timeout(Some(wait))
                .map_err(|e| err("setting a UDP timeout", e))?;
            match self.socket.recv(&mut buf) {
                Ok(n) => {
                    if let Some(r) = take(wire::decode(&buf[..n])) {
                        return Ok(Ok(r));
                    }
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::WouldBlock
                            | ErrorKind::TimedOut
                            | ErrorKind::Interrupted
                            | ErrorKind::ConnectionRefused
                    ) => {}
                Err(e) => return Err(err("receiving a datagram", e)),
            }
        }
    }
}

/// The master's end over UDP.
#[derive(Debug)]
pub struct UdpMaster {
    ep: Endpoint,
    ports: UdpPorts,
    out: Cell<OutboxStats>,
    inn: Cell<InboxStats>,
    next: Cell<Option<u64>>,
}

impl UdpMaster {
    /// Binds the master's port.
    pub fn open(ports: UdpPorts, wait: WaitPolicy) -> Result<Self, LinkError> {
        Ok(UdpMaster {
            ep: Endpoint::bind(ports.master_addr(), wait)?,
            ports,
            out: Cell::default(),
            inn: Cell::default(),
            next: Cell::new(None),
        })
    }
}

impl MasterLink for UdpMaster {
    fn send(&self, c: Forward) -> Result<(), LinkError> {
        self.ep.send(
            self.ports.emulator_addr(),
            c,
            false,
            &self.out,
            wire::encode_forward,
        )
    }
    fn send_control(&self, c: Forward) -> Result<(), LinkError> {
        self.ep.send(
            self.ports.emulator_addr(),
            c,
            true,
            &self.out,
            wire::encode_forward,
        )
    }
    fn recv(&self, deadline: Instant) -> Wait<Backward> {
        self.ep
            .recv(deadline, |got| take(got, backward, &self.inn, &self.next))
    }
    fn dead_peers(&self) -> Vec<String> {
        Vec::new()
    }
    fn stats(&self) -> (OutboxStats, InboxStats) {
        (self.out.get(), self.inn.get())
    }
}

/// The emulator's ends over UDP.
#[derive(Debug)]
pub struct UdpEmulator {
    ep: Endpoint,
    ports: UdpPorts,
    stats: [Cell<OutboxStats>; 2],
    inn: [Cell<InboxStats>; 2],
    next: [Cell<Option<u64>>; 2],
}

impl UdpEmulator {
    /// Binds the emulator's port.
    pub fn open(ports: UdpPorts, wait: WaitPolicy) -> Result<Self, LinkError> {
        Ok(UdpEmulator {
            ep: Endpoint::bind(ports.emulator_addr(), wait)?,
            ports,
            stats: Default::default(),
            inn: Default::default(),
            next: Default::default(),
        })
    }
}

impl EmulatorLink for UdpEmulator {
    fn recv(&self, deadline: Instant) -> Wait<Arrival> {
        self.ep.recv(deadline, |got| match got {
            Ok(Frame::Forward(_)) => {
                take(got, forward, &self.inn[0], &self.next[0]).map(Arrival::Forward)
            }
            Ok(Frame::Backward(_)) => {
                take(got, backward, &self.inn[1], &self.next[1]).map(Arrival::Backward)
            }
            Err(_) => take(got, forward, &self.inn[0], &self.next[0]).map(Arrival::Forward),
        })
    }
    fn send_v(&self, v: Forward, control: bool) -> Result<(), LinkError> {
        self.ep.send(
            self.ports.slave_addr(),
            v,
            control,
            &self.stats[0],
            wire::encode_forward,
        )
    }
    fn send_q(&self, q: Backward, control: bool) -> Result<(), LinkError> {
        self.ep.send(
            self.ports.master_addr(),
            q,
            control,
            &self.stats[1],
            wire::encode_backward,
        )
    }
    fn stats(&self) -> EmulatorStats {
        EmulatorStats {
            c_in: self.inn[0].get(),
            v_out: self.stats[0].get(),
            h_in: self.inn[1].get(),
            q_out: self.stats[1].get(),
        }
    }
}

/// The slave's ends over UDP.
#[derive(Debug)]
pub struct UdpSlave {
    ep: Endpoint,
    ports: UdpPorts,
    out: Cell<OutboxStats>,
    inn: Cell<InboxStats>,
    next: Cell<Option<u64>>,
}

impl UdpSlave {
    /// Binds the slave's port.
    pub fn open(ports: UdpPorts, wait: WaitPolicy) -> Result<Self, LinkError> {
        Ok(UdpSlave {
            ep: Endpoint::bind(ports.slave_addr(), wait)?,
            ports,
            out: Cell::default(),
            inn: Cell::default(),
            next: Cell::new(None),
        })
    }
}

impl SlaveLink for UdpSlave {
    fn recv(&self, deadline: Instant) -> Wait<Forward> {
        self.ep
            .recv(deadline, |got| take(got, forward, &self.inn, &self.next))
    }
    fn send_h(&self, h: Backward, control: bool) -> Result<(), LinkError> {
        self.ep.send(
            self.ports.emulator_addr(),
            h,
            control,
            &self.out,
            wire::encode_backward,
        )
    }
    fn stats(&self) -> (InboxStats, OutboxStats) {
        (self.inn.get(), self.out.get())
    }
}
