//! The haptic flow's time on a link, packet by packet: a packet every `t_s` for
//! `seconds`, of `bytes` on the wire, through a Mahimahi trace with mm-link's
//! semantics and a queue; prints the delay's percentiles (arrival to last byte out,
//! as mm-link logs it) and the drops. docs/04's table of the shipped LTE traces:
//!
//!   cargo run -p tactile-netem --example link_delay -- deploy/networks/Verizon-LTE-short.up
//!
//! Arguments: TRACE [bytes = 278] [rate_hz = 1000] [seconds = 140] [queue = infinite |
//! droptail:N | drophead:N (N packets)].

use tactile_netem::link::{Bound, Event, Fate, Fifo, Link, Opportunities, Packet, Queue, Server};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let trace = args
        .first()
        .ok_or("usage: link_delay TRACE [bytes] [rate_hz] [seconds] [queue]")?;
    let num = |i: usize, d: f64| args.get(i).map_or(Ok(d), |a| a.parse::<f64>());
    let (bytes, rate_hz, seconds) = (num(1, 278.0)?, num(2, 1000.0)?, num(3, 140.0)?);
    let queue: Box<dyn Queue> = match args.get(4).map(String::as_str) {
        None | Some("infinite") => Box::new(Fifo::infinite()),
        Some(q) => {
            let (kind, n) = q
                .split_once(':')
                .ok_or("queue: infinite, droptail:N or drophead:N")?;
            let bound = Bound {
                packets: n.parse()?,
                bytes: 0,
            };
            match kind {
                "droptail" => Box::new(Fifo::drop_tail(bound)),
                "drophead" => Box::new(Fifo::drop_head(bound)),
                _ => return Err("queue: infinite, droptail:N or drophead:N".into()),
            }
        }
    };
    let ops = Opportunities::parse(&std::fs::read_to_string(trace)?)?;
    let mut link = Link::new(Server::Trace(ops), queue, 1);
    let mut events: Vec<Event> = Vec::new();
    let n = (seconds * rate_hz) as u64;
    for k in 0..n {
        let p = Packet {
            flow: 0,
            tag: k,
            bytes: bytes as u32,
            arrival_ns: (k as f64 * 1e9 / rate_hz).round() as u64,
        };
        link.enqueue(p, &mut events);
    }
    link.advance(u64::MAX / 2, &mut events);
    let mut ms: Vec<f64> = events
        .iter()
        .filter_map(|e| match e.fate {
            Fate::Departed(at) => Some((at - e.packet.arrival_ns) as f64 / 1e6),
            Fate::Dropped(_) => None,
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    let q = |p: f64| ms[((p * ms.len() as f64) as usize).min(ms.len() - 1)];
    let s = link.stats(0);
    println!(
        "{trace}: {n} packets of {bytes} B at {rate_hz} Hz; delay ms p50 {:.0} p99 {:.0} p99.9 {:.0} max {:.0}; dropped {} (at the cap {})",
        q(0.5), q(0.99), q(0.999), ms[ms.len() - 1], s.dropped, s.dropped_cap
    );
    Ok(())
}
