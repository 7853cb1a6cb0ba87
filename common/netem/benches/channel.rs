//! What a channel costs a sample: the zero-delay channel of a lockstep run (each
//! in-process sample crosses two), and a 20-sample delay with noise.
//!
//! `cargo bench -p tactile-netem --bench channel`

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use tactile_netem::channel::{Channel, Value};
use tactile_scenario::ChannelConfig;

/// A channel of `cfg` driven for `n` samples along a smooth signal.
fn drive(cfg: &ChannelConfig, n: u64) -> f64 {
    let mut ch = Channel::new(cfg, 7, tactile_netem::channel::FORWARD_STREAM);
    let mut sum = 0.0;
    for seq in 0..n {
        let v = Value {
            v: (seq as f64 * 1e-3).sin(),
            sent_seq: seq,
            origin_seq: seq,
            origin_ns: seq * 1_000_000,
            ..Value::default()
        };
        sum += ch.push(seq, black_box([v; 3])).values[0].v;
    }
    sum
}

fn channel(c: &mut Criterion) {
    let mut g = c.benchmark_group("channel");
    let zero = ChannelConfig::default();
    g.bench_function("zero_delay_1000", |b| b.iter(|| drive(&zero, 1000)));
    let delayed = ChannelConfig {
        delay: [20; 3],
        noise_std: [1e-4; 3],
        ..ChannelConfig::default()
    };
    g.bench_function("delay_20_noise_1000", |b| b.iter(|| drive(&delayed, 1000)));
    g.finish();
}

criterion_group!(benches, channel);
criterion_main!(benches);
