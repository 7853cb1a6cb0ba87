//! Mutations of an input, as byte fuzzers make them: bits flipped, bytes replaced by
//! boundary values, runs inserted, deleted and repeated, integers overwritten with
//! extremes (lengths and counts are where decoders go wrong), and two inputs spliced.

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

/// A new input: one of `corpus`, mutated one to four times.
pub fn mutate(rng: &mut Rng, corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut b = corpus[rng.below(corpus.len())].clone();
    for _ in 0..=rng.below(4) {
        step(rng, &mut b, corpus);
    }
    b.truncate(MAX_LEN);
    b
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
                .map(|_| mutate(&mut rng, &corpus))
                .collect::<Vec<_>>()
        };
        let a = run(5);
        assert_eq!(a, run(5));
        assert_ne!(a, run(6));
        assert!(a.iter().all(|x| x.len() <= MAX_LEN));
        assert!(a.iter().any(|x| x != &corpus[0] && x != &corpus[1]));
    }
}
