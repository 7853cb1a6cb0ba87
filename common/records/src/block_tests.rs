//! Blocks against their definition: planes byte for byte, rows back exactly, damage
//! refused and never a crash.

use super::*;
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any rows, of any lengths, come back byte for byte.
    #[test]
    fn rows_come_back_exactly(rows in proptest::collection::vec(
        prop_oneof![
            proptest::collection::vec(any::<u8>(), 0..40),
            Just(vec![0u8; 17]),
            Just(vec![7u8; 17]),
        ],
        0..60,
    )) {
        let lens: Vec<usize> = rows.iter().map(Vec::len).collect();
        let flat: Vec<u8> = rows.concat();
        let mut packed = Vec::new();
        let raw = pack(&flat, &lens, &mut Vec::new(), &mut Vec::new(), &mut packed)
            .expect("pack");
        let (back, back_lens) = unpack(lens.len() as u32, raw, &packed).expect("unpack");
        prop_assert_eq!(back, flat);
        prop_assert_eq!(back_lens, lens);
    }

    /// Garbage never panics: it unpacks to something or is refused.
    #[test]
    fn garbage_is_refused_not_a_crash(b in proptest::collection::vec(any::<u8>(), 0..200)) {
        let rows = b.first().copied().unwrap_or(0).into();
        let _ = from_planes(&b, rows);
        let _ = unpack(rows, b.len() as u32, &b);
        let _ = unpack(rows, u32::from(b.last().copied().unwrap_or(0)) * 9, &b);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Planes damaged anywhere (cut, a bit flipped, a stretch copied over another)
    /// unpack to something or are refused, never a crash.
    #[test]
    fn damaged_planes_are_refused_not_a_crash(
        rows in proptest::collection::vec(
            prop_oneof![
                proptest::collection::vec(any::<u8>(), 0..24),
                Just(vec![5u8; 9]),
            ],
            1..30,
        ),
        cut in any::<proptest::sample::Index>(),
        flip in any::<proptest::sample::Index>(),
        bit in 0u8..8,
        from in any::<proptest::sample::Index>(),
        to in any::<proptest::sample::Index>(),
        len in 0usize..16,
    ) {
        let lens: Vec<usize> = rows.iter().map(Vec::len).collect();
        let mut planes = Vec::new();
        to_planes(&rows.concat(), &lens, &mut planes, &mut Vec::new());
        let n = lens.len() as u32;
        let _ = from_planes(&planes[..cut.index(planes.len() + 1)], n);
        let mut flipped = planes.clone();
        flipped[flip.index(planes.len())] ^= 1 << bit;
        let _ = from_planes(&flipped, n);
        let mut spliced = planes.clone();
        let (a, z) = (from.index(planes.len()), to.index(planes.len()));
        let k = len.min(planes.len() - a).min(planes.len() - z);
        spliced.copy_within(a..a + k, z);
        let _ = from_planes(&spliced, n);
    }
}

/// [`to_planes`] by its definition, one byte at a time: the rows' lengths, then
/// per group its first row, the bitmap of planes where a later row differs from
/// the one before it, and those planes.
fn planes_by_definition(rows: &[u8], lens: &[usize]) -> Vec<u8> {
    let mut out = Vec::new();
    put_varint(&mut out, lens.len() as u64);
    for &l in lens {
        put_varint(&mut out, l as u64);
    }
    // Groups: the distinct lengths in order of first appearance, each with its
    // rows' offsets (found here by a plain search, not by `groups`).
    let mut by_len: Vec<(usize, Vec<usize>)> = Vec::new();
    let mut at = 0;
    for &l in lens {
        match by_len.iter_mut().find(|(g, _)| *g == l) {
            Some((_, starts)) => starts.push(at),
            None => by_len.push((l, vec![at])),
        }
        at += l;
    }
    for (len, starts) in by_len {
        out.extend_from_slice(&rows[starts[0]..starts[0] + len]);
        let plane = |j: usize| -> Vec<u8> {
            starts
                .windows(2)
                .map(|p| rows[p[1] + j] ^ rows[p[0] + j])
                .collect()
        };
        let kept: Vec<usize> = (0..len)
            .filter(|&j| plane(j).iter().any(|&b| b != 0))
            .collect();
        let mut bitmap = vec![0u8; len.div_ceil(8)];
        for &j in &kept {
            bitmap[j / 8] |= 1 << (j % 8);
        }
        out.extend_from_slice(&bitmap);
        for j in kept {
            out.extend(plane(j));
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The planes are the bytes their definition gives (format 14), whether a run
    /// of eight columns goes by tiles or byte by byte.
    #[test]
    fn planes_are_their_definition(rows in proptest::collection::vec(
        prop_oneof![
            proptest::collection::vec(any::<u8>(), 0..40),
            proptest::collection::vec(0u8..2, 9),
            proptest::collection::vec(any::<u8>(), 24),
            Just(vec![7u8; 17]),
        ],
        // Up to 120 rows: a shape often has 16 later rows or more (whole tiles).
        0..120,
    )) {
        let lens: Vec<usize> = rows.iter().map(Vec::len).collect();
        let flat = rows.concat();
        let mut planes = vec![1, 2, 3];
        let mut scratch = vec![9; 5];
        to_planes(&flat, &lens, &mut planes, &mut scratch);
        prop_assert_eq!(&planes[..3], &[1, 2, 3]);
        let want = planes_by_definition(&flat, &lens);
        prop_assert_eq!(&planes[3..], want.as_slice());
    }
}

/// Every choice of kept planes in a run of eight columns, by tiles or byte by
/// byte, whole tiles or not, a last run of fewer than eight columns or not: the
/// planes their definition gives. Column `c` changes from row to row only if bit
/// `c % 8` of the mask is set.
#[test]
fn every_mask_of_kept_planes_lays_out_as_defined() {
    for mask in 0..=255u8 {
        for rows in [1, 2, 9, 16, 17, 18, 33, 34, 37] {
            for len in [8, 11, 16, 19] {
                let flat: Vec<u8> = (0..rows)
                    .flat_map(|i| {
                        (0..len).map(move |c| {
                            let changes = mask & (1 << (c % 8)) != 0;
                            let v = if changes { i * 31 + c * 7 } else { c };
                            (v % 251) as u8
                        })
                    })
                    .collect();
                let lens = vec![len; rows];
                let mut planes = Vec::new();
                to_planes(&flat, &lens, &mut planes, &mut Vec::new());
                assert_eq!(
                    planes,
                    planes_by_definition(&flat, &lens),
                    "mask {mask:08b}, {rows} rows of {len}"
                );
            }
        }
    }
}

proptest! {
    /// Row `k`'s byte `j` becomes vector `j`'s byte `k`.
    #[test]
    fn a_tile_transposes(m in any::<[u64; TILE_ROWS]>()) {
        let t = transpose(m);
        for (k, row) in m.iter().enumerate() {
            for (j, column) in t.iter().enumerate() {
                prop_assert_eq!(row.to_le_bytes()[j], column.as_array_ref()[k]);
            }
        }
    }
}

#[test]
fn unchanged_values_cost_nothing_and_counters_little() {
    // 50 rows of a counter and a constant: the constant's planes are left out.
    let mut flat = Vec::new();
    for n in 0u64..50 {
        flat.extend_from_slice(&n.to_le_bytes());
        flat.extend_from_slice(&1234.5f64.to_bits().to_le_bytes());
    }
    let mut planes = Vec::new();
    to_planes(&flat, &[16; 50], &mut planes, &mut Vec::new());
    // count and lengths (51), the first row (16), bitmap (2) and the counter's low
    // plane over the 49 later rows: the constant costs its first row alone.
    assert_eq!(planes.len(), 51 + 16 + 2 + 49);
}

#[test]
fn groups_are_the_lengths_in_order_of_first_appearance_few_or_many() {
    for distinct in [1, 3, FEW_GROUPS, FEW_GROUPS + 1, 100] {
        let lens: Vec<usize> = (0..500).map(|i| (i * 7) % distinct + 1).collect();
        let got = groups(&lens);
        let mut want: Vec<(usize, Vec<usize>)> = Vec::new();
        let mut at = 0;
        for &l in &lens {
            match want.iter_mut().find(|(g, _)| *g == l) {
                Some((_, rows)) => rows.push(at),
                None => want.push((l, vec![at])),
            }
            at += l;
        }
        assert_eq!(got, want, "{distinct} lengths");
    }
}

#[test]
fn a_block_that_claims_more_than_lz4_can_hold_is_refused() {
    // 16 bytes of zeros pack into a few bytes; claiming a megabyte for them is
    // refused before a megabyte is allocated.
    let mut packed = Vec::new();
    let raw = pack(
        &[0; 16],
        &[16],
        &mut Vec::new(),
        &mut Vec::new(),
        &mut packed,
    )
    .expect("pack");
    assert!(unpack(1, raw, &packed).is_ok());
    assert_eq!(
        unpack(1, 1 << 20, &packed),
        Err(BlockError("longer than its packed bytes can hold"))
    );
    assert_eq!(
        unpack(1, raw + 1, &packed),
        Err(BlockError("not the length it claims"))
    );
}

#[test]
fn a_block_that_claims_too_much_is_refused() {
    let mut b = Vec::new();
    put_varint(&mut b, 2);
    put_varint(&mut b, MAX_RAW as u64);
    put_varint(&mut b, 1);
    assert_eq!(
        from_planes(&b, 2),
        Err(BlockError("rows longer than a block may be"))
    );
    assert_eq!(
        from_planes(&b, 3),
        Err(BlockError("not the rows its entry says"))
    );
    let mut b = Vec::new();
    put_varint(&mut b, MAX_ROWS as u64 + 1);
    b.resize(2 * MAX_ROWS + 8, 0);
    assert_eq!(
        from_planes(&b, MAX_ROWS as u32 + 1),
        Err(BlockError("more rows than a block may hold"))
    );
}
