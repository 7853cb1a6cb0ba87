//! What a block of samples costs to pack and unpack: the rows of one 50 ms block of
//! the master's record (50 samples at 1 kHz, a `Sent` and an `Answer` each) along a
//! smooth trajectory, as [`tactile_records::file`] lays them out.
//!
//! `cargo bench -p tactile-records --bench blocks`

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use tactile_records::master::{Answer, MasterSample, Sent};
use tactile_records::{block, file};

/// The samples of one block.
fn samples() -> Vec<MasterSample> {
    let mut out = Vec::new();
    for n in 0..50u64 {
        let t = n as f64 * 1e-3;
        let at = |k: f64| {
            [
                0.05 * (t + k).sin(),
                0.04 * (2.0 * t + k).cos(),
                -0.1 + 0.01 * t,
            ]
        };
        let mut answer = Answer {
            n,
            round_trip_ns: 41_000 + n % 7,
            ..Answer::default()
        };
        answer.q.value = at(0.3);
        answer.q.origin_seq = [n; 3];
        answer.q.origin_ns = [1_000_000 * n; 3];
        answer.effect.tau = at(0.7);
        answer.effect.felt = at(0.9);
        let sent = Sent {
            n,
            target: at(0.0),
            theta_md: at(0.1),
            c: at(0.2),
            handle: at(0.0),
            tick_ns: 1_000_000 * n,
            send_ns: 1_000_000 * n + 900,
            ..Sent::default()
        };
        out.extend([MasterSample::Sent(sent), MasterSample::Answer(answer)]);
    }
    out
}

/// Encodes samples into rows as the writer does: concatenated, with their lengths.
fn encode(samples: &[MasterSample], rows: &mut file::Rows, lens: &mut Vec<usize>) {
    for s in samples {
        lens.push(rows.append(s).expect("encode"));
    }
}

fn blocks(c: &mut Criterion) {
    let samples = samples();
    let (mut encoded, mut lens) = (file::Rows::default(), Vec::new());
    encode(&samples, &mut encoded, &mut lens);
    let rows = encoded.as_slice().to_vec();
    let mut g = c.benchmark_group("block");
    g.throughput(Throughput::Bytes(rows.len() as u64));
    let (mut r, mut l) = (file::Rows::default(), Vec::new());
    g.bench_function("encode", |b| {
        b.iter(|| {
            r.clear();
            l.clear();
            encode(black_box(&samples), &mut r, &mut l);
        })
    });
    let (mut planes, mut scratch) = (Vec::new(), Vec::new());
    g.bench_function("to_planes", |b| {
        b.iter(|| {
            planes.clear();
            block::to_planes(black_box(&rows), &lens, &mut planes, &mut scratch);
        })
    });
    let mut packed = Vec::new();
    g.bench_function("pack", |b| {
        b.iter(|| {
            block::pack(
                black_box(&rows),
                &lens,
                &mut planes,
                &mut scratch,
                &mut packed,
            )
        })
    });
    // Format 13's coder on the same planes, for the comparison docs/06 makes.
    let mut z = zstd::bulk::Compressor::new(-1).expect("zstd");
    g.bench_function("pack_zstd_format_13", |b| {
        b.iter(|| {
            planes.clear();
            block::to_planes(black_box(&rows), &lens, &mut planes, &mut scratch);
            z.compress(&planes)
        })
    });
    let raw = block::pack(&rows, &lens, &mut planes, &mut scratch, &mut packed).expect("pack");
    g.bench_function("unpack", |b| {
        b.iter(|| block::unpack(lens.len() as u32, raw, black_box(&packed)))
    });
    g.finish();
}

criterion_group!(benches, blocks);
criterion_main!(benches);
