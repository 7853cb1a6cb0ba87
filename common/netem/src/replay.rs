//! Recorded networks replayed packet by packet: per-packet delays and losses from a
//! CSV, or a [`Link`] (a Mahimahi delivery trace or a fixed rate, and a queue).

use crate::link::{
    Arithmetic, Bound, ClassSpec, Codel, CodelParams, Fifo, FqCodel, FqCodelParams, Link,
    Opportunities, Pie, PieParams, Priority, Queue, RateSteps, Server, Weighted,
};
use rand_chacha::ChaCha8Rng;
use tactile_scenario::{CodelArithmetic, LinkConfig, QueueKind};

/// What is wrong in a replay file; each message names the line.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReplayError {
    /// A CSV whose first line is not `delay,lost`.
    #[error("line 1: header is {0:?}, expected delay,lost")]
    Header(String),
    /// An empty CSV.
    #[error("empty: expected the header delay,lost")]
    Empty,
    /// A row of another number of columns.
    #[error("line {0}: expected 2 columns (delay,lost)")]
    Columns(usize),
    /// A delay that is no whole number of samples in range.
    #[error("line {line}: delay {delay} is not a whole number of samples in 0..=100000")]
    Delay {
        /// The line.
        line: usize,
        /// The delay as written.
        delay: String,
    },
    /// A loss that is neither 0 nor 1.
    #[error("line {line}: lost {lost} is not 0 or 1")]
    Lost {
        /// The line.
        line: usize,
        /// The loss as written.
        lost: String,
    },
    /// A header and nothing else.
    #[error("no packets after the header")]
    NoPackets,
    /// A Mahimahi line that is no whole number of milliseconds.
    #[error("line {line}: {text:?} is not a whole number of milliseconds")]
    NotMs {
        /// The line.
        line: usize,
        /// What it holds.
        text: String,
        /// Why it is no number.
        source: std::num::ParseIntError,
    },
    /// A Mahimahi time before the one above it.
    #[error("line {line}: {ms} ms goes back in time")]
    Backwards {
        /// The line.
        line: usize,
        /// The time.
        ms: u64,
    },
    /// A Mahimahi trace with no line.
    #[error("no delivery opportunities")]
    NoOpportunities,
    /// A Mahimahi trace of only time 0.
    #[error("the trace lasts 0 ms")]
    Instant,
    /// A rate trace whose first line is not `time_ms,rate_bps`.
    #[error("line 1: header is {0:?}, expected time_ms,rate_bps")]
    RateHeader(String),
    /// A rate trace's row that is no step.
    #[error("line {line}: {text:?}: {why}")]
    RateRow {
        /// The line.
        line: usize,
        /// What it holds.
        text: String,
        /// What is wrong.
        why: &'static str,
    },
    /// A rate trace with a header and nothing else.
    #[error("no rates after the header")]
    NoSteps,
    /// A rate trace whose last rate is 0: the link would stop for good.
    #[error("the last rate is 0: the link would stop for good")]
    Stops,
    /// A Mahimahi trace of more opportunities than a link keeps.
    #[error("line {line}: more than {max} delivery opportunities")]
    TooLong {
        /// The first line past the limit.
        line: usize,
        /// The limit.
        max: usize,
    },
}

/// A loaded replay: each packet's delay (samples) and whether it is lost, or a link.
#[derive(Debug, Clone, PartialEq)]
pub enum Replay {
    /// Rows of a CSV file, one per packet sent, looped; the number of packets so far.
    Packets(Vec<(u32, bool)>, u64),
    /// A link with a rate and a queue: the channel runs it ([`LinkSpec::build`]).
    Link(LinkSpec),
}

/// A link as a scenario sets it: its server, its queue discipline and bound, and its
/// packets' size on the wire.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkSpec {
    /// A trace or a rate.
    pub server: Server,
    /// mm-link's discipline.
    pub queue: QueueKind,
    /// Its bound (none for `infinite`).
    pub bound: Bound,
    /// Each packet's size on the wire, bytes (payload and headers).
    pub packet_bytes: u32,
    /// The parameters of the discipline `queue` names beyond mm-link's.
    pub aqm: AqmSpec,
}

/// The parameters of CoDel, FQ-CoDel, PIE and the class schedulers (the RFCs'
/// defaults where a scenario gives none).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AqmSpec {
    /// CoDel's.
    pub codel: CodelParams,
    /// FQ-CoDel's.
    pub fq_codel: FqCodelParams,
    /// PIE's.
    pub pie: PieParams,
    /// The classes of `priority` or `weighted`.
    pub classes: Vec<ClassSpec>,
    /// `weighted`'s quantum of a weight of 1, bytes.
    pub quantum: u32,
}

fn arithmetic(a: CodelArithmetic) -> Arithmetic {
    match a {
        CodelArithmetic::Rfc => Arithmetic::Rfc,
        CodelArithmetic::Linux => Arithmetic::Linux,
    }
}

/// Milliseconds as whole ns.
fn ns(ms: f64) -> u64 {
    (ms * 1e6).round() as u64
}

impl AqmSpec {
    /// The parameters `cfg` sets.
    pub fn new(cfg: &LinkConfig) -> AqmSpec {
        let c = cfg.codel.unwrap_or_default();
        let codel = CodelParams {
            target_ns: ns(c.target_ms),
            interval_ns: ns(c.interval_ms),
            mtu_bytes: c.mtu_bytes,
            arithmetic: arithmetic(c.arithmetic),
        };
        let f = cfg.fq_codel.unwrap_or_default();
        let fq_codel = FqCodelParams {
            codel: CodelParams {
                target_ns: ns(f.target_ms),
                interval_ns: ns(f.interval_ms),
                mtu_bytes: f.mtu_bytes,
                arithmetic: arithmetic(f.arithmetic),
            },
            quantum: f.quantum,
            flows: f.flows,
            limit: f.limit,
            drop_batch: f.drop_batch,
        };
        let p = cfg.pie.unwrap_or_default();
        let pie = PieParams {
            target_ns: ns(p.target_ms),
            tupdate_ns: ns(p.tupdate_ms),
            alpha: p.alpha,
            beta: p.beta,
            max_burst_ns: ns(p.max_burst_ms),
            mean_packet_bytes: p.mean_packet_bytes,
        };
        let (classes, quantum) = match (&cfg.priority, &cfg.weighted) {
            (Some(p), _) if cfg.queue == QueueKind::Priority => (p.classes.as_slice(), 1514),
            (_, Some(w)) => (w.classes.as_slice(), w.quantum),
            _ => (&[][..], 1514),
        };
        let classes = classes
            .iter()
            .map(|c| ClassSpec {
                flows: c.flows.clone(),
                bound: Bound {
                    packets: c.packets.unwrap_or(0),
                    bytes: c.bytes.unwrap_or(0),
                },
                weight: c.weight.unwrap_or(1),
            })
            .collect();
        AqmSpec {
            codel,
            fq_codel,
            pie,
            classes,
            quantum,
        }
    }
}

impl LinkSpec {
    /// The link of `cfg` served by `server` (its trace read, or its rate).
    pub fn new(cfg: &LinkConfig, server: Server) -> LinkSpec {
        LinkSpec {
            server,
            queue: cfg.queue,
            bound: Bound {
                packets: cfg.packets.unwrap_or(0),
                bytes: cfg.bytes.unwrap_or(0),
            },
            packet_bytes: u32::try_from(cfg.packet_bytes()).unwrap_or(u32::MAX),
            aqm: AqmSpec::new(cfg),
        }
    }

    /// Parses a rate trace (`time_ms,rate_bps`) into the link `cfg` sets.
    pub fn parse_rates(text: &str, cfg: &LinkConfig) -> Result<LinkSpec, ReplayError> {
        Ok(LinkSpec::new(cfg, Server::Steps(RateSteps::parse(text)?)))
    }

    /// The link of `cfg` when it needs no file (a fixed rate).
    pub fn of_rate(cfg: &LinkConfig) -> Option<LinkSpec> {
        cfg.rate.map(|r| LinkSpec::new(cfg, Server::Rate(r)))
    }

    /// The link, empty at time 0, counting one flow; PIE draws from `rng`.
    pub fn build(&self, rng: ChaCha8Rng) -> Link {
        let a = &self.aqm;
        let queue: Box<dyn Queue> = match self.queue {
            QueueKind::Infinite => Box::new(Fifo::infinite()),
            QueueKind::Droptail => Box::new(Fifo::drop_tail(self.bound)),
            QueueKind::Drophead => Box::new(Fifo::drop_head(self.bound)),
            QueueKind::Codel => Box::new(Codel::new(a.codel, self.bound)),
            QueueKind::FqCodel => Box::new(FqCodel::new(a.fq_codel)),
            QueueKind::Pie => Box::new(Pie::new(a.pie, self.bound, rng)),
            QueueKind::Priority => Box::new(Priority::new(&a.classes)),
            QueueKind::Weighted => Box::new(Weighted::new(&a.classes, a.quantum)),
        };
        Link::new(self.server.clone(), queue, 1)
    }
}

impl Replay {
    /// Parses a CSV replay: header `delay,lost`; the error names the line. Rows are
    /// read straight into 5 bytes each (a replay file may hold hours of packets).
    pub fn parse_csv(text: &str) -> Result<Replay, ReplayError> {
        let mut lines = text.lines().enumerate();
        match lines.next() {
            Some((_, h)) if h.trim().replace(' ', "") == "delay,lost" => {}
            Some((_, h)) => return Err(ReplayError::Header(h.to_string())),
            None => return Err(ReplayError::Empty),
        }
        let mut out = Vec::new();
        for (k, raw) in lines {
            let line = k + 1;
            let row = raw.trim();
            if row.is_empty() {
                continue;
            }
            let mut cells = row.split(',').map(str::trim);
            let (Some(d), Some(l), None) = (cells.next(), cells.next(), cells.next()) else {
                return Err(ReplayError::Columns(line));
            };
            let d: u32 = d
                .parse()
                .ok()
                .filter(|d| i64::from(*d) <= tactile_scenario::MAX_DELAY_SAMPLES)
                .ok_or_else(|| ReplayError::Delay {
                    line,
                    delay: d.to_string(),
                })?;
            let l = match l {
                "0" => false,
                "1" => true,
                other => {
                    return Err(ReplayError::Lost {
                        line,
                        lost: other.to_string(),
                    })
                }
            };
            out.push((d, l));
        }
        if out.is_empty() {
            return Err(ReplayError::NoPackets);
        }
        Ok(Replay::Packets(out, 0))
    }

    /// Parses a Mahimahi trace (one non-decreasing millisecond timestamp per line)
    /// into the link `cfg` sets.
    pub fn parse_mahimahi(text: &str, cfg: &LinkConfig) -> Result<Replay, ReplayError> {
        let ops = Opportunities::parse(text)?;
        Ok(Replay::Link(LinkSpec::new(cfg, Server::Trace(ops))))
    }

    /// The largest delay a packet can be given, samples.
    pub fn bound(&self) -> u32 {
        match self {
            Replay::Packets(rows, _) => rows.iter().map(|r| r.0).max().unwrap_or(0),
            Replay::Link(_) => 0,
        }
    }

    /// The next sample's packet if `sent` (a sample its codec did not send is no
    /// packet: it takes no row): its delay in samples and whether it is lost.
    pub fn packet(&mut self, sent: bool) -> (u32, bool) {
        if !sent {
            return (0, false);
        }
        match self {
            Replay::Packets(rows, k) => {
                let r = rows[(*k % rows.len() as u64) as usize];
                *k += 1;
                r
            }
            // The channel runs a link itself; it never asks it for a delay.
            Replay::Link(_) => (0, false),
        }
    }
}
