//! What a link with FQ-CoDel costs a sample with four cross flows at 90 % load: the
//! 1 kHz haptic flow (278 bytes) and four Poisson flows of 1,000-byte packets
//! (1.695 Mbit/s each) on 10 Mbit/s; each sample runs the link to its time, puts the
//! cross packets that arrived since the last one on it in time order, then the
//! haptic packet (what the channel will do with cross traffic). Prints each sample's
//! cost's p50, p99 and p99.9 over 10^5 samples, then criterion's mean of 1,000.
//!
//! `cargo bench -p tactile-netem --bench link`

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;
use tactile_netem::link::{Event, FqCodel, FqCodelParams, Link, Packet, Server};

/// The link, its cross flows' next arrivals and their random stream.
struct Bench {
    link: Link,
    next: [f64; 4],
    rng: ChaCha8Rng,
    events: Vec<Event>,
    seq: u64,
}

/// Mean gap of a 1.695 Mbit/s flow of 1,000-byte packets, ns.
const GAP_NS: f64 = 8_000.0 / 1.695e6 * 1e9;

impl Bench {
    fn new() -> Bench {
        let mut rng = ChaCha8Rng::seed_from_u64(68);
        let next = [0; 4].map(|_| -GAP_NS * (1.0 - rng.random::<f64>()).ln());
        Bench {
            link: Link::new(
                Server::Rate(1e7),
                Box::new(FqCodel::new(FqCodelParams::default())),
                5,
            ),
            next,
            rng,
            events: Vec::with_capacity(64),
            seq: 0,
        }
    }

    /// One sample: the cross packets up to its time, then the haptic one.
    fn sample(&mut self) -> usize {
        let now = self.seq * 1_000_000;
        self.events.clear();
        loop {
            let (k, t) = self
                .next
                .iter()
                .copied()
                .enumerate()
                .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
            if t as u64 > now {
                break;
            }
            let p = Packet {
                flow: k as u32 + 1,
                tag: 0,
                bytes: 1000,
                arrival_ns: t as u64,
            };
            self.link.enqueue(p, &mut self.events);
            self.next[k] = t - GAP_NS * (1.0 - self.rng.random::<f64>()).ln();
        }
        let p = Packet {
            flow: 0,
            tag: self.seq,
            bytes: 278,
            arrival_ns: now,
        };
        self.link.enqueue(p, &mut self.events);
        self.seq += 1;
        self.events.len()
    }
}

fn link(c: &mut Criterion) {
    let mut b = Bench::new();
    let mut costs: Vec<u64> = (0..100_000)
        .map(|_| {
            let t = Instant::now();
            black_box(b.sample());
            t.elapsed().as_nanos() as u64
        })
        .collect();
    costs.sort_unstable();
    let q = |f: f64| costs[((costs.len() as f64 * f) as usize).min(costs.len() - 1)];
    let s = b.link.stats(0);
    eprintln!(
        "per sample, 10^5 samples: p50 {} ns, p99 {} ns, p99.9 {} ns; haptic flow {} departed, {} dropped",
        q(0.5),
        q(0.99),
        q(0.999),
        s.departed,
        s.dropped
    );
    let mut g = c.benchmark_group("link");
    g.bench_function("fq_codel_4_cross_90pct_1000", |bn| {
        bn.iter(|| {
            for _ in 0..1000 {
                black_box(b.sample());
            }
        })
    });
    g.finish();
}

criterion_group!(benches, link);
criterion_main!(benches);
