use super::*;
use crate::entry::Event;
use crate::frames::frame;
use proptest::prelude::*;

type R = Record<(u64, String), u64>;

fn event(k: u64) -> R {
    Record::Event(Event {
        sample: k,
        mono_ns: 0,
        what: "x".repeat((k % 7) as usize),
    })
}

/// Writes `n` entries, each its own frame; the byte span of each.
fn write(path: &Path, n: u64) -> Vec<(u64, u64)> {
    let mut w = RecordWriter::<R>::create(path, false).expect("create");
    let mut spans = Vec::new();
    for k in 0..n {
        let start = std::fs::metadata(path).expect("meta").len();
        w.write(&event(k)).expect("write");
        spans.push((start, std::fs::metadata(path).expect("meta").len()));
    }
    spans
}

/// The entries' and samples' numbers read back, and the damaged stretches.
fn read(path: &Path) -> (Vec<u64>, u64) {
    let mut r = RecordReader::<R>::open(path).expect("open");
    let mut got = Vec::new();
    while let Some(rec) = r.next_record().expect("read") {
        match rec {
            Record::Event(e) => got.push(e.sample),
            Record::Sample((k, _)) => got.push(k),
            _ => {}
        }
    }
    (got, r.damaged().1)
}

#[test]
fn a_torn_tail_is_trimmed_before_appending_and_nothing_whole_is_lost() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    write(&path, 50);
    let len = std::fs::metadata(&path).expect("meta").len();
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .expect("open");
    f.set_len(len - 7).expect("cut 7 bytes");
    let (got, damaged) = read(&path);
    assert_eq!(got, (0..49).collect::<Vec<_>>());
    assert_eq!(damaged, 1, "the torn tail is one damaged stretch");
    let mut w = RecordWriter::<R>::create(&path, true).expect("append");
    w.write(&event(100)).expect("write");
    drop(w);
    let (got, damaged) = read(&path);
    assert_eq!(got.len(), 50);
    assert_eq!(got.last(), Some(&100));
    assert_eq!(damaged, 0, "the append trimmed the torn frame");
}

#[test]
fn a_record_killed_before_its_magic_was_whole_starts_afresh_on_append() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    std::fs::write(&path, &THIS_MAGIC[..3]).expect("write");
    let mut w = RecordWriter::<R>::create(&path, true).expect("append");
    w.write(&event(1)).expect("write");
    drop(w);
    assert_eq!(read(&path), (vec![1], 0));
}

#[test]
fn garbage_is_refused_not_read() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    std::fs::write(&path, b"hello world").expect("write");
    assert!(matches!(
        RecordReader::<R>::open(&path),
        Err(RecordError::NotARecord { .. })
    ));
    assert!(RecordWriter::<R>::create(&path, true).is_err());
    let mut old = THIS_MAGIC.to_vec();
    old[7] = 4;
    std::fs::write(&path, &old).expect("write");
    let e = RecordReader::<R>::open(&path)
        .map(|_| ())
        .expect_err("version 4");
    let want = format!(
        "format version 4; this build reads version {}",
        THIS_MAGIC[7]
    );
    assert!(e.to_string().contains(&want), "{e}");
}

#[test]
fn a_whole_frame_claiming_a_huge_string_is_damage_not_a_crash() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    write(&path, 3);
    // Event (tag 3) at sample 7, then a string of 2^62 bytes in bincode's varints,
    // in a frame whose checksum holds: a writer of another build, or an attacker.
    let mut body = vec![3u8, 7, 0, 0xFD];
    body.extend_from_slice(&(1u64 << 62).to_le_bytes());
    body.extend_from_slice(b"abc");
    let mut bytes = std::fs::read(&path).expect("read");
    bytes.extend_from_slice(&frame(&body));
    std::fs::write(&path, &bytes).expect("write");
    let mut w = RecordWriter::<R>::create(&path, true).expect("append");
    w.write(&event(9)).expect("write");
    drop(w);
    assert_eq!(read(&path), (vec![0, 1, 2, 9], 1));
}

/// `n` samples in blocks of `rows`, an event after each hundred.
fn write_samples(path: &Path, n: u64, rows: usize) {
    let mut w = RecordWriter::<R>::create(path, false).expect("create");
    w.set_block_rows(rows);
    for k in 0..n {
        w.write(&Record::Sample((k, "s".repeat((k % 3) as usize))))
            .expect("sample");
        if k % 100 == 99 {
            w.write(&event(1_000_000 + k)).expect("event");
        }
    }
}

#[test]
fn samples_come_back_in_order_with_the_entries_between_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    write_samples(&path, 1000, 30);
    let (got, damaged) = read(&path);
    let mut want = Vec::new();
    for k in 0..1000 {
        want.push(k);
        if k % 100 == 99 {
            want.push(1_000_000 + k);
        }
    }
    assert_eq!(got, want);
    assert_eq!(damaged, 0);
    assert_eq!(runs_in(&path), Vec::<u64>::new());
}

#[test]
fn rows_in_counts_the_whole_blocks_written_so_far() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    assert_eq!(rows_in(&path), 0, "no file yet");
    write_samples(&path, 1000, 30);
    assert_eq!(
        rows_in(&path),
        1000,
        "events between the blocks are not samples"
    );
    // Three blocks of 30, the last torn (a node still writing it): not counted.
    write_samples(&path, 90, 30);
    let len = std::fs::metadata(&path).expect("meta").len();
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .expect("open");
    f.set_len(len - 5).expect("cut");
    assert_eq!(rows_in(&path), 60);
}

#[test]
fn a_corrupted_block_costs_its_samples_and_no_others() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    write_samples(&path, 90, 30);
    let mut bytes = std::fs::read(&path).expect("read");
    // Three blocks of 30 (no event: fewer than 100 samples); one byte of the second
    // block's packed bytes flipped.
    let second = bytes
        .windows(4)
        .enumerate()
        .filter(|(_, w)| *w == crate::frames::SYNC)
        .map(|(k, _)| k)
        .nth(1)
        .expect("a second frame");
    bytes[second + HEADER + 12] ^= 0x40;
    std::fs::write(&path, &bytes).expect("write");
    let (got, damaged) = read(&path);
    let want: Vec<u64> = (0..30).chain(60..90).collect();
    assert_eq!(got, want);
    assert_eq!(damaged, 1);
}

#[test]
fn a_block_is_written_when_50_ms_old_though_not_full() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    let mut w = RecordWriter::<R>::create(&path, false).expect("create");
    w.set_block_rows(1000);
    let len = || std::fs::metadata(&path).expect("meta").len();
    let empty = len();
    for k in 0..8 {
        w.write(&Record::Sample((k, String::new())))
            .expect("sample");
    }
    assert_eq!(len(), empty, "a young block stays in hand");
    std::thread::sleep(std::time::Duration::from_millis(60));
    for k in 8..16 {
        w.write(&Record::Sample((k, String::new())))
            .expect("sample");
    }
    assert!(len() > empty, "the block went out once 50 ms old");
    // The writer dropped (a node's error, its end): the rest goes out too.
    w.write(&Record::Sample((16, String::new())))
        .expect("sample");
    drop(w);
    assert_eq!(read(&path), ((0..17).collect(), 0));
}

/// Cuts the record at `path` at `cut` bytes past its magic and overwrites the
/// stretches (offset, length, value) given; the indices of `spans` (byte ranges of
/// frames) none of whose bytes were touched and that the cut left whole.
fn damage(
    path: &Path,
    cut: usize,
    stretches: &[(usize, usize, u8)],
    spans: &[(u64, u64)],
) -> Vec<usize> {
    let mut bytes = std::fs::read(path).expect("read");
    let magic = THIS_MAGIC.len();
    let cut = magic + cut.min(bytes.len() - magic);
    let mut touched = vec![false; bytes.len()];
    for (at, n, v) in stretches {
        let at = magic + at % (bytes.len() - magic);
        for i in at..(at + n).min(bytes.len()) {
            if bytes[i] != *v {
                bytes[i] = *v;
                touched[i] = true;
            }
        }
    }
    bytes.truncate(cut.max(magic));
    std::fs::write(path, &bytes).expect("write");
    spans
        .iter()
        .enumerate()
        .filter(|(_, (s, e))| {
            (*e as usize) <= bytes.len() && !touched[*s as usize..*e as usize].contains(&true)
        })
        .map(|(k, _)| k)
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random cuts and corrupted stretches: every frame none of whose bytes was
    /// touched is read back, in order, and nothing else.
    #[test]
    fn no_whole_frame_is_lost(
        cut in 0usize..4000,
        stretches in proptest::collection::vec((0usize..4000, 1usize..40, any::<u8>()), 0..4),
    ) {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.rec");
        let spans = write(&path, 200);
        let intact = damage(&path, cut, &stretches, &spans);
        let whole: Vec<u64> = intact
            .into_iter()
            .map(|k| k as u64)
            .collect();
        let (got, _) = read(&path);
        prop_assert_eq!(got, whole);
    }

    /// The same for blocks: every block none of whose bytes was touched gives back all
    /// its samples, in order, and nothing else.
    #[test]
    fn no_whole_block_is_lost(
        cut in 0usize..6000,
        stretches in proptest::collection::vec((0usize..6000, 1usize..40, any::<u8>()), 0..4),
    ) {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.rec");
        let mut w = RecordWriter::<R>::create(&path, false).expect("create");
        w.set_block_rows(10);
        let mut spans = Vec::new();
        for b in 0..30u64 {
            let start = std::fs::metadata(&path).expect("meta").len();
            for k in 0..10 {
                let n = b * 10 + k;
                w.write(&Record::Sample((n, "v".repeat((n % 5) as usize)))).expect("sample");
            }
            spans.push((start, std::fs::metadata(&path).expect("meta").len()));
        }
        drop(w);
        let intact = damage(&path, cut, &stretches, &spans);
        let whole: Vec<u64> = intact
            .into_iter()
            .flat_map(|b| (b as u64 * 10)..(b as u64 * 10 + 10))
            .collect();
        let (got, _) = read(&path);
        prop_assert_eq!(got, whole);
    }
}

#[test]
fn rows_longer_than_the_row_buffer_come_back_whole() {
    // Rows either side of `ROW` (a long arm's joints), mixed in one block: the long ones
    // take the other way in, and every row comes back as written.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.rec");
    let samples: Vec<(u64, String)> = (0..40u64)
        .map(|k| (k, "ab".repeat((k as usize * 97) % (ROW + 300))))
        .collect();
    assert!(samples.iter().any(|(_, s)| s.len() > ROW));
    let mut w = RecordWriter::<R>::create(&path, false).expect("create");
    w.set_block_rows(16);
    for s in &samples {
        w.write(&Record::Sample(s.clone())).expect("write");
    }
    drop(w);
    let mut r = RecordReader::<R>::open(&path).expect("open");
    let mut got = Vec::new();
    while let Some(rec) = r.next_record().expect("read") {
        if let Record::Sample(s) = rec {
            got.push(s);
        }
    }
    assert_eq!(got, samples);
}

/// Writes `len` bytes of a string, then fails: a sample that cannot be encoded.
struct FailsAfter(usize);

impl serde::Serialize for FailsAfter {
    fn serialize<Z: serde::Serializer>(&self, s: Z) -> Result<Z::Ok, Z::Error> {
        use serde::ser::{Error, SerializeTuple};
        let mut t = s.serialize_tuple(2)?;
        t.serialize_element(&"x".repeat(self.0))?;
        t.end()?;
        Err(Z::Error::custom("this sample cannot be encoded"))
    }
}

#[test]
fn a_row_that_fails_to_encode_leaves_the_rows_as_they_were() {
    let mut rows = Rows::default();
    assert_eq!(rows.append(&(7u64, 9u32)).expect("a row"), 12);
    let before = rows.as_slice().to_vec();
    // Failing inside the room, and past it (the long way in).
    for len in [10, ROW + 100] {
        assert!(rows.append(&FailsAfter(len)).is_err());
        assert_eq!(rows.as_slice(), &before[..]);
    }
    assert_eq!(rows.append(&(8u64, 1u32)).expect("a row"), 12);
    assert_eq!(rows.as_slice().len(), 24);
}

/// `body_len` is the length the writer writes (what a scenario's check measures a
/// run's start entry with), and an entry past a frame is refused, the file as it was.
#[test]
fn an_entrys_length_is_counted_as_written_and_a_frame_too_long_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("r.rec");
    let mut w = RecordWriter::<R>::create(&path, false).expect("create");
    let len = |p: &Path| std::fs::metadata(p).expect("meta").len() as usize;
    for what in [String::new(), "x".repeat(1000)] {
        let e: R = Record::Event(Event {
            sample: 7,
            mono_ns: u64::MAX,
            what,
        });
        let before = len(&path);
        w.write(&e).expect("write");
        assert_eq!(len(&path) - before, HEADER + body_len(&e).expect("len"));
    }
    let long: R = Record::Event(Event {
        sample: 0,
        mono_ns: 0,
        what: "x".repeat(MAX_FRAME as usize),
    });
    let n = body_len(&long).expect("len");
    assert_eq!(fits(n), Err(TooLong { len: n }));
    let before = len(&path);
    let e = w.write(&long).expect_err("longer than a frame");
    assert!(e.to_string().contains("longer than a frame may be"), "{e}");
    assert_eq!(len(&path), before);
}
