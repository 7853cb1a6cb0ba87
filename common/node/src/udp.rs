//! The same loop over UDP on loopback: the transport most teleoperation stacks use,
//! measured beside iceoryx2 by `tactile bench`.
//!
//! Each process binds one socket; a datagram is a tag byte (forward or backward) and
//! the sample encoded with bincode. Receives block with a timeout (what a typical
//! stack does), waking every 50 ms at most to notice a stop request. A send refused by
//! the operating system (no socket bound at the peer's port) counts as published with
//! no receiver; UDP cannot tell a dead peer otherwise.

use crate::ipc::{Idle, InboxStats, IpcError, OutboxStats};
use crate::link::{Arrival, EmulatorLink, EmulatorStats, MasterLink, SlaveLink, Wait};
use serde::{de::DeserializeOwned, Serialize};
use std::cell::{Cell, RefCell};
use std::io::ErrorKind;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactile_common::samples::{Backward, Forward, Sequenced};

const TAG_FORWARD: u8 = 0;
const TAG_BACKWARD: u8 = 1;

fn err(context: &str, e: impl std::fmt::Display) -> IpcError {
    IpcError {
        context: context.to_string(),
        detail: e.to_string(),
    }
}

/// Loopback ports of the three processes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UdpPorts {
    /// The master's port.
    pub master: u16,
    /// The emulator's port.
    pub emulator: u16,
    /// The slave's port.
    pub slave: u16,
}

impl UdpPorts {
    /// Three ports free right now (bound to port 0 and released).
    pub fn free() -> Result<UdpPorts, IpcError> {
        let pick = || -> Result<u16, IpcError> {
            let s = UdpSocket::bind("127.0.0.1:0").map_err(|e| err("picking a UDP port", e))?;
            Ok(s.local_addr()
                .map_err(|e| err("picking a UDP port", e))?
                .port())
        };
        Ok(UdpPorts {
            master: pick()?,
            emulator: pick()?,
            slave: pick()?,
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
            }),
            _ => None,
        }
    }

    /// `m,e,s` for the command line.
    pub fn arg(&self) -> String {
        format!("{},{},{}", self.master, self.emulator, self.slave)
    }

    fn addr(port: u16) -> SocketAddr {
        SocketAddr::from(([127, 0, 0, 1], port))
    }
}

/// One process's socket, with the counting every link does.
#[derive(Debug)]
struct Endpoint {
    socket: UdpSocket,
    stop: Arc<AtomicBool>,
    buf: RefCell<Vec<u8>>,
}

impl Endpoint {
    fn bind(port: u16) -> Result<Endpoint, IpcError> {
        let socket = UdpSocket::bind(UdpPorts::addr(port))
            .map_err(|e| err(&format!("binding UDP port {port}"), e))?;
        let stop = Arc::new(AtomicBool::new(false));
        for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            signal_hook::flag::register(sig, Arc::clone(&stop))
                .map_err(|e| err("installing signal handlers", e))?;
        }
        Ok(Endpoint {
            socket,
            stop,
            buf: RefCell::new(vec![0; 4096]),
        })
    }

    fn send<T: Serialize + Sequenced>(
        &self,
        to: u16,
        tag: u8,
        mut value: T,
        control: bool,
        stats: &Cell<OutboxStats>,
    ) -> Result<(), IpcError> {
        let mut st = stats.get();
        st.stamp(&mut value, control);
        let mut buf = self.buf.borrow_mut();
        buf[0] = tag;
        let n = bincode::serde::encode_into_slice(&value, &mut buf[1..], bincode::config::legacy())
            .map_err(|e| err("encoding a sample", e))?;
        let receivers = match self.socket.send_to(&buf[..n + 1], UdpPorts::addr(to)) {
            Ok(_) => 1,
            Err(e) if e.kind() == ErrorKind::ConnectionRefused => 0,
            Err(e) => return Err(err("sending a datagram", e)),
        };
        st.count(receivers, control);
        stats.set(st);
        Ok(())
    }

    /// Waits for one datagram until `deadline` and hands its tag and body to `take`
    /// (decoded in place: no copy, no allocation).
    fn recv<R>(
        &self,
        deadline: Instant,
        mut take: impl FnMut(u8, &[u8]) -> Result<Option<R>, IpcError>,
    ) -> Result<Result<R, Idle>, IpcError> {
        let mut buf = self.buf.borrow_mut();
        loop {
            if self.stop.load(Ordering::Relaxed) {
                return Ok(Err(Idle::Terminate));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(Err(Idle::Timeout));
            }
            let wait = (deadline - now)
                .min(Duration::from_millis(50))
                .max(Duration::from_micros(1));
            self.socket
                .set_read_timeout(Some(wait))
                .map_err(|e| err("setting a UDP timeout", e))?;
            match self.socket.recv(&mut buf) {
                Ok(n) if n > 0 => {
                    if let Some(r) = take(buf[0], &buf[1..n])? {
                        return Ok(Ok(r));
                    }
                }
                Ok(_) => {}
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

/// Decodes one datagram body and counts it; a body that is not a whole sample (garbage,
/// truncated, another format) is counted as malformed and dropped, never an error:
/// nothing the network delivers may stop a node.
fn decode<T: DeserializeOwned + Sequenced>(
    body: &[u8],
    stats: &Cell<InboxStats>,
    next: &Cell<Option<u64>>,
) -> Option<T> {
    let mut st = stats.get();
    let decoded = bincode::serde::decode_from_slice::<T, _>(body, bincode::config::legacy());
    let v = match decoded {
        Ok((v, used)) if used == body.len() => Some(v),
        _ => {
            st.malformed += 1;
            None
        }
    };
    if let Some(v) = &v {
        let mut n = next.get();
        st.count(v, &mut n);
        next.set(n);
    }
    stats.set(st);
    v
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
    pub fn open(ports: UdpPorts) -> Result<Self, IpcError> {
        Ok(UdpMaster {
            ep: Endpoint::bind(ports.master)?,
            ports,
            out: Cell::default(),
            inn: Cell::default(),
            next: Cell::new(None),
        })
    }
}

impl MasterLink for UdpMaster {
    fn send(&self, c: Forward) -> Result<(), IpcError> {
        self.ep
            .send(self.ports.emulator, TAG_FORWARD, c, false, &self.out)
    }
    fn send_control(&self, c: Forward) -> Result<(), IpcError> {
        self.ep
            .send(self.ports.emulator, TAG_FORWARD, c, true, &self.out)
    }
    fn recv(&self, deadline: Instant) -> Wait<Backward> {
        self.ep.recv(deadline, |tag, body| {
            Ok((tag == TAG_BACKWARD)
                .then(|| decode(body, &self.inn, &self.next))
                .flatten())
        })
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
    pub fn open(ports: UdpPorts) -> Result<Self, IpcError> {
        Ok(UdpEmulator {
            ep: Endpoint::bind(ports.emulator)?,
            ports,
            stats: Default::default(),
            inn: Default::default(),
            next: Default::default(),
        })
    }
}

impl EmulatorLink for UdpEmulator {
    fn recv(&self, deadline: Instant) -> Wait<Arrival> {
        self.ep.recv(deadline, |tag, body| {
            Ok(match tag {
                TAG_FORWARD => decode(body, &self.inn[0], &self.next[0]).map(Arrival::Forward),
                TAG_BACKWARD => decode(body, &self.inn[1], &self.next[1]).map(Arrival::Backward),
                _ => {
                    let mut st = self.inn[0].get();
                    st.malformed += 1;
                    self.inn[0].set(st);
                    None
                }
            })
        })
    }
    fn send_v(&self, v: Forward, control: bool) -> Result<(), IpcError> {
        self.ep
            .send(self.ports.slave, TAG_FORWARD, v, control, &self.stats[0])
    }
    fn send_q(&self, q: Backward, control: bool) -> Result<(), IpcError> {
        self.ep
            .send(self.ports.master, TAG_BACKWARD, q, control, &self.stats[1])
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
    pub fn open(ports: UdpPorts) -> Result<Self, IpcError> {
        Ok(UdpSlave {
            ep: Endpoint::bind(ports.slave)?,
            ports,
            out: Cell::default(),
            inn: Cell::default(),
            next: Cell::new(None),
        })
    }
}

impl SlaveLink for UdpSlave {
    fn recv(&self, deadline: Instant) -> Wait<Forward> {
        self.ep.recv(deadline, |tag, body| {
            Ok((tag == TAG_FORWARD)
                .then(|| decode(body, &self.inn, &self.next))
                .flatten())
        })
    }
    fn send_h(&self, h: Backward, control: bool) -> Result<(), IpcError> {
        self.ep
            .send(self.ports.emulator, TAG_BACKWARD, h, control, &self.out)
    }
    fn stats(&self) -> (InboxStats, OutboxStats) {
        (self.inn.get(), self.out.get())
    }
}
