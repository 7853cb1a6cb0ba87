//! Mutations of an input, as byte fuzzers make them: bits flipped, bytes replaced by
//! boundary values, runs inserted, deleted and repeated, integers overwritten with
//! extremes (lengths and counts are where decoders go wrong), and two inputs spliced;
//! for a text format, also its tokens (a number replaced by `1e308`, a `"fixed"`
//! inserted): what a byte fuzzer seldom makes of `1.5` is what a parser must refuse.

/// Longest input kept in a corpus, bytes.
pub const MAX_LEN: usize = 1 << 16;

/// xorshift64*: small, fast, and the same sequence for the same seed.
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed` (0 is replaced: xorshift never leaves it).
    pub fn new(seed: u64) -> Rng {
        Rng(seed.max(1))
    }

    /// The next 64 bits.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// A number below `n` (0 for `n` = 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

const BYTES: [u8; 8] = [0, 1, 0x7f, 0x80, 0xfe, 0xff, b'\n', b','];
const WORDS: [u64; 7] = [
    0,
    1,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    u64::MAX,
    1 << 62,
];

/// A new input: one of `corpus`, mutated one to four times, with the format's
/// tokens `dict` among the mutations (none without).
pub fn mutate(rng: &mut Rng, corpus: &[Vec<u8>], dict: &[&str]) -> Vec<u8> {
    let mut b = corpus[rng.below(corpus.len())].clone();
    for _ in 0..=rng.below(4) {
        if !dict.is_empty() && rng.below(3) == 0 {
            token(rng, &mut b, dict);
        } else {
            step(rng, &mut b, corpus);
        }
    }
    b.truncate(MAX_LEN);
    b
}

/// Part of a number: a digit, a point, a sign, an exponent.
fn numeric(c: u8) -> bool {
    c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'+' | b'e' | b'E')
}

/// One of `dict` in place of the number at or after a random byte (inserted there
/// when there is none, or one time in four).
fn token(rng: &mut Rng, b: &mut Vec<u8>, dict: &[&str]) {
    let t = dict[rng.below(dict.len())].as_bytes();
    let at = rng.below(b.len() + 1);
    let start = b[at..]
        .iter()
        .position(|c| c.is_ascii_digit())
        .map(|k| at + k);
    match start {
        Some(mut s) if rng.below(4) != 0 => {
            while s > 0 && numeric(b[s - 1]) {
                s -= 1;
            }
            let end = s + b[s..].iter().take_while(|c| numeric(**c)).count();
            b.splice(s..end, t.iter().copied());
        }
        _ => {
            b.splice(at..at, t.iter().copied());
        }
    }
}

fn step(rng: &mut Rng, b: &mut Vec<u8>, corpus: &[Vec<u8>]) {
    if b.is_empty() {
        b.push(BYTES[rng.below(BYTES.len())]);
        return;
    }
    let at = rng.below(b.len());
    match rng.below(7) {
        0 => b[at] ^= 1 << rng.below(8),
        1 => b[at] = BYTES[rng.below(BYTES.len())],
        2 => {
            let n = 1 + rng.below(16);
            let run: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
            b.splice(at..at, run);
        }
        3 => {
            let end = (at + 1 + rng.below(32)).min(b.len());
            b.drain(at..end);
        }
        4 => {
            let end = (at + 1 + rng.below(64)).min(b.len());
            let run = b[at..end].to_vec();
            b.splice(end..end, run);
        }
        5 => {
            let w = WORDS[rng.below(WORDS.len())].to_le_bytes();
            let n = [1, 2, 4, 8][rng.below(4)];
            for (i, x) in w.iter().take(n).enumerate() {
                if let Some(slot) = b.get_mut(at + i) {
                    *slot = *x;
                }
            }
        }
        _ => {
            let other = &corpus[rng.below(corpus.len())];
            let from = rng.below(other.len());
            b.truncate(at);
            b.extend_from_slice(&other[from..]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutations_are_bounded_and_the_same_for_the_same_seed() {
        let corpus = vec![b"abcdef".to_vec(), vec![0u8; 100]];
        let run = |seed| {
            let mut rng = Rng::new(seed);
            (0..2000)
                .map(|_| mutate(&mut rng, &corpus, &[]))
                .collect::<Vec<_>>()
        };
        let a = run(5);
        assert_eq!(a, run(5));
        assert_ne!(a, run(6));
        assert!(a.iter().all(|x| x.len() <= MAX_LEN));
        assert!(a.iter().any(|x| x != &corpus[0] && x != &corpus[1]));
    }

    #[test]
    fn tokens_replace_whole_numbers() {
        let corpus = vec![b"scale = 1.5e-2\n".to_vec()];
        let mut rng = Rng::new(3);
        let got: Vec<String> = (0..400)
            .map(|_| String::from_utf8_lossy(&mutate(&mut rng, &corpus, &["1e308"])).into_owned())
            .collect();
        assert!(
            got.iter().any(|s| s == "scale = 1e308\n"),
            "{:?}",
            &got[..20]
        );
        assert!(got.iter().all(|s| s.len() <= MAX_LEN));
    }
}
