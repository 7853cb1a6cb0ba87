//! A block of samples, stored as columns: how a record gets from 1.1 kB to a few tens
//! of bytes a sample without losing a bit.
//!
//! Each sample is one row: its bincode encoding with fixed-width integers, so a field
//! sits at the same byte offset in every row of the same shape (the same variant, the
//! same options present), and rows are grouped by length. A group's first row is kept
//! as it is; every later row is XORed with the one before it (a value that did not
//! change becomes zeros, a slowly changing one keeps only its low bytes) and those
//! deltas are transposed into byte planes: plane `j` holds byte `j` of every later row,
//! so an exponent, a flag or a counter's high bytes sit together. Planes of zeros (a
//! byte that stays as the first row has it) are left out, a bitmap says which, and
//! LZ4 codes the rest (its block format: the planes' runs and repeats as matches, the
//! other bytes as they are). Every step is exact: the rows come back byte for byte.
//!
//! LZ4 rather than zstd (format 13): on the million-sample run's blocks zstd at its
//! fastest level made them 2 to 9 % smaller and took 1.4 to 1.7 times as long, and the
//! records were half the simulation's time (docs/06 measures both). The reference C
//! library writes the blocks, at an acceleration lz4_flex does not offer; lz4_flex
//! reads them ([`pack`] says why).
//!
//! A block is self-contained (each group starts from its first row), so damage to one
//! block costs that block alone.

use thiserror::Error;
use wide::u8x16;

/// A packed block that cannot be unpacked: damage, or another build's writer.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("a damaged sample block: {0}")]
pub struct BlockError(&'static str);

/// Largest unpacked block a reader accepts (a whole frame's rows can claim no more).
pub const MAX_RAW: usize = 64 << 20;

/// Most rows a block may hold: 16 times a writer's at the highest rate a scenario
/// allows (2 rows a sample for 50 ms at 10 kHz), and writers hold no more at any rate
/// ([`crate::recorder::block_rows`]). A reader holds a block's samples at once: a
/// crafted block cannot make it hold more than this many.
pub const MAX_ROWS: usize = 1 << 14;

/// Appends `v` as a LEB128 varint.
fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Reads a LEB128 varint at `*at`, moving past it.
fn get_varint(b: &[u8], at: &mut usize) -> Result<u64, BlockError> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let byte = *b.get(*at).ok_or(BlockError("cut inside a length"))?;
        *at += 1;
        v |= u64::from(byte & 0x7f) << shift;
        if byte & 0x80 == 0 {
            return Ok(v);
        }
    }
    Err(BlockError("a length of more than 64 bits"))
}

/// Groups a block finds by looking through them; past this many, by a hash map (a
/// crafted block of thousands of lengths must not cost a search through them all
/// for each row). A node's rows have one to four shapes.
const FEW_GROUPS: usize = 8;

/// The distinct row lengths in order of first appearance, with the rows (their start
/// offsets) of each.
fn groups(lens: &[usize]) -> Vec<(usize, Vec<usize>)> {
    let mut out: Vec<(usize, Vec<usize>)> = Vec::new();
    let mut index: Option<std::collections::HashMap<usize, usize>> = None;
    let mut at = 0;
    for &l in lens {
        let found = match &index {
            Some(ix) => ix.get(&l).copied(),
            None => out.iter().position(|(g, _)| *g == l),
        };
        let k = found.unwrap_or_else(|| {
            out.push((l, Vec::new()));
            if let Some(ix) = &mut index {
                ix.insert(l, out.len() - 1);
            } else if out.len() > FEW_GROUPS {
                index = Some(out.iter().enumerate().map(|(k, (g, _))| (*g, k)).collect());
            }
            out.len() - 1
        });
        out[k].1.push(at);
        at += l;
    }
    out
}

/// Lays out `rows` (concatenated, `lens` long each) per group as its first row, then
/// the later rows' XOR deltas as transposed byte planes with zero planes left out: the
/// bytes LZ4 then compresses. `scratch` is reused.
pub fn to_planes(rows: &[u8], lens: &[usize], out: &mut Vec<u8>, scratch: &mut Vec<u8>) {
    put_varint(out, lens.len() as u64);
    for &l in lens {
        put_varint(out, l as u64);
    }
    for (len, starts) in groups(lens) {
        let first = &rows[starts[0]..starts[0] + len];
        out.extend_from_slice(first);
        // A column's plane is all zeros exactly when every row has the first row's
        // byte there: one pass that only reads (the compiler vectorises it) finds the
        // planes kept, and the deltas are then worked out only where they are kept,
        // straight from the rows.
        scratch.clear();
        scratch.resize(len, 0);
        for &s in &starts[1..] {
            for ((o, a), b) in scratch.iter_mut().zip(&rows[s..s + len]).zip(first) {
                *o |= a ^ b;
            }
        }
        let any = &scratch[..];
        let r = starts.len() - 1;
        let kept = any.iter().filter(|a| **a != 0).count();
        let bitmap_at = out.len();
        let planes_at = bitmap_at + len.div_ceil(8);
        out.resize(planes_at + kept * r, 0);
        let (head, planes) = out.split_at_mut(planes_at);
        let bitmap = &mut head[bitmap_at..];
        // Eight columns at a time: their byte of the bitmap (which comes before all
        // the planes), and their kept planes after those of the columns before them.
        let mut at = 0;
        for (c0, any) in (0..len).step_by(8).zip(any.chunks(8)) {
            let mask = any
                .iter()
                .enumerate()
                .fold(0u8, |m, (j, a)| m | (u8::from(*a != 0) << j));
            bitmap[c0 / 8] = mask;
            let n = mask.count_ones() as usize;
            let here = &mut planes[at..at + n * r];
            at += n * r;
            let run = Run {
                rows,
                starts: &starts,
                c0,
                mask,
            };
            if any.len() == 8 && n >= TILE_PLANES {
                run.by_tiles(here);
            } else {
                run.by_bytes(0, here);
            }
        }
    }
}

/// Kept planes, of a run of eight columns, from which the run goes by tiles. A tile
/// moves all eight columns, kept or not. With 16-row tiles in vector registers, 1 and
/// 2 measured the same on a real run's rows and 4 took 20 % longer (docs/06).
const TILE_PLANES: usize = 2;

/// Eight columns `c0..c0 + 8` of a group's rows (those past the rows' end are never
/// read), and `mask` of those whose planes are kept (bit `j`: column `c0 + j`).
struct Run<'a> {
    rows: &'a [u8],
    starts: &'a [usize],
    c0: usize,
    mask: u8,
}

impl Run<'_> {
    /// The run's eight bytes of row `i` (of `starts`), as a little-endian word.
    fn word(&self, i: usize) -> u64 {
        let at = self.starts[i] + self.c0;
        let mut b = [0u8; 8];
        b.copy_from_slice(&self.rows[at..at + 8]);
        u64::from_le_bytes(b)
    }

    /// The kept planes into `out` one after another (each a plane's `r` bytes),
    /// [`TILE_ROWS`] rows at a time as tiles of deltas transposed in vector registers,
    /// the rows past the last whole tile byte by byte. Needs all eight columns in the
    /// rows.
    fn by_tiles(&self, out: &mut [u8]) {
        let r = self.starts.len() - 1;
        let whole = r / TILE_ROWS * TILE_ROWS;
        let mut prev = self.word(0);
        for i0 in (0..whole).step_by(TILE_ROWS) {
            let mut deltas = [0u64; TILE_ROWS];
            for (t, delta) in deltas.iter_mut().enumerate() {
                let row = self.word(i0 + t + 1);
                *delta = row ^ prev;
                prev = row;
            }
            let columns = transpose(deltas);
            let mut n = 0;
            for (j, column) in columns.iter().enumerate() {
                if self.mask & (1 << j) != 0 {
                    out[n * r + i0..n * r + i0 + TILE_ROWS].copy_from_slice(column.as_array_ref());
                    n += 1;
                }
            }
        }
        self.by_bytes(whole, out);
    }

    /// Rows `from..r` of the kept planes (each `r` long, one after another in `out`),
    /// a byte at a time.
    fn by_bytes(&self, from: usize, out: &mut [u8]) {
        let r = self.starts.len() - 1;
        let kept = (0..8).filter(|j| self.mask & (1 << j) != 0);
        for (n, j) in kept.enumerate() {
            let c = self.c0 + j;
            let pairs = self.starts[from..].windows(2);
            for (o, pair) in out[n * r + from..(n + 1) * r].iter_mut().zip(pairs) {
                *o = self.rows[pair[1] + c] ^ self.rows[pair[0] + c];
            }
        }
    }
}

/// Rows a tile holds: one vector register's bytes.
const TILE_ROWS: usize = 16;

/// 16 rows of eight bytes (little-endian words) transposed: vector `j` holds byte `j`
/// of each row, in order. Four rounds of byte interleaving (SSE2's `punpcklbw` and
/// `punpckhbw`, NEON's `zip`), each pairing vector `k` with vector `k + 4` (the first,
/// row `k` with row `k + 8`): 32 shuffles for 128 bytes, where 8-by-8 tiles in `u64`
/// registers took about 70 operations for 64.
fn transpose(rows: [u64; TILE_ROWS]) -> [u8x16; 8] {
    let low = |w: u64| {
        let mut b = [0u8; 16];
        b[..8].copy_from_slice(&w.to_le_bytes());
        u8x16::new(b)
    };
    let mut v: [u8x16; 8] =
        std::array::from_fn(|k| u8x16::unpack_low(low(rows[k]), low(rows[k + 8])));
    for _ in 0..3 {
        v = std::array::from_fn(|m| {
            let (a, b) = (v[m / 2], v[m / 2 + 4]);
            if m % 2 == 0 {
                u8x16::unpack_low(a, b)
            } else {
                u8x16::unpack_high(a, b)
            }
        });
    }
    v
}

/// The rows back from [`to_planes`]'s bytes: concatenated, with their lengths; a block
/// of other than `rows` rows is refused before anything is allocated for it.
pub fn from_planes(b: &[u8], rows: u32) -> Result<(Vec<u8>, Vec<usize>), BlockError> {
    let mut at = 0;
    let count = get_varint(b, &mut at)?;
    if count != u64::from(rows) {
        return Err(BlockError("not the rows its entry says"));
    }
    let count = count as usize;
    if count > b.len() || count > MAX_ROWS {
        return Err(BlockError("more rows than a block may hold"));
    }
    let mut lens = Vec::with_capacity(count);
    let mut total = 0usize;
    for _ in 0..count {
        let l = get_varint(b, &mut at)? as usize;
        total = total.saturating_add(l);
        lens.push(l);
    }
    if total > MAX_RAW {
        return Err(BlockError("rows longer than a block may be"));
    }
    // Each group's first row and bitmap must be there before the rows are allocated.
    let groups = groups(&lens);
    let least = groups.iter().fold(0usize, |n, (len, _)| {
        n.saturating_add(len + len.div_ceil(8))
    });
    if least > b.len() - at {
        return Err(BlockError("shorter than its rows' first rows"));
    }
    let mut out = vec![0u8; total];
    for (len, starts) in groups {
        let first = b
            .get(at..at + len)
            .ok_or(BlockError("cut inside a first row"))?;
        at += len;
        // Every row starts as the first; the planes then say where later rows differ.
        for &s in &starts {
            out[s..s + len].copy_from_slice(first);
        }
        let bitmap = b
            .get(at..at + len.div_ceil(8))
            .ok_or(BlockError("cut inside a bitmap"))?;
        at += bitmap.len();
        let later = &starts[1..];
        for (j, &first_byte) in first.iter().enumerate() {
            if bitmap[j / 8] & (1 << (j % 8)) == 0 {
                continue;
            }
            let plane = b
                .get(at..at + later.len())
                .ok_or(BlockError("cut inside a plane"))?;
            at += plane.len();
            let mut prev = first_byte;
            for (&s, &x) in later.iter().zip(plane) {
                prev ^= x;
                out[s + j] = prev;
            }
        }
    }
    if at != b.len() {
        return Err(BlockError("bytes after the last plane"));
    }
    Ok((out, lens))
}

/// LZ4's acceleration for a block: it looks for matches at fewer places, trading a
/// little size for time. On the 200,000-sample run's rows (the `block_sizes` example)
/// 1 (LZ4's default) gave 189.6 bytes a sample, 3 gave 194.3 in two thirds of the
/// time, 6 gave 201.0 (docs/06).
pub const ACCELERATION: i32 = 3;

/// Packs rows: planes, then LZ4 into `packed` (cleared first). Returns the planes'
/// length, which the reader needs to unpack them.
///
/// The reference C library compresses (at [`ACCELERATION`]); lz4_flex, in Rust,
/// decompresses: the block format is the same, and what a reader takes from a file it
/// did not write goes through safe code.
pub fn pack(
    rows: &[u8],
    lens: &[usize],
    planes: &mut Vec<u8>,
    scratch: &mut Vec<u8>,
    packed: &mut Vec<u8>,
) -> std::io::Result<u32> {
    planes.clear();
    to_planes(rows, lens, planes, scratch);
    let raw = u32::try_from(planes.len()).map_err(std::io::Error::other)?;
    packed.clear();
    packed.resize(lz4::block::compress_bound(planes.len())?, 0);
    let mode = lz4::block::CompressionMode::FAST(ACCELERATION);
    let n = lz4::block::compress_to_buffer(planes, Some(mode), false, packed)?;
    packed.truncate(n);
    Ok(raw)
}

/// Unpacks [`pack`]'s bytes back into rows and their lengths; planes of other than
/// `raw_len` bytes are refused.
pub fn unpack(rows: u32, raw_len: u32, packed: &[u8]) -> Result<(Vec<u8>, Vec<usize>), BlockError> {
    if raw_len as usize > MAX_RAW {
        return Err(BlockError("longer than a block may be"));
    }
    // An LZ4 length byte stands for at most 255 bytes: a claim past that is refused
    // before the planes are allocated.
    if raw_len as usize > packed.len().saturating_mul(255).saturating_add(64) {
        return Err(BlockError("longer than its packed bytes can hold"));
    }
    let mut planes = vec![0u8; raw_len as usize];
    let n = lz4_flex::block::decompress_into(packed, &mut planes)
        .map_err(|_| BlockError("LZ4 could not decompress it"))?;
    if n != planes.len() {
        return Err(BlockError("not the length it claims"));
    }
    from_planes(&planes, rows)
}

#[cfg(test)]
#[path = "block_tests.rs"]
mod tests;
