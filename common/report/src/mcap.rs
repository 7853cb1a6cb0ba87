//! An MCAP writer (<https://mcap.dev/spec>), streaming: messages go into a chunk
//! buffer that is compressed (an LZ4 frame, or a zstd frame: [`Compression`]) and written when it passes a size, followed
//! by its message indexes; the summary at the end holds the schemas, channels,
//! statistics, chunk indexes and the offsets of each group, so readers can seek and
//! `ros2 bag info` can count without reading the data. Memory is one chunk plus one
//! index entry per chunk, whatever the length of the run.

use std::collections::BTreeMap;
use std::io::{self, Write};

/// The file's first and last bytes.
pub const MAGIC: [u8; 8] = [0x89, b'M', b'C', b'A', b'P', b'0', b'\r', b'\n'];

/// Record opcodes.
mod op {
    pub const HEADER: u8 = 0x01;
    pub const FOOTER: u8 = 0x02;
    pub const SCHEMA: u8 = 0x03;
    pub const CHANNEL: u8 = 0x04;
    pub const MESSAGE: u8 = 0x05;
    pub const CHUNK: u8 = 0x06;
    pub const MESSAGE_INDEX: u8 = 0x07;
    pub const CHUNK_INDEX: u8 = 0x08;
    pub const STATISTICS: u8 = 0x0B;
    pub const SUMMARY_OFFSET: u8 = 0x0E;
    pub const DATA_END: u8 = 0x0F;
}

/// How chunks are compressed: the two the MCAP spec names, both read by Foxglove,
/// `mcap` and rosbag2.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Compression {
    /// LZ4 frames: the faster to write and to read.
    #[default]
    Lz4,
    /// zstd frames (level 3): the smaller file.
    Zstd,
}

impl Compression {
    /// The name the chunk records carry.
    pub fn name(self) -> &'static str {
        match self {
            Compression::Lz4 => "lz4",
            Compression::Zstd => "zstd",
        }
    }

    fn compress(self, data: &[u8]) -> io::Result<Vec<u8>> {
        match self {
            Compression::Lz4 => {
                let mut enc =
                    lz4_flex::frame::FrameEncoder::new(Vec::with_capacity(data.len() / 2));
                enc.write_all(data)?;
                enc.finish().map_err(io::Error::other)
            }
            Compression::Zstd => zstd::bulk::compress(data, 3),
        }
    }
}

impl std::str::FromStr for Compression {
    type Err = crate::error::UnknownChoice;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "lz4" => Ok(Compression::Lz4),
            "zstd" => Ok(Compression::Zstd),
            _ => Err(crate::error::UnknownChoice {
                given: s.to_string(),
                choices: "lz4 or zstd",
            }),
        }
    }
}

/// Uncompressed bytes a chunk collects before it is written.
pub const CHUNK_BYTES: usize = 1 << 20;

/// Little-endian record fields.
#[derive(Default)]
struct Fields(Vec<u8>);

impl Fields {
    fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    fn u16(&mut self, v: u16) -> &mut Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn u64(&mut self, v: u64) -> &mut Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn str(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32);
        self.0.extend_from_slice(s.as_bytes());
        self
    }
    fn bytes32(&mut self, b: &[u8]) -> &mut Self {
        self.u32(b.len() as u32);
        self.0.extend_from_slice(b);
        self
    }
    /// A map or array: its byte length (u32), then the entries.
    fn prefixed(&mut self, entries: &Fields) -> &mut Self {
        self.bytes32(&entries.0)
    }
}

/// One record: opcode, u64 length, fields.
fn record(opcode: u8, f: &Fields) -> Vec<u8> {
    let mut r = Vec::with_capacity(9 + f.0.len());
    r.push(opcode);
    r.extend_from_slice(&(f.0.len() as u64).to_le_bytes());
    r.extend_from_slice(&f.0);
    r
}

#[derive(Debug)]
struct ChunkIndex {
    start: u64,
    end: u64,
    offset: u64,
    length: u64,
    index_offsets: BTreeMap<u16, u64>,
    index_length: u64,
    compressed: u64,
    uncompressed: u64,
    compression: Compression,
}

/// Writes one MCAP file to `W`.
#[derive(Debug)]
pub struct McapWriter<W: Write> {
    out: W,
    pos: u64,
    schemas: Vec<Vec<u8>>,
    channels: Vec<Vec<u8>>,
    chunk: Vec<u8>,
    chunk_times: Option<(u64, u64)>,
    /// Per channel: (log time, offset in the chunk's records) of the chunk's messages.
    chunk_messages: BTreeMap<u16, Vec<(u64, u64)>>,
    chunks: Vec<ChunkIndex>,
    counts: BTreeMap<u16, u64>,
    times: Option<(u64, u64)>,
    compression: Compression,
}

impl<W: Write> McapWriter<W> {
    /// Starts the file: magic and header (`profile` "ros2" for ROS 2 messages).
    pub fn new(out: W, profile: &str, library: &str) -> io::Result<Self> {
        let mut w = McapWriter {
            out,
            pos: 0,
            schemas: Vec::new(),
            channels: Vec::new(),
            chunk: Vec::with_capacity(CHUNK_BYTES + (64 << 10)),
            chunk_times: None,
            chunk_messages: BTreeMap::new(),
            chunks: Vec::new(),
            counts: BTreeMap::new(),
            times: None,
            compression: Compression::default(),
        };
        w.put(&MAGIC)?;
        w.put(&record(
            op::HEADER,
            Fields::default().str(profile).str(library),
        ))?;
        Ok(w)
    }

    /// Compresses the chunks from here on with `c` (LZ4 unless told).
    pub fn compress_with(&mut self, c: Compression) {
        self.compression = c;
    }

    fn put(&mut self, b: &[u8]) -> io::Result<()> {
        self.out.write_all(b)?;
        self.pos += b.len() as u64;
        Ok(())
    }

    /// Declares a schema; returns its id (1, 2, ...).
    pub fn schema(&mut self, name: &str, encoding: &str, data: &[u8]) -> io::Result<u16> {
        let id = self.schemas.len() as u16 + 1;
        let r = record(
            op::SCHEMA,
            Fields::default()
                .u16(id)
                .str(name)
                .str(encoding)
                .bytes32(data),
        );
        self.put(&r)?;
        self.schemas.push(r);
        Ok(id)
    }

    /// Declares a channel on `topic` with `schema`; returns its id (0, 1, ...).
    pub fn channel(&mut self, topic: &str, schema: u16, encoding: &str) -> io::Result<u16> {
        let id = self.channels.len() as u16;
        let r = record(
            op::CHANNEL,
            Fields::default()
                .u16(id)
                .u16(schema)
                .str(topic)
                .str(encoding)
                .prefixed(&Fields::default()),
        );
        self.put(&r)?;
        self.channels.push(r);
        Ok(id)
    }

    /// Adds a message; writes the chunk when it is full.
    pub fn message(
        &mut self,
        channel: u16,
        sequence: u32,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> io::Result<()> {
        let offset = self.chunk.len() as u64;
        self.chunk.push(op::MESSAGE);
        self.chunk
            .extend_from_slice(&(22 + data.len() as u64).to_le_bytes());
        self.chunk.extend_from_slice(&channel.to_le_bytes());
        self.chunk.extend_from_slice(&sequence.to_le_bytes());
        self.chunk.extend_from_slice(&log_time.to_le_bytes());
        self.chunk.extend_from_slice(&publish_time.to_le_bytes());
        self.chunk.extend_from_slice(data);
        self.chunk_messages
            .entry(channel)
            .or_default()
            .push((log_time, offset));
        *self.counts.entry(channel).or_default() += 1;
        let widen = |t: Option<(u64, u64)>| {
            Some(t.map_or((log_time, log_time), |(a, b)| {
                (a.min(log_time), b.max(log_time))
            }))
        };
        self.chunk_times = widen(self.chunk_times);
        self.times = widen(self.times);
        if self.chunk.len() >= CHUNK_BYTES {
            self.flush_chunk()?;
        }
        Ok(())
    }

    fn flush_chunk(&mut self) -> io::Result<()> {
        let Some((start, end)) = self.chunk_times.take() else {
            return Ok(());
        };
        let crc = crc32fast::hash(&self.chunk);
        let compressed = self.compression.compress(&self.chunk)?;
        let mut f = Fields::default();
        f.u64(start)
            .u64(end)
            .u64(self.chunk.len() as u64)
            .u32(crc)
            .str(self.compression.name())
            .u64(compressed.len() as u64);
        f.0.extend_from_slice(&compressed);
        let chunk = record(op::CHUNK, &f);
        let offset = self.pos;
        self.put(&chunk)?;
        let index_start = self.pos;
        let mut index_offsets = BTreeMap::new();
        for (channel, entries) in std::mem::take(&mut self.chunk_messages) {
            let mut list = Fields::default();
            for (t, o) in entries {
                list.u64(t).u64(o);
            }
            index_offsets.insert(channel, self.pos);
            self.put(&record(
                op::MESSAGE_INDEX,
                Fields::default().u16(channel).prefixed(&list),
            ))?;
        }
        self.chunks.push(ChunkIndex {
            start,
            end,
            offset,
            length: chunk.len() as u64,
            index_offsets,
            index_length: self.pos - index_start,
            compressed: compressed.len() as u64,
            uncompressed: self.chunk.len() as u64,
            compression: self.compression,
        });
        self.chunk.clear();
        Ok(())
    }

    /// Writes the last chunk, the summary and the footer; returns the writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.flush_chunk()?;
        self.put(&record(op::DATA_END, Fields::default().u32(0)))?;
        let summary_start = self.pos;
        let mut summary = Vec::new();
        let mut groups = Vec::new();
        let mut group = |opcode: u8, records: Vec<Vec<u8>>, summary: &mut Vec<u8>| {
            if records.is_empty() {
                return;
            }
            let start = summary_start + summary.len() as u64;
            records.iter().for_each(|r| summary.extend_from_slice(r));
            groups.push((opcode, start, summary_start + summary.len() as u64 - start));
        };
        group(op::SCHEMA, self.schemas.clone(), &mut summary);
        group(op::CHANNEL, self.channels.clone(), &mut summary);
        group(op::STATISTICS, vec![self.statistics()], &mut summary);
        let indexes = self.chunks.iter().map(chunk_index).collect();
        group(op::CHUNK_INDEX, indexes, &mut summary);
        let offsets_start = summary_start + summary.len() as u64;
        for (opcode, start, length) in groups {
            summary.extend(record(
                op::SUMMARY_OFFSET,
                Fields::default().u8(opcode).u64(start).u64(length),
            ));
        }
        // The footer's CRC covers the summary and the footer up to the CRC itself.
        let mut footer = vec![op::FOOTER];
        footer.extend_from_slice(&20u64.to_le_bytes());
        footer.extend_from_slice(&summary_start.to_le_bytes());
        footer.extend_from_slice(&offsets_start.to_le_bytes());
        let mut crc = crc32fast::Hasher::new();
        crc.update(&summary);
        crc.update(&footer);
        footer.extend_from_slice(&crc.finalize().to_le_bytes());
        self.put(&summary)?;
        self.put(&footer)?;
        self.put(&MAGIC)?;
        self.out.flush()?;
        Ok(self.out)
    }

    fn statistics(&self) -> Vec<u8> {
        let (start, end) = self.times.unwrap_or((0, 0));
        let mut counts = Fields::default();
        for (c, n) in &self.counts {
            counts.u16(*c).u64(*n);
        }
        let mut f = Fields::default();
        f.u64(self.counts.values().sum())
            .u16(self.schemas.len() as u16)
            .u32(self.channels.len() as u32)
            .u32(0)
            .u32(0)
            .u32(self.chunks.len() as u32)
            .u64(start)
            .u64(end)
            .prefixed(&counts);
        record(op::STATISTICS, &f)
    }
}

fn chunk_index(c: &ChunkIndex) -> Vec<u8> {
    let mut offsets = Fields::default();
    for (ch, o) in &c.index_offsets {
        offsets.u16(*ch).u64(*o);
    }
    let mut f = Fields::default();
    f.u64(c.start)
        .u64(c.end)
        .u64(c.offset)
        .u64(c.length)
        .prefixed(&offsets)
        .u64(c.index_length)
        .str(c.compression.name())
        .u64(c.compressed)
        .u64(c.uncompressed);
    record(op::CHUNK_INDEX, &f)
}
