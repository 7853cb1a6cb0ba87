//! What other block codings would make of a run's real rows: bytes a sample and time,
//! against format 14's (XOR deltas, byte planes, LZ4). It reads a run's three records,
//! encodes their samples back into rows as the writer does, cuts them into the
//! writer's blocks and codes each block every way:
//!
//! - `format 14`: [`block::pack`], what the files hold;
//! - `planes`: the planes alone, no LZ4;
//! - `xor words`: each row XORed with the row of its shape before it, then each 8-byte
//!   word as a byte saying which of its bytes are not zero, and those bytes (the
//!   cheapest coding that knows nothing but the row's layout);
//! - `xor words + lz4`: the same, then LZ4.
//!
//! `cargo run --release -p tactile-records --example block_sizes -- DIR [RATE_HZ]`
//! on the folder of a run (docs/06 measures the million-sample lockstep run's).

use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;
use tactile_messages::Role;
use tactile_records::{block, file, record_path, Record, RecordReader};

/// The codings compared, in the order printed.
const CODINGS: [&str; 4] = ["format 14", "planes", "xor words", "xor words + lz4"];

/// Bytes and nanoseconds per coding, summed over blocks.
type Tally = [(u64, u128); 4];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(dir) = args.get(1) else {
        eprintln!("usage: block_sizes DIR [RATE_HZ]");
        std::process::exit(2);
    };
    let rate: f64 = args.get(2).and_then(|r| r.parse().ok()).unwrap_or(1000.0);
    let dir = Path::new(dir);
    let (master, samples) = tally::<
        tactile_records::master::MasterSample,
        tactile_records::master::MasterTotals,
    >(dir, Role::Master, rate);
    let (emulator, _) = tally::<
        tactile_records::emulator::Passage,
        tactile_records::emulator::EmulatorTotals,
    >(dir, Role::Emulator, rate);
    let (slave, _) = tally::<
        tactile_records::slave::SlaveSample,
        tactile_records::slave::SlaveTotals,
    >(dir, Role::Slave, rate);
    // The master writes a `Sent` row and an answer or miss row a sample.
    let n = (samples / 2).max(1) as f64;
    println!("{samples} master rows, {n} samples");
    println!(
        "{:<16} {:>8} {:>8} {:>8} {:>8} {:>10}",
        "coding", "master", "emul.", "slave", "B/sample", "ns/sample"
    );
    for (k, name) in CODINGS.iter().enumerate() {
        let bytes = [master[k].0, emulator[k].0, slave[k].0].map(|b| b as f64 / n);
        let ns = (master[k].1 + emulator[k].1 + slave[k].1) as f64 / n;
        println!(
            "{name:<16} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>10.0}",
            bytes[0],
            bytes[1],
            bytes[2],
            bytes.iter().sum::<f64>(),
            ns
        );
    }
}

/// Codes `role`'s record in `dir` every way: the tallies, and the rows read.
fn tally<S, C>(dir: &Path, role: Role, rate: f64) -> (Tally, usize)
where
    S: Serialize + DeserializeOwned,
    C: DeserializeOwned,
{
    let path = record_path(dir, role);
    let mut reader = match RecordReader::<Record<S, C>>::open(&path) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let per_block = tactile_records::recorder::block_rows(role, rate);
    let (mut rows, mut lens, mut count) = (file::Rows::default(), Vec::new(), 0);
    let mut t: Tally = [(0, 0); 4];
    let mut buffers = Buffers::default();
    let mut code = |rows: &mut file::Rows, lens: &mut Vec<usize>| {
        if !lens.is_empty() {
            block_tally(rows.as_slice(), lens, &mut buffers, &mut t);
        }
        rows.clear();
        lens.clear();
    };
    while let Ok(Some(r)) = reader.next_record() {
        if let Record::Sample(s) = r {
            lens.push(rows.append(&s).unwrap_or(0));
            count += 1;
            if lens.len() == per_block {
                code(&mut rows, &mut lens);
            }
        }
    }
    code(&mut rows, &mut lens);
    (t, count)
}

/// The buffers the codings write into, kept from block to block as the writer keeps
/// its own, so no coding's time includes growing them.
#[derive(Default)]
struct Buffers {
    planes: Vec<u8>,
    scratch: Vec<u8>,
    packed: Vec<u8>,
    words: Vec<u8>,
}

/// Adds one block's bytes and time under each coding to `t`.
fn block_tally(rows: &[u8], lens: &[usize], b: &mut Buffers, t: &mut Tally) {
    let at = Instant::now();
    let _ = block::pack(rows, lens, &mut b.planes, &mut b.scratch, &mut b.packed);
    t[0].1 += at.elapsed().as_nanos();
    t[0].0 += b.packed.len() as u64;
    let at = Instant::now();
    b.planes.clear();
    block::to_planes(rows, lens, &mut b.planes, &mut b.scratch);
    t[1].1 += at.elapsed().as_nanos();
    t[1].0 += b.planes.len() as u64;
    // Timed on its own, then again with LZ4 after it.
    let at = Instant::now();
    xor_words(rows, lens, &mut b.words);
    t[2].1 += at.elapsed().as_nanos();
    t[2].0 += b.words.len() as u64;
    let at = Instant::now();
    xor_words(rows, lens, &mut b.words);
    b.packed.clear();
    b.packed
        .resize(lz4_flex::block::get_maximum_output_size(b.words.len()), 0);
    let n = lz4_flex::block::compress_into(&b.words, &mut b.packed).unwrap_or(0);
    t[3].1 += at.elapsed().as_nanos();
    t[3].0 += n as u64;
}

/// Each row XORed with the last row of its length, as 8-byte words: a mask byte of
/// the word's bytes that are not zero, then those bytes.
fn xor_words(rows: &[u8], lens: &[usize], out: &mut Vec<u8>) {
    out.clear();
    let mut last: Vec<(usize, usize)> = Vec::new();
    let mut at = 0;
    for &l in lens {
        let k = match last.iter().position(|(len, _)| *len == l) {
            Some(k) => k,
            None => {
                last.push((l, usize::MAX));
                last.len() - 1
            }
        };
        let prev = Some(last[k].1).filter(|&s| s != usize::MAX);
        for w in (0..l).step_by(8) {
            let end = (w + 8).min(l);
            let mut x = [0u8; 8];
            x[..end - w].copy_from_slice(&rows[at + w..at + end]);
            let mut word = u64::from_le_bytes(x);
            if let Some(p) = prev {
                x = [0; 8];
                x[..end - w].copy_from_slice(&rows[p + w..p + end]);
                word ^= u64::from_le_bytes(x);
            }
            let bytes = word.to_le_bytes();
            let mask = bytes
                .iter()
                .enumerate()
                .fold(0u8, |m, (k, b)| m | (u8::from(*b != 0) << k));
            out.push(mask);
            out.extend(bytes.iter().filter(|b| **b != 0));
        }
        last[k].1 = at;
        at += l;
    }
}
