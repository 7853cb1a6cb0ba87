//! The wire format of the hops that leave the host (UDP, Zenoh): a header, then the
//! sample encoded with bincode 2.
//!
//! Header: 4 bytes of magic (`TCTL`), the format version (`u16`, little-endian) and the
//! kind of sample (forward or backward); the sample itself carries its run token. Two
//! builds whose formats differ refuse each other's samples with a clear error instead
//! of misreading them; bytes from a stranger (no magic), truncated or trailing bytes
//! are rejected and counted, never used. Nothing the network delivers can make a node
//! panic: every field is checked by the decoder.

use crate::streams::Kind;
use serde::{de::DeserializeOwned, Serialize};
use std::collections::VecDeque;
use tactile_messages::samples::{Backward, Forward, Sequenced};
use tactile_messages::stream::{InboxStats, OutboxStats};

/// First bytes of every frame.
pub const MAGIC: [u8; 4] = *b"TCTL";
/// The format version; bump it whenever a sample's layout changes.
pub const VERSION: u16 = 5;
/// Header length, bytes.
pub const HEADER: usize = 7;
/// Largest frame a receiver accepts (a sample is about 250 bytes).
pub const MAX_FRAME: usize = 4096;

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

fn encode_into<T: Serialize>(
    kind: Kind,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), bincode::error::EncodeError> {
    buf.clear();
    buf.extend_from_slice(&MAGIC);
    buf.extend_from_slice(&VERSION.to_le_bytes());
    buf.push(kind as u8);
    bincode::serde::encode_into_std_write(value, buf, config()).map(|_| ())
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

/// A sample type that crosses the wire: its kind in the header and how to take it
/// out of a decoded frame.
pub trait OnWire: Sequenced + Copy + Serialize + DeserializeOwned {
    /// The header's kind.
    const KIND: Kind;
    /// The sample of a frame of this kind.
    fn of(f: Frame) -> Option<Self>;
}

impl OnWire for Forward {
    const KIND: Kind = Kind::Forward;
    fn of(f: Frame) -> Option<Self> {
        match f {
            Frame::Forward(v) => Some(v),
            Frame::Backward(_) => None,
        }
    }
}

impl OnWire for Backward {
    const KIND: Kind = Kind::Backward;
    fn of(f: Frame) -> Option<Self> {
        match f {
            Frame::Backward(v) => Some(v),
            Frame::Forward(_) => None,
        }
    }
}

/// Encodes `value` as one frame into `buf` (cleared first).
pub fn encode<T: OnWire>(value: &T, buf: &mut Vec<u8>) -> Result<(), bincode::error::EncodeError> {
    encode_into(T::KIND, value, buf)
}

/// Stamps a copy of `value` with its hop's next publish counter (or the control
/// marker), encodes it into `buf`, hands the frame to `send` (which says how many
/// receivers it reached) and counts it: UDP and Zenoh stamp and count exactly as
/// iceoryx2 does.
pub fn send_counted<T: OnWire>(
    value: &T,
    control: bool,
    stats: &mut OutboxStats,
    buf: &mut Vec<u8>,
    send: impl FnOnce(&[u8]) -> Result<usize, crate::LinkError>,
) -> Result<(), crate::LinkError> {
    let mut value = *value;
    stats.stamp(&mut value, control);
    encode(&value, buf).map_err(|e| crate::LinkError::new("encoding a sample", e))?;
    let receivers = send(buf)?;
    stats.count(receivers, control);
    Ok(())
}

/// Frames a receiving end holds for a stream its node has not taken yet.
pub const PARKED: usize = 1024;

/// The frames of one source (a node's UDP socket, its Zenoh session) sorted into its
/// two streams in: a frame of the stream asked for is returned, one of the other is
/// kept for it (up to [`PARKED`], then dropped and counted), and each stream counts
/// what it took and lost. What is not a frame of a stream the node takes belongs to no
/// stream: it is counted against the node's forward stream in if it has one (the
/// first it takes), else its backward one.
#[derive(Debug, Default)]
pub struct Demux {
    parked: [VecDeque<Frame>; 2],
    stats: [InboxStats; 2],
    next: [Option<u64>; 2],
    /// Which kinds the node subscribes to: a frame of another kind is refused.
    wanted: [bool; 2],
}

impl Demux {
    /// A demultiplexer for a node that takes the streams of kinds `wanted`.
    pub fn new(wanted: &[Kind]) -> Demux {
        let mut d = Demux::default();
        for k in wanted {
            d.wanted[*k as usize] = true;
        }
        d
    }

    /// The next sample of kind `T::KIND`: one kept earlier, else the next good one
    /// `read` yields (it fills the buffer with a received payload and says whether it
    /// got one). Every payload read on the way is counted against its stream (or, not
    /// a whole frame, against `T`'s).
    pub fn take<T: OnWire>(
        &mut self,
        buf: &mut Vec<u8>,
        mut read: impl FnMut(&mut Vec<u8>) -> bool,
    ) -> Option<T> {
        let k = T::KIND as usize;
        if let Some(f) = self.parked[k].pop_front() {
            return T::of(f);
        }
        while read(buf) {
            match decode(buf) {
                Ok(f) => {
                    let kind = match f {
                        Frame::Forward(_) => Kind::Forward,
                        Frame::Backward(_) => Kind::Backward,
                    } as usize;
                    if !self.wanted[kind] {
                        self.stats[self.strays()].malformed += 1;
                        continue;
                    }
                    self.count(kind, &f);
                    if kind == k {
                        return T::of(f);
                    }
                    if self.parked[kind].len() < PARKED {
                        self.parked[kind].push_back(f);
                    } else {
                        self.stats[kind].overwritten += 1;
                    }
                }
                Err(r) => {
                    let strays = self.strays();
                    count_reject(r, &mut self.stats[strays]);
                }
            }
        }
        None
    }

    /// The stream that counts what belongs to none.
    fn strays(&self) -> usize {
        if self.wanted[Kind::Forward as usize] {
            Kind::Forward as usize
        } else {
            Kind::Backward as usize
        }
    }

    fn count(&mut self, kind: usize, f: &Frame) {
        let (stats, next) = (&mut self.stats[kind], &mut self.next[kind]);
        match f {
            Frame::Forward(v) => stats.count(v, next),
            Frame::Backward(v) => stats.count(v, next),
        }
    }

    /// What the stream of `kind` counted.
    pub fn stats(&self, kind: Kind) -> InboxStats {
        self.stats[kind as usize]
    }
}

/// Counts a rejected frame in a receiver's counters, and logs the first frame of
/// another version loudly: it means two builds that do not agree.
pub fn count_reject(r: Reject, stats: &mut InboxStats) {
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
        encode(&sample(), &mut buf).expect("encode");
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
        encode(&b, &mut buf).expect("encode");
        assert_eq!(decode(&buf), Ok(Frame::Backward(b)));
    }

    #[test]
    fn truncated_versioned_and_foreign_frames_are_rejected() {
        let mut buf = Vec::new();
        encode(&sample(), &mut buf).expect("encode");
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
