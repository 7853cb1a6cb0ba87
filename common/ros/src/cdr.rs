//! CDR (XCDR1, little endian) as ROS 2 serializes messages: a 4-byte encapsulation
//! header `00 01 00 00`, then the fields in order, each primitive aligned to its own
//! size (at most 8) counted from the end of the header; strings as a u32 length that
//! counts the closing NUL, the bytes and the NUL; sequences as a u32 count and the
//! elements; fixed arrays as the bare elements.

use thiserror::Error;

/// The encapsulation header of little-endian plain CDR.
pub const HEADER: [u8; 4] = [0, 1, 0, 0];

/// Writes one message.
#[derive(Debug, Clone)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self::new()
    }
}

macro_rules! put {
    ($($name:ident: $t:ty),*) => {$(
        #[doc = concat!("Appends a `", stringify!($t), "`, aligned to its size.")]
        pub fn $name(&mut self, v: $t) {
            self.align(std::mem::size_of::<$t>());
            self.buf.extend_from_slice(&v.to_le_bytes());
        }
    )*};
}

impl CdrWriter {
    /// A message with its encapsulation header.
    pub fn new() -> Self {
        let mut buf = Vec::with_capacity(256);
        buf.extend_from_slice(&HEADER);
        CdrWriter { buf }
    }

    /// Starts a new message in the same buffer (keeps its capacity).
    pub fn reset(&mut self) {
        self.buf.clear();
        self.buf.extend_from_slice(&HEADER);
    }

    fn align(&mut self, n: usize) {
        let pos = self.buf.len() - HEADER.len();
        let pad = (n - pos % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    put!(u32: u32, i32: i32, u64: u64, i64: i64, f32: f32, f64: f64);

    /// Appends a byte.
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// Appends a bool as one byte.
    pub fn bool(&mut self, v: bool) {
        self.buf.push(u8::from(v));
    }

    /// Appends a string: length with the NUL, bytes, NUL.
    pub fn string(&mut self, s: &str) {
        self.seq_len(s.len() + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// Appends a sequence's element count.
    pub fn seq_len(&mut self, n: usize) {
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }

    /// The message's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.buf
    }
}

/// Why a CDR message could not be read.
#[derive(Debug, Clone, Error, PartialEq, Eq)]
pub enum CdrError {
    /// The message ends before a field does.
    #[error("message truncated at byte {at} (needs {need} more)")]
    Truncated {
        /// Offset of the field.
        at: usize,
        /// Bytes it needs.
        need: usize,
    },
    /// Not little-endian plain CDR.
    #[error("encapsulation {0:02x?} is not little-endian CDR (00 01 00 00)")]
    Encapsulation([u8; 4]),
    /// A string without its NUL or not UTF-8.
    #[error("string at byte {0} is not NUL-terminated UTF-8")]
    BadString(usize),
    /// Bytes left after the last field.
    #[error("{0} bytes after the last field")]
    Trailing(usize),
    /// A sequence longer than the reader allows.
    #[error("sequence of {len} at byte {at} exceeds the limit of {limit}")]
    TooLong {
        /// Offset of the count.
        at: usize,
        /// The count.
        len: u32,
        /// The largest count accepted.
        limit: usize,
    },
}

/// Reads one message; every read is checked (a peer's bytes are never trusted).
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    pos: usize,
    /// Largest sequence count accepted (bounds what a malformed count can allocate).
    pub limit: usize,
}

macro_rules! get {
    ($($name:ident: $t:ty),*) => {$(
        #[doc = concat!("Reads a `", stringify!($t), "`, aligned to its size.")]
        pub fn $name(&mut self) -> Result<$t, CdrError> {
            const N: usize = std::mem::size_of::<$t>();
            self.align(N);
            let b = self.take(N)?;
            let mut a = [0u8; N];
            a.copy_from_slice(b);
            Ok(<$t>::from_le_bytes(a))
        }
    )*};
}

impl<'a> CdrReader<'a> {
    /// A reader over a whole message, header included.
    pub fn new(buf: &'a [u8]) -> Result<Self, CdrError> {
        let head: [u8; 4] = match buf.get(..4) {
            Some(h) => [h[0], h[1], h[2], h[3]],
            None => {
                return Err(CdrError::Truncated {
                    at: 0,
                    need: 4 - buf.len(),
                })
            }
        };
        if head != HEADER {
            return Err(CdrError::Encapsulation(head));
        }
        Ok(CdrReader {
            buf,
            pos: 4,
            limit: 1 << 16,
        })
    }

    fn align(&mut self, n: usize) {
        let rel = self.pos - HEADER.len();
        self.pos += (n - rel % n) % n;
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], CdrError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.buf.len());
        let Some(end) = end else {
            return Err(CdrError::Truncated {
                at: self.pos,
                need: self.pos + n - self.buf.len().min(self.pos + n),
            });
        };
        let s = &self.buf[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    get!(u32: u32, i32: i32, u64: u64, i64: i64, f32: f32, f64: f64);

    /// Reads a byte.
    pub fn u8(&mut self) -> Result<u8, CdrError> {
        Ok(self.take(1)?[0])
    }

    /// Reads a bool (any non-zero byte is true).
    pub fn bool(&mut self) -> Result<bool, CdrError> {
        Ok(self.u8()? != 0)
    }

    /// Reads a sequence count, refusing one above [`Self::limit`].
    pub fn seq_len(&mut self) -> Result<usize, CdrError> {
        let at = self.pos;
        let len = self.u32()?;
        let n = len as usize;
        if n > self.limit {
            return Err(CdrError::TooLong {
                at,
                len,
                limit: self.limit,
            });
        }
        Ok(n)
    }

    /// The end of the message: at most the 3 bytes of padding a writer may leave
    /// (rmw pads a message to 4 bytes), and those zero.
    pub fn finish(&self) -> Result<(), CdrError> {
        let rest = self.buf.get(self.pos..).unwrap_or_default();
        if rest.len() < 4 && rest.iter().all(|b| *b == 0) {
            Ok(())
        } else {
            Err(CdrError::Trailing(rest.len()))
        }
    }

    /// Reads a string.
    pub fn string(&mut self) -> Result<String, CdrError> {
        let at = self.pos;
        let n = self.seq_len()?;
        let b = self.take(n)?;
        match b.split_last() {
            Some((0, s)) => std::str::from_utf8(s)
                .map(str::to_owned)
                .map_err(|_| CdrError::BadString(at)),
            _ => Err(CdrError::BadString(at)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_align_from_the_end_of_the_header() {
        let mut w = CdrWriter::new();
        w.u8(1);
        w.f64(2.5);
        w.string("ab");
        w.u32(7);
        let b = w.bytes();
        // u8 at 4, padding to 8 past the header (byte 12), f64 at 12..20, string
        // length at 20, "ab\0" at 24..27, pad to 28, u32 at 28.
        assert_eq!(b.len(), 32);
        assert_eq!(&b[12..20], &2.5f64.to_le_bytes());
        assert_eq!(&b[20..27], &[3, 0, 0, 0, b'a', b'b', 0]);
        let mut r = CdrReader::new(b).expect("header");
        assert_eq!(r.u8(), Ok(1));
        assert_eq!(r.f64(), Ok(2.5));
        assert_eq!(r.string().as_deref(), Ok("ab"));
        assert_eq!(r.u32(), Ok(7));
        assert!(r.u8().is_err());
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        assert!(CdrReader::new(&[0, 1]).is_err());
        assert!(matches!(
            CdrReader::new(&[1, 0, 0, 0]),
            Err(CdrError::Encapsulation(_))
        ));
        let mut r = CdrReader::new(&[0, 1, 0, 0, 255, 255, 255, 255]).expect("header");
        assert!(matches!(r.seq_len(), Err(CdrError::TooLong { .. })));
        let mut r = CdrReader::new(&[0, 1, 0, 0, 2, 0, 0, 0, b'a', b'b']).expect("header");
        assert_eq!(r.string(), Err(CdrError::BadString(4)));
    }
}
