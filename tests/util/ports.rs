//! Ports for the tests' listeners (nodes and Python stand-ins listen on them), handed
//! out so they cannot race. Binding port 0 and dropping the socket gave a number that
//! another test of the same binary could be handed next (the kernel picks ephemeral
//! ports at random), so two tests could listen on one port. Here each test process
//! owns a block of ports below the kernel's ephemeral range (chosen from its PID, so
//! parallel test binaries start apart) and hands each number out once; a number some
//! other program holds, over TCP or UDP, is passed over.

use std::net::{Ipv4Addr, TcpListener, UdpSocket};
use std::sync::atomic::{AtomicU32, Ordering};

/// The lowest port handed out: above the well-known and most registered services.
const LOW: u32 = 10_000;
/// One past the highest: Linux's ephemeral range starts at 32768, so no socket bound
/// to port 0 (a test's own, or any program's outgoing connection) lands here.
const HIGH: u32 = 32_000;
/// Ports a test process owns before it moves on to its neighbour's block.
const BLOCK: u32 = 256;

/// How many ports this process has handed out (or passed over).
static NEXT: AtomicU32 = AtomicU32::new(0);

/// A port on loopback that no other call in this process returns and that nothing
/// listens on (TCP or UDP) when it is handed out.
pub fn free_port() -> u16 {
    let blocks = (HIGH - LOW) / BLOCK;
    let first = LOW + (std::process::id() % blocks) * BLOCK;
    let candidates = std::iter::from_fn(|| {
        let k = NEXT.fetch_add(1, Ordering::SeqCst);
        assert!(
            k < HIGH - LOW,
            "the tests asked for more than {} ports",
            HIGH - LOW
        );
        let port = LOW + (first - LOW + k) % (HIGH - LOW);
        u16::try_from(port).ok()
    });
    first_free(candidates).expect("a free port below 32000")
}

/// The first of `candidates` that can be bound on loopback both over TCP and UDP.
pub fn first_free(candidates: impl IntoIterator<Item = u16>) -> Option<u16> {
    candidates.into_iter().find(|&p| {
        TcpListener::bind((Ipv4Addr::LOCALHOST, p)).is_ok()
            && UdpSocket::bind((Ipv4Addr::LOCALHOST, p)).is_ok()
    })
}

#[test]
fn no_port_is_handed_out_twice() {
    // Nothing listens on them in between, as when a test hands a port to a program it
    // has yet to start: binding port 0 would repeat a number within a few hundred.
    let ports: Vec<u16> = (0..1000).map(|_| free_port()).collect();
    let mut sorted = ports.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(sorted.len(), ports.len(), "a port handed out twice");
}

#[test]
fn a_port_held_over_udp_or_tcp_is_passed_over() {
    let udp = UdpSocket::bind((Ipv4Addr::LOCALHOST, 0)).expect("bind udp");
    let tcp = TcpListener::bind((Ipv4Addr::LOCALHOST, 0)).expect("bind tcp");
    let [u, t] = [udp.local_addr(), tcp.local_addr()].map(|a| a.expect("addr").port());
    let free = free_port();
    assert_eq!(first_free([u, t, free]), Some(free));
}
