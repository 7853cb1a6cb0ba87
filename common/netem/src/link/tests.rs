//! The link against mm-link's own algorithm, transcribed below from
//! `src/frontend/link_queue.cc` (`read_packet`, `rationalize`,
//! `use_a_delivery_opportunity`) and `src/packet/` (ravinet/mahimahi at
//! ae477d437615b972217498ba52be07db17a15618), and the disciplines' bounds.

use super::*;
use std::collections::VecDeque;

/// mm-link's `LinkQueue` line by line, its queue one of `src/packet/`'s, with time in
/// whole milliseconds as its `timestamp()`; returns each packet's departure (ms) or
/// `None` if dropped.
struct Reference {
    schedule: Vec<u64>,
    next_delivery: usize,
    base: u64,
    queue: VecDeque<(usize, u64, u32)>,
    kind: &'static str,
    packets_limit: usize,
    bytes_limit: u64,
    in_transit: Option<(usize, u64, u32)>,
    in_transit_left: u32,
    out: Vec<Option<u64>>,
}

impl Reference {
    fn next_delivery_time(&self) -> u64 {
        self.schedule[self.next_delivery] + self.base
    }

    fn use_a_delivery_opportunity(&mut self) {
        self.next_delivery = (self.next_delivery + 1) % self.schedule.len();
        if self.next_delivery == 0 {
            self.base += self.schedule[self.schedule.len() - 1];
        }
    }

    fn rationalize(&mut self, now: u64) {
        while self.next_delivery_time() <= now {
            let this_delivery_time = self.next_delivery_time();
            let mut bytes_left_in_this_delivery = 1504u32;
            self.use_a_delivery_opportunity();
            while bytes_left_in_this_delivery > 0 {
                if self.in_transit_left == 0 {
                    let Some(p) = self.queue.pop_front() else {
                        break;
                    };
                    self.in_transit = Some(p);
                    self.in_transit_left = p.2;
                }
                let amount_to_send = bytes_left_in_this_delivery.min(self.in_transit_left);
                self.in_transit_left -= amount_to_send;
                bytes_left_in_this_delivery -= amount_to_send;
                if self.in_transit_left == 0 {
                    let (id, _, _) = self.in_transit.expect("in transit");
                    self.out[id] = Some(this_delivery_time);
                }
            }
        }
    }

    fn good(&self, bytes: u64, packets: usize) -> bool {
        (self.bytes_limit == 0 || bytes <= self.bytes_limit)
            && (self.packets_limit == 0 || packets <= self.packets_limit)
    }

    fn bytes(&self) -> u64 {
        self.queue.iter().map(|p| u64::from(p.2)).sum()
    }

    fn read_packet(&mut self, id: usize, now: u64, size: u32) {
        self.rationalize(now);
        self.out.push(None);
        match self.kind {
            "droptail" => {
                if self.good(self.bytes() + u64::from(size), self.queue.len() + 1) {
                    self.queue.push_back((id, now, size));
                }
            }
            "drophead" => {
                self.queue.push_back((id, now, size));
                while !self.good(self.bytes(), self.queue.len()) {
                    self.queue.pop_front();
                }
            }
            _ => self.queue.push_back((id, now, size)),
        }
    }
}

const SHIPPED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../deploy/networks/");

fn trace(name: &str) -> String {
    std::fs::read_to_string(format!("{SHIPPED}{name}")).expect("a shipped trace")
}

/// Arrivals: `n` packets, one every `gap_us` microseconds from 0.123457 ms (so
/// within a millisecond, as mm-link's clock floors them), three of every ten sent
/// together at the first one's time (bursts), sizes cycling through `sizes`.
fn arrivals(n: usize, gap_us: u64, sizes: &[u32]) -> Vec<(u64, u32)> {
    (0..n)
        .map(|k| {
            let slot = if k % 10 < 3 { k - k % 10 } else { k } as u64;
            (123_457 + slot * gap_us * 1000, sizes[k % sizes.len()])
        })
        .collect()
}

fn reference(
    text: &str,
    kind: &'static str,
    bound: Bound,
    pkts: &[(u64, u32)],
) -> Vec<Option<u64>> {
    let schedule: Vec<u64> = text
        .lines()
        .map(|l| l.trim().parse().expect("ms"))
        .collect();
    let mut r = Reference {
        schedule,
        next_delivery: 0,
        base: 0,
        queue: VecDeque::new(),
        kind,
        packets_limit: bound.packets as usize,
        bytes_limit: bound.bytes,
        in_transit: None,
        in_transit_left: 0,
        out: Vec::new(),
    };
    for (id, &(t, size)) in pkts.iter().enumerate() {
        r.read_packet(id, t / 1_000_000, size);
    }
    // Far enough on for every packet queued to leave.
    r.rationalize(pkts.last().map_or(0, |p| p.0 / 1_000_000) + 3_600_000);
    r.out
}

fn ours(text: &str, queue: Box<dyn Queue>, pkts: &[(u64, u32)]) -> Vec<Option<u64>> {
    let ops = Opportunities::parse(text).expect("trace");
    let mut link = Link::new(Server::Trace(ops), queue, 1);
    let mut events = Vec::new();
    for (id, &(t, bytes)) in pkts.iter().enumerate() {
        let p = Packet {
            flow: 0,
            tag: id as u64,
            bytes,
            arrival_ns: t,
        };
        link.enqueue(p, &mut events);
    }
    let end = pkts.last().map_or(0, |p| p.0) + 3_600_000 * 1_000_000;
    link.advance(end, &mut events);
    let mut out = vec![None; pkts.len()];
    for e in events {
        if let Fate::Departed(at) = e.fate {
            assert!(
                out[e.packet.tag as usize].is_none(),
                "a packet departs once"
            );
            out[e.packet.tag as usize] = Some(at / 1_000_000);
        }
    }
    out
}

fn queue_of(kind: &str, bound: Bound) -> Box<dyn Queue> {
    match kind {
        "droptail" => Box::new(Fifo::drop_tail(bound)),
        "drophead" => Box::new(Fifo::drop_head(bound)),
        _ => Box::new(Fifo::infinite()),
    }
}

/// Per-packet departure times equal mm-link's on the shipped traces, for sizes that
/// divide 1504 (188, 376, 752, 1504) and that do not (278 = 250 + 28, 1000, 1400,
/// mixed), 20,000 packets each at a load above and below the traces' rates, through
/// the three disciplines.
#[test]
fn departures_equal_mm_links_on_the_shipped_traces() {
    let cases: [(&str, &[u32]); 8] = [
        ("188", &[188]),
        ("376", &[376]),
        ("752", &[752]),
        ("1504", &[1504]),
        ("278", &[278]),
        ("1000", &[1000]),
        ("1400", &[1400]),
        ("mixed", &[60, 1504, 278, 999, 1, 1400]),
    ];
    let kinds: [(&'static str, Bound); 4] = [
        ("infinite", Bound::default()),
        (
            "droptail",
            Bound {
                packets: 50,
                bytes: 0,
            },
        ),
        (
            "drophead",
            Bound {
                packets: 0,
                bytes: 30_000,
            },
        ),
        (
            "drophead",
            Bound {
                packets: 20,
                bytes: 20_000,
            },
        ),
    ];
    let mut compared = 0;
    for name in [
        "Verizon-LTE-short.up",
        "TMobile-UMTS-driving.down",
        "ATT-LTE-driving-2016.up",
    ] {
        let text = trace(name);
        for (label, sizes) in cases {
            for gap_us in [1000, 250] {
                let pkts = arrivals(20_000, gap_us, sizes);
                for (kind, bound) in kinds {
                    let want = reference(&text, kind, bound, &pkts);
                    let got = ours(&text, queue_of(kind, bound), &pkts);
                    let first = want.iter().zip(&got).position(|(w, g)| w != g);
                    assert_eq!(
                        first, None,
                        "{name} {label} every {gap_us} us {kind}: first difference"
                    );
                    compared += got.iter().flatten().count();
                }
            }
        }
    }
    assert!(compared > 1_000_000, "{compared} departures compared");
}

fn packet(tag: u64, bytes: u32, arrival_ns: u64) -> Packet {
    Packet {
        flow: 0,
        tag,
        bytes,
        arrival_ns,
    }
}

/// Drop-tail refuses the arrival that breaks a bound, drop-head pushes out the
/// oldest until the bounds hold; each bound alone and both.
#[test]
fn drop_tail_and_drop_head_keep_their_bounds() {
    let mut drops = Vec::new();
    let both = Bound {
        packets: 3,
        bytes: 250,
    };
    let mut tail = Fifo::drop_tail(both);
    let mut head = Fifo::drop_head(both);
    for (k, bytes) in [100, 100, 40, 100, 10].into_iter().enumerate() {
        tail.enqueue(packet(k as u64, bytes, 0), &mut drops);
    }
    // 100 + 100 + 40 fit; the 4th breaks bytes, the 5th (10 bytes) packets.
    let tags: Vec<u64> = drops.iter().map(|(p, _)| p.tag).collect();
    assert_eq!(tags, [3, 4]);
    assert!(drops.iter().all(|d| d.1 == DropCause::Tail));
    assert_eq!((tail.len_packets(), tail.len_bytes()), (3, 240));
    drops.clear();
    for (k, bytes) in [100, 100, 40, 100, 10].into_iter().enumerate() {
        head.enqueue(packet(k as u64, bytes, 0), &mut drops);
    }
    // The 4th pushes out the 1st (bytes); the 5th the 2nd (packets).
    let tags: Vec<u64> = drops.iter().map(|(p, _)| p.tag).collect();
    assert_eq!(tags, [0, 1]);
    assert!(drops.iter().all(|d| d.1 == DropCause::Head));
    assert_eq!((head.len_packets(), head.len_bytes()), (3, 150));
    let order: Vec<u64> = std::iter::from_fn(|| head.dequeue(0, &mut drops))
        .map(|p| p.tag)
        .collect();
    assert_eq!(order, [2, 3, 4]);
}

/// An infinite queue at overload grows to the memory cap and no further: each
/// arrival past it is dropped and counted apart, whatever the run's length.
#[test]
fn an_infinite_queue_stops_at_the_memory_cap() {
    let mut link = Link::new(Server::Rate(1e3), Box::new(Fifo::infinite()), 1);
    let mut events = Vec::new();
    let n = MAX_QUEUE_PACKETS as u64 + 50_000;
    for k in 0..n {
        link.enqueue(packet(k, 100, k * 1_000), &mut events);
        events.clear();
    }
    let s = link.stats(0);
    // 1 kbit/s: 100 bytes take 0.8 s, so one packet is in transit, none departed.
    assert_eq!(s.departed, 0);
    assert_eq!(link.queue().len_packets(), MAX_QUEUE_PACKETS);
    assert_eq!(s.dropped_cap, n - 1 - MAX_QUEUE_PACKETS as u64);
    assert_eq!(s.dropped, 0);
    assert_eq!(s.offered, n);
}

/// A rate server sends a packet of B bytes in 8 B / rate, back to back when the
/// queue holds more, from its arrival when it was idle.
#[test]
fn a_rate_server_serialises_at_its_rate() {
    let mut link = Link::new(Server::Rate(8e6), Box::new(Fifo::infinite()), 1);
    let mut events = Vec::new();
    // 1000 bytes at 8 Mbit/s: 1 ms each. Three at 0, one at 10 ms.
    for k in 0..3 {
        link.enqueue(packet(k, 1000, 0), &mut events);
    }
    link.enqueue(packet(3, 1000, 10_000_000), &mut events);
    link.advance(20_000_000, &mut events);
    let at: Vec<u64> = events
        .iter()
        .filter_map(|e| match e.fate {
            Fate::Departed(t) => Some(t / 1_000),
            Fate::Dropped(_) => None,
        })
        .collect();
    assert_eq!(at, [1_000, 2_000, 3_000, 11_000]);
    let s = link.stats(0);
    assert_eq!((s.delay_ns_max, s.delay_ns_sum), (3_000_000, 7_000_000));
}

/// A trace of too many lines is refused as it is read.
#[test]
fn a_trace_longer_than_the_limit_is_refused() {
    let text = "1\n".repeat(MAX_OPPORTUNITIES + 1);
    let e = Opportunities::parse(&text).expect_err("too long");
    assert_eq!(
        e.to_string(),
        format!(
            "line {}: more than 10000000 delivery opportunities",
            MAX_OPPORTUNITIES + 1
        )
    );
    assert!(Opportunities::parse("").is_err());
    assert!(Opportunities::parse("0\n0\n").is_err());
}

fn departures(server: Server, pkts: &[(u64, u32)]) -> Vec<u64> {
    let mut link = Link::new(server, Box::new(Fifo::infinite()), 1);
    let mut events = Vec::new();
    for (k, &(t, bytes)) in pkts.iter().enumerate() {
        link.enqueue(packet(k as u64, bytes, t), &mut events);
    }
    link.advance(u64::MAX / 2, &mut events);
    events
        .iter()
        .filter_map(|e| match e.fate {
            Fate::Departed(t) => Some(t),
            Fate::Dropped(_) => None,
        })
        .collect()
}

/// A rate over time: one constant step is the fixed rate, packet for packet; an
/// outage (a step of 0) holds the packet in transit, which finishes when the rate
/// comes back; the file's mistakes are named by line.
#[test]
fn a_rate_over_time_serves_as_its_steps_say() {
    let pkts = arrivals(10_000, 250, &[278, 1400, 60]);
    let fixed = departures(Server::Rate(3e6), &pkts);
    let steps = RateSteps::parse("time_ms,rate_bps\n0,3e6\n").expect("steps");
    assert_eq!(departures(Server::Steps(steps), &pkts), fixed);
    // 1500 bytes at 8 Mbit/s take 1.5 ms: 1 ms sent, 2 ms of nothing, 0.5 ms more.
    let outage = RateSteps::parse("time_ms,rate_bps\n0,8e6\n1,0\n3,8e6\n").expect("steps");
    let at = departures(Server::Steps(outage), &[(0, 1500), (0, 1000)]);
    assert_eq!(at, [3_500_000, 4_500_000]);
    for (text, want) in [
        (
            "t,r\n0,1\n",
            "line 1: header is \"t,r\", expected time_ms,rate_bps",
        ),
        (
            "time_ms,rate_bps\n5,1\n",
            "line 2: \"5,1\": the first row's time_ms must be 0",
        ),
        (
            "time_ms,rate_bps\n0,1\n3,2\n3,1\n",
            "line 4: \"3,1\": time_ms does not increase",
        ),
        (
            "time_ms,rate_bps\n0,-1\n",
            "line 2: \"0,-1\": rate_bps is outside 0..=1e12",
        ),
        (
            "time_ms,rate_bps\n0,nan\n",
            "line 2: \"0,nan\": rate_bps is outside 0..=1e12",
        ),
        (
            "time_ms,rate_bps\n0,1\n2,0\n",
            "the last rate is 0: the link would stop for good",
        ),
        ("time_ms,rate_bps\n", "no rates after the header"),
    ] {
        let e = RateSteps::parse(text).expect_err(text);
        assert_eq!(e.to_string(), want, "{text}");
    }
}
