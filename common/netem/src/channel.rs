//! The paper's channel model, v_i(n) = c_i(n - d_i(n)) + r_i(n), as pure code.
//!
//! The emulator process feeds each arriving sample into a [`Channel`] and sends what
//! comes out; the in-process simulation does the same, so both produce identical
//! values. Each of the three signals has its own delay (whole samples, constant or
//! scheduled, plus the packet's jitter when configured) and its own zero-mean Gaussian
//! noise. Each packet sent at n arrives at n + d(n); at each sample the receiver gets
//! the newest packet that has arrived (a packet overtaken by a newer one is of no use
//! to it), or, when none has arrived since the last, the same value again, flagged.
//! With a constant delay this is exactly c(n - d). Every output value carries the
//! origin (sequence and timestamp) of the input value it came from and the delay that
//! was injected, so the master can tell injected delay from system overhead; the noise
//! actually added is returned too. A 6-DoF sample's rotational half (an orientation
//! forward, a torque backward) rides in the packet of the first signal: it arrives
//! with it, is held with it, and is never noised (the scenario makes a 6-DoF run's
//! three delays equal, so the whole pose arrives together).

use crate::histogram::{Drawn, HistogramDelay};
use crate::link::FlowStats;
use crate::{Jitter, Replay};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::collections::VecDeque;
use tactile_scenario::ChannelConfig;

/// One signal value with its provenance.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Value {
    /// The signal value.
    pub v: f64,
    /// The sender's input energy, delayed with the value and never noised, J.
    pub energy: f64,
    /// The sender's sample number for this value.
    pub sent_seq: u64,
    /// Master sample number this value originates from.
    pub origin_seq: u64,
    /// Master's CLOCK_MONOTONIC timestamp of that sample, ns.
    pub origin_ns: u64,
    /// Delay the network added so far along its path, samples: the value's age at
    /// each channel's output (its packet's delay, plus any time it was held because
    /// no newer packet had arrived).
    pub delay_samples: u32,
}

/// What a channel emits for one input sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Emitted {
    /// The delayed, noisy values.
    pub values: [Value; 3],
    /// The noise added to each value.
    pub noise: [f64; 3],
    /// The rest of the sample that came with the first value's packet.
    pub extra: Rest,
    /// The jitter drawn for the input packet, samples (before rounding).
    pub jitter: f64,
    /// True if a replayed network lost the input packet.
    pub lost: bool,
    /// True if the input packet was sent twice (netem's `duplicate`).
    pub duplicated: bool,
    /// True if no new packet arrived for this sample: the last value again (or, before
    /// the first arrival, the first value sent).
    pub substituted: bool,
}

#[derive(Debug, Clone, Copy)]
struct Slot {
    seq: u64,
    values: [Value; 3],
    extra: Rest,
}

/// A sample's rest beside its three values, carried whole in the first value's packet,
/// so it arrives with the values it came with, however late; never noised.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rest {
    /// A 6-DoF sample's rotational half: an orientation forward, a torque backward.
    pub rotation: [f64; 4],
    /// The flags that belong to the packet (the clutch's).
    pub flags: u32,
    /// An environment model the packet carries (model-mediated teleoperation's plane:
    /// normal, offset, stiffness), opaque here.
    pub model: [f64; 5],
    /// That model's number (0: none).
    pub model_seq: u64,
}

/// One signal's packets in flight: `(arrival sample, newest sequence arriving then)`
/// by arrival, one entry a sample; and the newest arrived, its value copied on arrival
/// (its ring slot may be reused while the receiver still holds it). A queue, not a
/// map: packets mostly arrive in sending order, joining at the back and leaving at the
/// front (a map rebalanced twice a packet); one that overtakes (jitter with `reorder`)
/// is inserted, moving at most the packets in flight (bounded by the longest delay).
#[derive(Debug, Clone, Default)]
struct InFlight {
    arriving: VecDeque<(u64, u64)>,
    newest: Option<(u64, Value, Rest)>,
    last_arrival: u64,
    last_emitted: Option<u64>,
}

impl InFlight {
    /// Packet `seq` arrives at `at`.
    fn send(&mut self, seq: u64, at: u64) {
        self.last_arrival = self.last_arrival.max(at);
        // Mostly the packet arrives after all those in flight: it joins at the back.
        if self.arriving.back().is_none_or(|&(a, _)| a < at) {
            self.arriving.push_back((at, seq));
            return;
        }
        let i = self.arriving.partition_point(|&(a, _)| a < at);
        match self.arriving.get_mut(i) {
            Some((a, s)) if *a == at => *s = (*s).max(seq),
            _ => self.arriving.insert(i, (at, seq)),
        }
    }

    /// The newest packet arrived by sample `now`, its value read from `ring` as it
    /// arrives (every packet arrives within the ring's length of being sent, and
    /// [`Channel::push_packet`] takes what arrived before it writes a slot, so the
    /// packet's slot still holds it then).
    fn receive(&mut self, now: u64, ring: &[Option<Slot>], i: usize) -> Option<(u64, Value, Rest)> {
        while let Some(&(at, seq)) = self.arriving.front() {
            if at > now {
                break;
            }
            self.arriving.pop_front();
            if self.newest.is_none_or(|(n, ..)| seq > n) {
                // By reference: a slot is 144 bytes, read three times a packet.
                if let Some(s) = ring[slot_of(ring, seq)].as_ref().filter(|s| s.seq == seq) {
                    self.newest = Some((seq, s.values[i], s.extra));
                }
            }
        }
        self.newest
    }
}

/// A ring of at least `len` slots for the packets in flight: a power of two, so a
/// packet's slot is its number's low bits, not a division per packet and axis (with
/// the queue's join at the back in [`InFlight::send`], a zero-delay channel went from
/// 70 to 59 ns a sample, the `channel` bench). A packet is read from its slot by the
/// time a later one can take it (`len` is more than the longest delay, and
/// [`Channel::push_packet`] takes what arrived before it writes), so a larger ring
/// than needed changes nothing. Delays are bounded (the scenario allows at most
/// 100,000 samples), so this at most doubles the ring.
fn ring(len: usize) -> Vec<Option<Slot>> {
    vec![None; len.max(1).next_power_of_two()]
}

/// Packet `seq`'s slot in `ring` (of [`ring`]'s power-of-two length).
fn slot_of(ring: &[Option<Slot>], seq: u64) -> usize {
    (seq as usize) & (ring.len() - 1)
}

/// Largest step between successive sample numbers a channel takes: a sender's numbers
/// that jump further are not a network's packets (a peer's bug or a forgery), and are
/// carried as no packet at all.
pub const MAX_SEQ_JUMP: u64 = 1 << 20;

/// One direction of the emulated network.
#[derive(Debug)]
pub struct Channel {
    delay: [u32; 3],
    schedule: Vec<(u64, [u32; 3])>,
    noise: [Option<Normal<f64>>; 3],
    rng: ChaCha8Rng,
    ring: Vec<Option<Slot>>,
    /// The jitter, or a histogram's delays, and its own random stream.
    jitter: Option<(Drawn, ChaCha8Rng)>,
    reorder: bool,
    flight: [InFlight; 3],
    replay: Option<(Replay, f64)>,
    duplicate: Option<(f64, ChaCha8Rng)>,
    first: Option<Slot>,
    last_seq: Option<u64>,
    /// No delay, jitter, replay or duplication: [`Channel::push_direct`].
    direct: bool,
    /// On the direct path, the newest packet: the last one sent.
    newest: Option<Slot>,
    /// A link with a rate and a queue carries the packets: [`Channel::push_link`].
    link: Option<Box<link_path::OnLink>>,
    /// The link's own random stream (PIE's draws), stream + 500: a link leaves the
    /// other streams' draws where they were.
    link_rng: ChaCha8Rng,
}

/// Seeds of the two channels differ so their noise is independent.
pub const FORWARD_STREAM: u64 = 1;
/// See [`FORWARD_STREAM`].
pub const BACKWARD_STREAM: u64 = 2;

impl Channel {
    /// A channel from a validated configuration; `stream` separates the random streams
    /// of channels sharing one scenario seed.
    pub fn new(cfg: &ChannelConfig, seed: u64, stream: u64) -> Channel {
        let to_u32 = |d: i64| u32::try_from(d.max(0)).unwrap_or(u32::MAX);
        let delay = cfg.delay.map(to_u32);
        let schedule: Vec<(u64, [u32; 3])> = cfg
            .schedule
            .iter()
            .map(|e| {
                (
                    e[0].max(0) as u64,
                    [to_u32(e[1]), to_u32(e[2]), to_u32(e[3])],
                )
            })
            .collect();
        let jitter_bound = cfg.jitter.as_ref().map_or(0, |j| j.bound().ceil() as usize);
        let max_delay = schedule
            .iter()
            .flat_map(|(_, d)| d.iter().copied())
            .chain(delay.iter().copied())
            .max()
            .unwrap_or(0) as usize
            + jitter_bound;
        let noise = cfg
            .noise_std
            .map(|s| (s > 0.0).then(|| Normal::new(0.0, s).ok()).flatten());
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        // The jitter's own random stream, so enabling it leaves the noise unchanged.
        let jitter = cfg.jitter.as_ref().map(|j| {
            let mut r = ChaCha8Rng::seed_from_u64(seed);
            r.set_stream(stream + 200);
            (Drawn::Jitter(Jitter::new(j)), r)
        });
        // Duplication draws from its own stream, so turning it on leaves the others'
        // draws unchanged.
        let duplicate = (cfg.duplicate > 0.0).then(|| {
            let mut r = ChaCha8Rng::seed_from_u64(seed);
            r.set_stream(stream + 300);
            (cfg.duplicate, r)
        });
        // Every packet arrives the sample it is sent (a replay, set later, says not).
        let direct =
            delay == [0; 3] && schedule.is_empty() && jitter.is_none() && duplicate.is_none();
        Channel {
            delay,
            schedule,
            noise,
            rng,
            ring: ring(max_delay + 1),
            jitter,
            reorder: cfg.reorder,
            flight: Default::default(),
            replay: None,
            duplicate,
            first: None,
            last_seq: None,
            direct,
            newest: None,
            link: None,
            link_rng: {
                let mut r = ChaCha8Rng::seed_from_u64(seed);
                r.set_stream(stream + 500);
                r
            },
        }
    }

    /// The same channel driven by a recorded network (`t_s`: the sampling period):
    /// each packet's delay and loss come from it.
    pub fn with_replay(mut self, replay: Replay, t_s: f64) -> Channel {
        self.direct = false;
        if let Replay::Link(spec) = &replay {
            let rng = self.link_rng.clone();
            self.link = Some(Box::new(link_path::OnLink::new(spec, t_s, rng)));
            return self;
        }
        let need = replay.bound() as usize + 1;
        if self.ring.len() < need {
            self.ring = ring(need);
        }
        self.replay = Some((replay, t_s));
        self.direct = false;
        self
    }

    /// The same channel drawing each packet's whole delay from `h` (in samples) on a
    /// random stream of its own, so turning it on leaves the noise, the faults, the
    /// loss model and the duplicates where they were. It takes the jitter's place: one
    /// draw a sample, sent or not; a duplicate's copy draws its own; `reorder` as for
    /// jitter. (The scenario leaves `delay`, `schedule`, `jitter` and `replay` out.)
    pub fn with_histogram(mut self, h: HistogramDelay, seed: u64, stream: u64) -> Channel {
        self.ring = ring(self.ring.len() + h.bound().ceil() as usize + 1);
        let mut r = ChaCha8Rng::seed_from_u64(seed);
        r.set_stream(stream + 400);
        self.jitter = Some((Drawn::Histogram(h), r));
        self.direct = false;
        self
    }

    /// What a link carrying this channel counted for its packets (none without a
    /// link): offered, departed, dropped, dropped at the memory cap, and their time
    /// on the link (the queueing delay, with the serialisation).
    pub fn link_stats(&self) -> Option<FlowStats> {
        self.link.as_ref().map(|l| l.stats())
    }

    /// The delays in force at sample `n`.
    pub fn delay_at(&self, n: u64) -> [u32; 3] {
        self.schedule
            .iter()
            .rev()
            .find(|(from, _)| *from <= n)
            .map(|(_, d)| *d)
            .unwrap_or(self.delay)
    }

    /// Takes input sample `seq` and returns the output for the same sample index.
    pub fn push(&mut self, seq: u64, values: [Value; 3]) -> Emitted {
        self.push_packet(seq, values, Rest::default(), true)
    }

    /// As [`Channel::push`]; `sent` false when the sender's codec sent no packet for
    /// this sample (it still draws its jitter, so enabling a codec leaves the network
    /// the same): the receiver then gets whatever arrived, or the last value again.
    /// `extra` is the sample's [`Rest`] (zero in a 3-DoF run).
    pub fn push_packet(
        &mut self,
        seq: u64,
        values: [Value; 3],
        extra: Rest,
        sent: bool,
    ) -> Emitted {
        if self.direct {
            return self.push_direct(Slot { seq, values, extra }, sent);
        }
        if self.link.is_some() {
            return self.push_link(Slot { seq, values, extra }, sent);
        }
        // Packets that arrived while no sample came (the sender's numbers skipped some:
        // a sample lost before this channel) are taken before this one's slot is
        // written, which could otherwise be theirs: a packet arrives within the ring's
        // length of being sent, but with a gap it may not have been read by then.
        // Without a gap the previous sample took them already.
        if self.last_seq.is_some_and(|l| seq > l.saturating_add(1)) {
            for (i, f) in self.flight.iter_mut().enumerate() {
                f.receive(seq - 1, &self.ring, i);
            }
        }
        let (sent, replayed) = self.admit(Slot { seq, values, extra }, sent);
        let lost = replayed.is_some_and(|(_, lost)| lost);
        let jitter = self.jitter.as_mut().map_or(0.0, |(j, rng)| j.next(rng));
        let (duplicated, copy_jitter) = self.duplicate_of(sent);
        let packet = Packet {
            seq,
            sent,
            delay: self.delay_at(seq),
            replayed: replayed.map(|(d, _)| d),
            jitter,
            copy: duplicated.then_some(copy_jitter),
        };
        let mut out = [Value::default(); 3];
        let mut noise = [0.0; 3];
        let mut extra = Rest::default();
        let mut substituted = false;
        for i in 0..3 {
            let (v, r, held, x) = self.axis(i, &packet);
            (out[i], noise[i]) = (v, r);
            if i == 0 {
                extra = x;
            }
            substituted |= held;
        }
        Emitted {
            values: out,
            noise,
            extra,
            jitter,
            lost,
            duplicated,
            substituted,
        }
    }

    /// [`Channel::push_packet`] when every packet arrives the sample it is sent (no
    /// delay, jitter, replay or duplication: the zero-delay channels of
    /// `lockstep-1e6.toml`, and of any run that studies no network): the newest
    /// packet arrived is the last one sent, so no ring and no queues. The same outputs
    /// bit for bit, noise draws included (a property test drives both paths). A
    /// zero-delay channel went from 41.8 to 10.9 ns a sample (`cargo bench -p
    /// tactile-netem --bench channel`, one session).
    fn push_direct(&mut self, slot: Slot, sent: bool) -> Emitted {
        let seq = slot.seq;
        // Checked whether sent or not: a sample not sent still moves the numbers on.
        let in_order = self.in_order(seq);
        let fresh = sent && in_order;
        if fresh {
            self.newest = Some(slot);
        }
        // Before the first packet: the general path's "nothing has arrived yet".
        let newest = self.newest.unwrap_or(Slot {
            seq,
            values: [Value::default(); 3],
            extra: Rest::default(),
        });
        let (values, noise) = self.aged(&newest, seq);
        Emitted {
            values,
            noise,
            extra: newest.extra,
            jitter: 0.0,
            lost: false,
            duplicated: false,
            substituted: !fresh,
        }
    }

    /// `from`'s values as they leave at sample `seq`: their age added to their delay,
    /// and each signal's noise (drawn in the signals' order); the noise added.
    #[inline(always)]
    fn aged(&mut self, from: &Slot, seq: u64) -> ([Value; 3], [f64; 3]) {
        let age = u32::try_from(seq.saturating_sub(from.seq)).unwrap_or(u32::MAX);
        let mut noise = [0.0; 3];
        let values = std::array::from_fn(|i| {
            let value = from.values[i];
            noise[i] = self.noise(i);
            Value {
                v: value.v + noise[i],
                delay_samples: value.delay_samples.saturating_add(age),
                ..value
            }
        });
        (values, noise)
    }

    /// Whether sample `seq` comes in order, then the last in order: sample numbers
    /// must increase, and not by absurd steps. This and [`Channel::noise`] are inlined
    /// by force: left to the compiler, the 20-sample channel bench took 4 % longer
    /// than with the code written out in place (51.8 against 53.9 us; 52.0 forced).
    #[inline(always)]
    fn in_order(&mut self, seq: u64) -> bool {
        let in_order = self
            .last_seq
            .is_none_or(|l| seq > l && seq - l <= MAX_SEQ_JUMP);
        if in_order {
            self.last_seq = Some(seq);
        }
        in_order
    }

    /// Signal `i`'s noise for this sample (none drawn without noise).
    #[inline(always)]
    fn noise(&mut self, i: usize) -> f64 {
        match &self.noise[i] {
            Some(dist) => dist.sample(&mut self.rng),
            None => 0.0,
        }
    }

    /// Takes sample `seq` in: whether its packet goes on the network (it was sent, in
    /// order, and a replayed network did not lose it; then it is kept for its
    /// arrival), and the replay's delay and loss for it.
    fn admit(&mut self, slot: Slot, sent: bool) -> (bool, Option<(u32, bool)>) {
        let seq = slot.seq;
        // Checked whether sent or not: a sample not sent still moves the numbers on
        // (else a long unsent stretch, a deadband codec's in free space, would look
        // like an absurd jump and every later packet be refused).
        let in_order = self.in_order(seq);
        let sent = sent && in_order;
        let replayed = self.replay.as_mut().map(|(r, _)| r.packet(sent));
        let sent = sent && !replayed.is_some_and(|(_, lost)| lost);
        if sent {
            let at = slot_of(&self.ring, seq);
            self.ring[at] = Some(slot);
            if self.first.is_none() {
                self.first = Some(slot);
            }
        }
        (sent, replayed)
    }

    /// Whether this sample's packet goes twice, and the copy's jitter. A duplicate is
    /// a second copy with its own jitter: it may arrive before the original (which is
    /// then of no use) or after (no use itself). Its stream draws the same numbers
    /// every sample whatever else is on (a codec, a replay, jitter), so turning those
    /// on leaves the duplicates where they were; the copy's jitter continues the
    /// correlated process with the duplication's own draw, so the originals' jitter
    /// stays as it was.
    fn duplicate_of(&mut self, sent: bool) -> (bool, f64) {
        let (draw, e) = match &mut self.duplicate {
            Some((p, rng)) => (
                rng.random::<f64>() < *p,
                rand_distr::StandardNormal.sample(rng),
            ),
            None => (false, 0.0),
        };
        let duplicated = sent && draw;
        let copy = match &self.jitter {
            Some((j, _)) if duplicated => j.clone().next_with(e),
            _ => 0.0,
        };
        (duplicated, copy)
    }

    /// Axis `i` of the sample: its packet (and copy) in flight, the newest arrived
    /// value out with its age added to its delay and its noise; true if it was held
    /// (no newer packet came); and the rotational half of the packet it came in.
    fn axis(&mut self, i: usize, p: &Packet) -> (Value, f64, bool, Rest) {
        // When a copy sent now with this jitter arrives: the replay's delay, or the
        // configured one plus jitter; in sending order unless reordering is on.
        let reorder = self.reorder;
        let f = &mut self.flight[i];
        let arrival = |f: &InFlight, jitter: f64| {
            let d = match p.replayed {
                Some(d) => u64::from(d),
                None => (f64::from(p.delay[i]) + jitter).round().max(0.0) as u64,
            };
            let at = p.seq.saturating_add(d);
            if reorder {
                at
            } else {
                at.max(f.last_arrival)
            }
        };
        if p.sent {
            let at = arrival(f, p.jitter);
            f.send(p.seq, at);
        }
        if let Some(copy) = p.copy {
            let at = arrival(f, copy);
            f.send(p.seq, at);
        }
        let newest = f.receive(p.seq, &self.ring, i);
        let fresh = newest.is_some() && newest.map(|n| n.0) != f.last_emitted;
        f.last_emitted = newest.map(|n| n.0);
        let (from, value, held, extra) = match newest {
            // Held when no newer packet came: flagged so the receiver knows.
            Some((from, v, x)) => (from, v, !fresh, x),
            None => {
                // Nothing has arrived yet: hold the first value sent.
                match &self.first {
                    Some(s) => (s.seq, s.values[i], true, s.extra),
                    None => (p.seq, Value::default(), true, Rest::default()),
                }
            }
        };
        // The delay injected is the value's age here: the packet's delay, and any
        // time it was held.
        let age = u32::try_from(p.seq.saturating_sub(from)).unwrap_or(u32::MAX);
        let r = self.noise(i);
        let v = Value {
            v: value.v + r,
            delay_samples: value.delay_samples.saturating_add(age),
            ..value
        };
        (v, r, held, extra)
    }
}

/// One sample's packet as the three axes see it.
#[derive(Debug, Clone, Copy)]
struct Packet {
    seq: u64,
    /// It went on the network.
    sent: bool,
    /// The configured delays at this sample.
    delay: [u32; 3],
    /// A replayed network's delay for it.
    replayed: Option<u32>,
    /// Its jitter.
    jitter: f64,
    /// A duplicate's jitter, if it went twice.
    copy: Option<f64>,
}

#[path = "channel_link.rs"]
mod link_path;

#[cfg(test)]
#[path = "channel_tests.rs"]
mod tests;
