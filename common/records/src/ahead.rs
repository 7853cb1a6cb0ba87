//! The bytes a reader reads ahead while it resynchronises after damage, kept with the
//! CRC-32 of the stream at every [`MARK`]th byte, so that a candidate frame's checksum
//! comes from two of those CRCs and at most `2 * MARK` bytes hashed again, not from
//! reading and hashing its whole claimed body. Each byte of the file is then read and
//! hashed a bounded number of times however the damage is made: a stretch of sync
//! words each claiming a megabyte cost a megabyte of reading and a CRC per sync word
//! before (16 MB of them kept `tactile report` busy for two minutes).

/// Bytes between two CRCs kept.
const MARK: usize = 256;

/// The CRC-32 polynomial, reflected (the bit order crc32fast and zlib use).
const POLY: u32 = 0xEDB8_8320;

/// `a * b` modulo the CRC-32 polynomial, in its reflected bit order (zlib's
/// `multmodp`).
const fn multiply(a: u32, mut b: u32) -> u32 {
    let mut p = 0;
    let mut k = 0;
    while k < 32 {
        if a & (1 << (31 - k)) != 0 {
            p ^= b;
        }
        b = if b & 1 != 0 { (b >> 1) ^ POLY } else { b >> 1 };
        k += 1;
    }
    p
}

/// `X2N[k]` is x^(2^k) modulo the polynomial (zlib's `x2n_table`).
const X2N: [u32; 64] = {
    let mut t = [0u32; 64];
    // x^1.
    t[0] = 1 << 30;
    let mut k = 1;
    while k < 64 {
        t[k] = multiply(t[k - 1], t[k - 1]);
        k += 1;
    }
    t
};

/// `crc` as if `bytes` zero bytes followed the data it is the CRC of, without its
/// pre- and post-conditioning: what the CRC of a prefix contributes to the CRC of the
/// longer stream (zlib's `crc32_combine` is this shift and an exclusive or). `bytes`
/// is below 2^61.
fn shift(crc: u32, bytes: u64) -> u32 {
    let (mut p, mut n, mut k) = (crc, bytes, 3);
    while n != 0 {
        if n & 1 != 0 {
            p = multiply(X2N[k], p);
        }
        n >>= 1;
        k += 1;
    }
    p
}

/// The CRC-32 of the data `crc` is the CRC of, followed by `bytes`.
fn extend(crc: u32, bytes: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new_with_initial(crc);
    h.update(bytes);
    h.finalize()
}

/// Bytes of a file read in order from some offset, with the CRCs of the stream.
#[derive(Debug)]
pub(crate) struct Ahead {
    /// The file's offset of `buf[0]`: the stream's start plus a multiple of [`MARK`].
    at: u64,
    buf: Vec<u8>,
    /// `marks[i]`: the CRC-32 of the stream up to `at + i * MARK`.
    marks: Vec<u32>,
    /// The CRC-32 of the stream up to the end of `buf`.
    run: u32,
    /// Where the look for the next frame goes on: no whole frame starts between the
    /// frame last found and here.
    pub(crate) search: u64,
}

impl Ahead {
    /// A stream that starts at the file's offset `at`.
    pub(crate) fn new(at: u64) -> Ahead {
        Ahead {
            at,
            buf: Vec::new(),
            marks: Vec::new(),
            run: 0,
            search: at,
        }
    }

    /// The file's offset after the last byte held.
    pub(crate) fn end(&self) -> u64 {
        self.at + self.buf.len() as u64
    }

    /// The bytes held from `from` to `to` (both at or after what was forgotten).
    pub(crate) fn bytes(&self, from: u64, to: u64) -> &[u8] {
        &self.buf[(from - self.at) as usize..(to - self.at) as usize]
    }

    /// Appends the next bytes of the file.
    pub(crate) fn push(&mut self, bytes: &[u8]) {
        let mut pos = self.buf.len();
        self.buf.extend_from_slice(bytes);
        while pos < self.buf.len() {
            if pos.is_multiple_of(MARK) {
                self.marks.push(self.run);
            }
            let next = ((pos / MARK + 1) * MARK).min(self.buf.len());
            self.run = extend(self.run, &self.buf[pos..next]);
            pos = next;
        }
    }

    /// Forgets the bytes before `keep` once they are at least half of those held, so
    /// that what is held stays within twice what is needed and each byte is moved a
    /// bounded number of times.
    pub(crate) fn forget_before(&mut self, keep: u64) {
        let k = (keep.saturating_sub(self.at) as usize / MARK).min(self.marks.len());
        let drop = k * MARK;
        if drop == 0 || drop < self.buf.len() / 2 {
            return;
        }
        self.buf.drain(..drop);
        self.marks.drain(..k);
        self.at += drop as u64;
    }

    /// The CRC-32 of the stream up to `x` (held, or the end).
    fn prefix(&self, x: u64) -> u32 {
        let r = (x - self.at) as usize;
        if r == self.buf.len() {
            return self.run;
        }
        let i = r / MARK;
        extend(self.marks[i], &self.buf[i * MARK..r])
    }

    /// The CRC-32 of the bytes from `from` to `to`, both held.
    pub(crate) fn crc(&self, from: u64, to: u64) -> u32 {
        self.prefix(to) ^ shift(self.prefix(from), to - from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bytes(n: usize, seed: u64) -> Vec<u8> {
        let mut x = seed;
        (0..n)
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (x >> 56) as u8
            })
            .collect()
    }

    #[test]
    fn the_crc_of_any_stretch_is_the_crc_of_its_bytes() {
        let data = bytes(3000, 7);
        let mut a = Ahead::new(100);
        // Pushed in uneven pieces, across the marks.
        for piece in data.chunks(333) {
            a.push(piece);
        }
        for (from, to) in [
            (0, 0),
            (0, 1),
            (0, 3000),
            (5, 261),
            (255, 257),
            (256, 512),
            (1000, 2999),
        ] {
            let want = crc32fast::hash(&data[from..to]);
            assert_eq!(
                a.crc(100 + from as u64, 100 + to as u64),
                want,
                "{from}..{to}"
            );
        }
        a.forget_before(100 + 2000);
        assert_eq!(a.end(), 3100);
        assert_eq!(a.crc(2100, 3100), crc32fast::hash(&data[2000..]));
        assert_eq!(a.bytes(2500, 2510), &data[2400..2410]);
    }

    #[test]
    fn forgetting_keeps_what_is_asked_for() {
        let data = bytes(4096, 3);
        let mut a = Ahead::new(0);
        a.push(&data);
        // Less than half: nothing forgotten.
        a.forget_before(1000);
        assert_eq!(a.bytes(0, 4), &data[..4]);
        a.forget_before(2100);
        assert_eq!(a.bytes(2100, 4096), &data[2100..]);
        assert_eq!(a.crc(2100, 4096), crc32fast::hash(&data[2100..]));
        a.push(&data[..10]);
        assert_eq!(a.crc(4000, 4106), {
            let mut v = data[4000..].to_vec();
            v.extend_from_slice(&data[..10]);
            crc32fast::hash(&v)
        });
    }
}
