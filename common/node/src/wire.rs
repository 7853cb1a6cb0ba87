//! The wire format of the hops that leave the host (UDP, Zenoh): a header, then the
//! sample encoded with bincode 2.
//!
//! Header: 4 bytes of magic (`TCTL`), the format version (`u16`, little-endian) and the
//! kind of sample (forward or backward); the sample itself carries its run token. Two
//! builds whose formats differ refuse each other's samples with a clear error instead
//! of misreading them; bytes from a stranger (no magic), truncated or trailing bytes
//! are rejected and counted, never used. Nothing the network delivers can make a node
//! panic: every field is checked by the decoder.

use serde::{de::DeserializeOwned, Serialize};
use tactile_messages::samples::{Backward, Forward};

/// First bytes of every frame.
pub const MAGIC: [u8; 4] = *b"TCTL";
/// The format version; bump it whenever a sample's layout changes.
pub const VERSION: u16 = 3;
/// Header length, bytes.
pub const HEADER: usize = 7;
/// Largest frame a receiver accepts (a sample is about 250 bytes).
pub const MAX_FRAME: usize = 4096;

/// Which stream a frame belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// c(n) or v(n).
    Forward = 0,
    /// h(n) or q(n).
    Backward = 1,
}

/// A decoded frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Frame {
    /// A forward sample.
    Forward(Forward),
    /// A backward sample.
    Backward(Backward),
}

/// Why a frame was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reject {
    /// Not a Tactile frame (no magic), truncated, or not a whole sample.
    Malformed,
    /// A Tactile frame of another format version (another build).
    Version(u16),
}

fn config() -> impl bincode::config::Config {
    bincode::config::standard()
        .with_little_endian()
        .with_fixed_int_encoding()
        .with_limit::<MAX_FRAME>()
}

fn encode_into<T: Serialize>(kind: Kind, value: &T, buf: &mut Vec<u8>) -> Result<(), String> {
    buf.clear();
    buf.extend_from_slice(&MAGIC);
    buf.extend_from_slice(&VERSION.to_le_bytes());
    buf.push(kind as u8);
    bincode::serde::encode_into_std_write(value, buf, config())
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// Encodes a forward sample into `buf` (cleared first).
pub fn encode_forward(v: &Forward, buf: &mut Vec<u8>) -> Result<(), String> {
    encode_into(Kind::Forward, v, buf)
}

/// Encodes a backward sample into `buf` (cleared first).
pub fn encode_backward(v: &Backward, buf: &mut Vec<u8>) -> Result<(), String> {
    encode_into(Kind::Backward, v, buf)
}

fn body<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, Reject> {
    match bincode::serde::decode_from_slice::<T, _>(bytes, config()) {
        Ok((v, used)) if used == bytes.len() => Ok(v),
        _ => Err(Reject::Malformed),
    }
}

/// Decodes one frame.
pub fn decode(bytes: &[u8]) -> Result<Frame, Reject> {
    if bytes.len() < HEADER || bytes.len() > MAX_FRAME || bytes[..4] != MAGIC {
        return Err(Reject::Malformed);
    }
    let version = u16::from_le_bytes([bytes[4], bytes[5]]);
    if version != VERSION {
        return Err(Reject::Version(version));
    }
    match bytes[6] {
        0 => body(&bytes[HEADER..]).map(Frame::Forward),
        1 => body(&bytes[HEADER..]).map(Frame::Backward),
        _ => Err(Reject::Malformed),
    }
}

/// Counts a rejected frame in a receiver's counters, and logs the first frame of
/// another version loudly: it means two builds that do not agree.
pub fn count_reject(r: Reject, stats: &mut crate::link::InboxStats) {
    match r {
        Reject::Malformed => stats.malformed += 1,
        Reject::Version(v) => {
            if stats.wrong_version == 0 {
                tracing::error!(
                    "a peer sends wire format version {v}, this node speaks version {VERSION}: \
                     the two were built from different sources; rebuild both from one"
                );
            }
            stats.wrong_version += 1;
        }
    }
}

/// Counts a received frame (rejected, of the wrong kind, or good) and returns the
/// sample if `want` extracts it.
pub fn count<T: tactile_messages::samples::Sequenced>(
    got: Result<Frame, Reject>,
    want: fn(Frame) -> Option<T>,
    stats: &std::cell::Cell<crate::link::InboxStats>,
    next: &std::cell::Cell<Option<u64>>,
) -> Option<T> {
    let mut st = stats.get();
    let v = match got {
        Ok(f) => {
            let v = want(f);
            if v.is_none() {
                st.malformed += 1;
            }
            v
        }
        Err(r) => {
            count_reject(r, &mut st);
            None
        }
    };
    if let Some(v) = &v {
        let mut n = next.get();
        st.count(v, &mut n);
        next.set(n);
    }
    stats.set(st);
    v
}

/// The forward sample of a frame.
pub fn forward(f: Frame) -> Option<Forward> {
    match f {
        Frame::Forward(v) => Some(v),
        Frame::Backward(_) => None,
    }
}

/// The backward sample of a frame.
pub fn backward(f: Frame) -> Option<Backward> {
    match f {
        Frame::Backward(v) => Some(v),
        Frame::Forward(_) => None,
    }
}

/// A receiving stream's counters, and the publish counter it expects next.
#[derive(Debug, Default)]
pub struct In {
    /// What it counted.
    pub stats: std::cell::Cell<crate::link::InboxStats>,
    /// The sender's next publish counter.
    pub next: std::cell::Cell<Option<u64>>,
}

/// Sends one sample over a link that leaves the host: stamps it with its hop's next
/// publish counter (or the control marker), encodes it into `buf`, hands the frame to
/// `send` (which says how many receivers it reached) and counts it. UDP and Zenoh
/// share this, so they stamp and count exactly as iceoryx2 does.
pub fn send_counted<T: tactile_messages::samples::Sequenced + Copy>(
    mut value: T,
    control: bool,
    stats: &std::cell::Cell<crate::link::OutboxStats>,
    buf: &mut Vec<u8>,
    encode: fn(&T, &mut Vec<u8>) -> Result<(), String>,
    send: impl FnOnce(&[u8]) -> Result<usize, crate::link::LinkError>,
) -> Result<(), crate::link::LinkError> {
    let mut st = stats.get();
    st.stamp(&mut value, control);
    encode(&value, buf).map_err(|detail| crate::link::LinkError {
        context: "encoding a sample".into(),
        detail,
    })?;
    let receivers = send(buf)?;
    st.count(receivers, control);
    stats.set(st);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sample() -> Forward {
        let mut f = Forward {
            seq: 42,
            hop_seq: 7,
            run: 0xdead_beef,
            ..Forward::default()
        };
        f.signal.value = [0.1, -0.2, f64::NAN];
        f.stamps[3] = 123_456_789;
        f
    }

    #[test]
    fn a_sample_survives_the_round_trip() {
        let mut buf = Vec::new();
        encode_forward(&sample(), &mut buf).expect("encode");
        let Ok(Frame::Forward(back)) = decode(&buf) else {
            panic!("decode failed");
        };
        assert_eq!(back.seq, 42);
        assert_eq!(back.run, 0xdead_beef);
        assert!(back.signal.value[2].is_nan());
        let b = Backward {
            seq: 3,
            ..Backward::default()
        };
        encode_backward(&b, &mut buf).expect("encode");
        assert_eq!(decode(&buf), Ok(Frame::Backward(b)));
    }

    #[test]
    fn truncated_versioned_and_foreign_frames_are_rejected() {
        let mut buf = Vec::new();
        encode_forward(&sample(), &mut buf).expect("encode");
        for cut in 0..buf.len() {
            assert_eq!(decode(&buf[..cut]), Err(Reject::Malformed), "cut at {cut}");
        }
        let mut longer = buf.clone();
        longer.push(0);
        assert_eq!(decode(&longer), Err(Reject::Malformed));
        let mut other = buf.clone();
        other[4] = 9;
        assert_eq!(decode(&other), Err(Reject::Version(9)));
        let mut kind = buf.clone();
        kind[6] = 5;
        assert_eq!(decode(&kind), Err(Reject::Malformed));
        assert_eq!(decode(b"hello, world"), Err(Reject::Malformed));
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
            let _ = decode(&bytes);
            let mut framed = MAGIC.to_vec();
            framed.extend_from_slice(&VERSION.to_le_bytes());
            framed.extend_from_slice(&bytes);
            let _ = decode(&framed);
        }
    }
}
