//! Resynchronisation: the same frames and damage as reading every candidate afresh,
//! in work linear in the file's size, and a stop request honoured while damage is
//! read through.

use super::*;
use proptest::prelude::*;

/// The frames (offset, body length) and damaged stretches of `bytes`, found as the
/// reader did before it read ahead: each candidate sync word checked by reading its
/// whole claimed body. The reference the reader must agree with.
fn reference(bytes: &[u8]) -> (Vec<(u64, usize)>, Vec<Damage>) {
    let n = bytes.len();
    let whole = |at: usize| -> Option<usize> {
        let h = bytes.get(at..at + HEADER)?;
        let len = u32::from_le_bytes([h[4], h[5], h[6], h[7]]);
        let crc = u32::from_le_bytes([h[8], h[9], h[10], h[11]]);
        let body = bytes.get(at + HEADER..at + HEADER + len as usize)?;
        (h[..4] == SYNC && len <= MAX_FRAME && crc32fast::hash(body) == crc).then_some(len as usize)
    };
    let (mut frames, mut damage) = (Vec::new(), Vec::new());
    let mut at = MAGIC.len();
    while at < n {
        let (start, len) = match whole(at) {
            Some(len) => (at, len),
            None => (at + 1..n)
                .find_map(|c| whole(c).map(|l| (c, l)))
                .unwrap_or((n, 0)),
        };
        if start > at {
            damage.push(Damage {
                offset: at as u64,
                bytes: (start - at) as u64,
            });
        }
        if start >= n {
            break;
        }
        frames.push((start as u64, len));
        at = start + HEADER + len;
    }
    (frames, damage)
}

/// What the reader finds in the file at `path`, and the bytes it read.
fn read(path: &Path) -> (Vec<(u64, usize)>, Vec<Damage>, u64) {
    let mut r = Frames::open(path).expect("open");
    let mut frames = Vec::new();
    while r.next_frame(&|| false).expect("read") == Next::Frame {
        let len = r.body.len();
        frames.push((r.offset - (HEADER + len) as u64, len));
    }
    let (bytes, stretches) = (r.damaged_bytes, r.damaged_stretches);
    let total: u64 = r.damage.iter().map(|d| d.bytes).sum();
    if stretches as usize <= MAX_KEPT_DAMAGE {
        assert_eq!((r.damage.len() as u64, total), (stretches, bytes));
    }
    (frames, r.damage, r.bytes_read)
}

/// Writes `bytes` as a record and reads it ([`read`]), checking the work linear: at
/// most twice the file's bytes read.
fn read_linear(bytes: &[u8]) -> (Vec<(u64, usize)>, Vec<Damage>) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    std::fs::write(&path, bytes).expect("write");
    let (frames, damage, read_bytes) = read(&path);
    let len = bytes.len() as u64;
    assert!(
        read_bytes <= 2 * len,
        "{read_bytes} bytes read of a {len}-byte file"
    );
    (frames, damage)
}

/// A frame header claiming `len` bytes with checksum `crc`.
fn header(len: u32, crc: u32) -> Vec<u8> {
    let mut h = SYNC.to_vec();
    h.extend_from_slice(&len.to_le_bytes());
    h.extend_from_slice(&crc.to_le_bytes());
    h
}

/// Issue 65's record: sync words back to back, each claiming a whole frame's
/// length, then room for their claims and one whole frame. Reading it used to cost
/// a megabyte of reading and a CRC per sync word; now at most twice the file.
#[test]
fn sync_words_claiming_a_megabyte_each_cost_linear_work() {
    let mut bytes = MAGIC.to_vec();
    let words = 2000;
    for _ in 0..words {
        bytes.extend(header(MAX_FRAME, 0));
    }
    bytes.resize(bytes.len() + MAX_FRAME as usize, 0x5A);
    let garbage = bytes.len() as u64 - MAGIC.len() as u64;
    bytes.extend(frame(b"the one whole frame"));
    let (frames, damage) = read_linear(&bytes);
    assert_eq!(frames, vec![(MAGIC.len() as u64 + garbage, 19)]);
    assert_eq!(
        damage,
        vec![Damage {
            offset: MAGIC.len() as u64,
            bytes: garbage
        }]
    );
}

/// The same shape between every two whole frames: each costs its own bytes, not a
/// megabyte (a sync word claiming a megabyte before every frame).
#[test]
fn a_false_sync_word_before_every_frame_costs_linear_work() {
    let mut bytes = MAGIC.to_vec();
    let mut want = Vec::new();
    for k in 0..3000u32 {
        bytes.extend(header(MAX_FRAME, k));
        want.push((bytes.len() as u64, 4));
        bytes.extend(frame(&k.to_le_bytes()));
    }
    bytes.resize(bytes.len() + MAX_FRAME as usize, 0);
    let (frames, damage) = read_linear(&bytes);
    assert_eq!(frames, want);
    let (_, mut stretches) = reference(&bytes);
    assert_eq!(
        stretches.len(),
        3001,
        "each false word, and the zeros at the end"
    );
    stretches.truncate(MAX_KEPT_DAMAGE);
    assert_eq!(damage, stretches);
}

/// A stop request while damage is read through: the reader says so, and asked again
/// goes on to the same frames as a reading never stopped.
#[test]
fn a_stop_request_is_honoured_inside_damage_and_reading_resumes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    let mut bytes = MAGIC.to_vec();
    bytes.extend(frame(b"first"));
    bytes.resize(bytes.len() + 3 * CHUNK + 17, 0xA5);
    bytes.extend(frame(b"second"));
    std::fs::write(&path, &bytes).expect("write");
    let mut r = Frames::open(&path).expect("open");
    assert_eq!(r.next_frame(&|| true).expect("read"), Next::Frame);
    let asked = std::cell::Cell::new(0);
    let stop = || {
        asked.set(asked.get() + 1);
        asked.get() == 2
    };
    assert_eq!(r.next_frame(&stop).expect("read"), Next::Stopped);
    assert_eq!(r.next_frame(&|| false).expect("read"), Next::Frame);
    assert_eq!(r.body, b"second");
    assert_eq!(r.next_frame(&|| false).expect("read"), Next::End);
    assert_eq!(r.damaged_stretches, 1);
    let (frames, damage) = reference(&bytes);
    assert_eq!((frames.len(), r.damage.clone()), (2, damage));
}

/// A file of whole frames with random bodies, then damaged: stretches overwritten,
/// and false headers put in (claiming random lengths, some with the right checksum
/// of what follows them, so a false frame may be whole).
fn damaged_file(
    bodies: &[usize],
    stretches: &[(usize, usize, u8)],
    fakes: &[(usize, u32, bool)],
) -> Vec<u8> {
    let mut bytes = MAGIC.to_vec();
    for (k, n) in bodies.iter().enumerate() {
        let body: Vec<u8> = (0..*n).map(|i| (i * 31 + k * 7) as u8).collect();
        bytes.extend(frame(&body));
    }
    let room = bytes.len() - MAGIC.len();
    for &(at, n, v) in stretches {
        let at = MAGIC.len() + at % room;
        let end = (at + n).min(bytes.len());
        bytes[at..end].fill(v);
    }
    for &(at, len, right) in fakes {
        let at = MAGIC.len() + at % room;
        if at + HEADER > bytes.len() {
            continue;
        }
        let end = (at + HEADER + len as usize).min(bytes.len());
        let crc = if right {
            crc32fast::hash(&bytes[at + HEADER..end])
        } else {
            0x1234_5678
        };
        let claimed = (end - at - HEADER) as u32;
        bytes[at..at + HEADER].copy_from_slice(&header(if right { claimed } else { len }, crc));
    }
    bytes
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Whatever the damage, the reader finds the frames and stretches that checking
    /// every candidate afresh finds, and reads at most twice the file.
    #[test]
    fn the_frames_found_are_those_of_checking_every_candidate(
        bodies in proptest::collection::vec(0usize..30_000, 1..12),
        stretches in proptest::collection::vec((any::<usize>(), 1usize..3000, any::<u8>()), 0..4),
        fakes in proptest::collection::vec((any::<usize>(), 0u32..200_000, any::<bool>()), 0..40),
    ) {
        let bytes = damaged_file(&bodies, &stretches, &fakes);
        let (frames, damage) = read_linear(&bytes);
        let (want_frames, mut want_damage) = reference(&bytes);
        want_damage.truncate(MAX_KEPT_DAMAGE);
        prop_assert_eq!(frames, want_frames);
        prop_assert_eq!(damage, want_damage);
    }
}
