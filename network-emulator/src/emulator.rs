//! The network emulator's per-sample logic: both channels of the paper's NW subsystem.
//!
//! Forward, v_i(n) = c_i(n - d^f_i(n)) + r^f_i(n); backward, q_i(n) = h_i(n - d^b_i(n)) +
//! r^b_i(n), with a constant delay; with jitter, a replay or a codec, each packet
//! arrives when its own delay says and the newest arrived is passed on
//! (`tactile_netem::channel`). Each arriving sample is pushed through its
//! [`Channel`]; what comes out
//! keeps the sample number and stamps of the sample that triggered it, with values (and
//! their provenance) taken from the delayed one. What was done to each sample (noise
//! added, delay, drop or corruption) is the emulator's record of it.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tactile_messages::samples::{Backward, Flags, Forward, Model, Signal};

/// The flags that belong to a sample's packet and arrive with it, not with the sample
/// that triggers the emulator's output: the clutch (released at the pose it was
/// released at, however late that pose arrives).
const CARRIED: Flags = Flags::RELEASED;
use tactile_netem::channel::{Channel, Rest, Value, BACKWARD_STREAM, FORWARD_STREAM};
use tactile_netem::link::FlowStats;
use tactile_netem::{HistogramDelay, Loss, Replay};
use tactile_records::emulator::{Direction, EmulatorCounters, Fate, Passage};
use tactile_scenario::{ChannelConfig, Scenario};

/// The seeded drop and corruption decisions of one channel. A random stream of its
/// own, so enabling loss does not change the noise a run sees.
#[derive(Debug)]
struct Faults {
    loss: f64,
    /// A loss model and its own random stream, so choosing one leaves the corruption
    /// draws where they were.
    model: Option<(Loss, ChaCha8Rng)>,
    corrupt: f64,
    rng: ChaCha8Rng,
}

impl Faults {
    fn new(cfg: &ChannelConfig, seed: u64, stream: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream + 100);
        Faults {
            loss: cfg.loss,
            model: cfg.loss_model.as_ref().map(|m| {
                let mut r = ChaCha8Rng::seed_from_u64(seed);
                r.set_stream(stream + 500);
                (Loss::new(m), r)
            }),
            corrupt: cfg.corrupt,
            rng,
        }
    }

    /// Whether the loss model loses this sample's packet (one draw per sample, sent or
    /// not, so a codec leaves the losses where they were).
    fn packet_lost(&mut self) -> bool {
        self.model.as_mut().is_some_and(|(m, rng)| m.lose(rng))
    }

    fn fate(&mut self) -> Fate {
        // Draw only for enabled faults, so a run without them draws nothing.
        if self.loss > 0.0 && self.rng.random::<f64>() < self.loss {
            return Fate::Drop;
        }
        if self.corrupt > 0.0 && self.rng.random::<f64>() < self.corrupt {
            return Fate::Corrupt;
        }
        Fate::Deliver
    }
}

/// Both channels.
#[derive(Debug)]
pub struct Emulator {
    forward: Channel,
    backward: Channel,
    forward_faults: Faults,
    backward_faults: Faults,
    counters: EmulatorCounters,
}

fn values(s: &Signal) -> [Value; 3] {
    [0, 1, 2].map(|i| Value {
        v: s.value[i],
        energy: s.energy[i],
        sent_seq: s.sent_seq[i],
        origin_seq: s.origin_seq[i],
        origin_ns: s.origin_ns[i],
        delay_samples: s.delay_samples[i],
    })
}

fn apply(s: &mut Signal, e: &tactile_netem::channel::Emitted) {
    for i in 0..3 {
        s.value[i] = e.values[i].v;
        s.energy[i] = e.values[i].energy;
        s.sent_seq[i] = e.values[i].sent_seq;
        s.origin_seq[i] = e.values[i].origin_seq;
        s.origin_ns[i] = e.values[i].origin_ns;
        s.delay_samples[i] = e.values[i].delay_samples;
    }
    if e.substituted {
        s.flags |= Flags::SUBSTITUTED;
    }
}

impl Emulator {
    /// Channels as the scenario configures them, seeded from its seed.
    pub fn new(scenario: &Scenario) -> Emulator {
        Emulator::with_replays(scenario, [None, None])
    }

    /// As [`Emulator::new`], the forward and backward channels driven by recorded
    /// networks where given (loaded by [`crate::replay::load`]).
    pub fn with_replays(scenario: &Scenario, replays: [Option<Replay>; 2]) -> Emulator {
        let (f, b) = (&scenario.network.forward, &scenario.network.backward);
        let [rf, rb] = replays;
        let channel = |c, stream, r: Option<Replay>| {
            let ch = Channel::new(c, scenario.seed, stream);
            match r {
                Some(r) => ch.with_replay(r, scenario.t_s()),
                None => ch,
            }
        };
        Emulator {
            forward: channel(f, FORWARD_STREAM, rf),
            backward: channel(b, BACKWARD_STREAM, rb),
            forward_faults: Faults::new(f, scenario.seed, FORWARD_STREAM),
            backward_faults: Faults::new(b, scenario.seed, BACKWARD_STREAM),
            counters: EmulatorCounters::default(),
        }
    }

    /// The same emulator drawing each packet's delay from the forward and backward
    /// histograms where given (loaded by [`crate::histogram::load`]), each on a random
    /// stream of its own seeded from the scenario's seed.
    pub fn with_histograms(
        mut self,
        seed: u64,
        histograms: [Option<HistogramDelay>; 2],
    ) -> Emulator {
        let [f, b] = histograms;
        if let Some(h) = f {
            self.forward = self.forward.with_histogram(h, seed, FORWARD_STREAM);
        }
        if let Some(h) = b {
            self.backward = self.backward.with_histogram(h, seed, BACKWARD_STREAM);
        }
        self
    }

    /// Counters so far.
    pub fn counters(&self) -> EmulatorCounters {
        self.counters
    }

    /// What the forward and backward links counted for the haptic flow (none for a
    /// channel without a link): packets offered, departed, dropped, dropped at the
    /// memory cap, and their time on the link. Not in the record yet: the report's
    /// queueing-delay stage comes with the cross traffic that shares the link.
    pub fn link_stats(&self) -> [Option<FlowStats>; 2] {
        [self.forward.link_stats(), self.backward.link_stats()]
    }

    /// c(n) in: v(n) into `v` (`None` when the channel's `loss` drops the sample; a
    /// packet lost by a loss model still gives a sample) and the record of it into
    /// `record`. Both are filled where they lie: they are hundreds of bytes
    /// each, and returning them copied each on its way out to the follower's reply.
    pub fn forward(&mut self, c: &Forward, v: &mut Option<Forward>, record: &mut Option<Passage>) {
        let out = v.insert(*c);
        let mut rest = Rest {
            rotation: c.rotation,
            ..Rest::default()
        };
        let (fate, noise, jitter, lost, duplicated) = pass(
            &mut self.forward,
            &mut self.forward_faults,
            c.seq,
            &mut out.signal,
            &mut rest,
        );
        out.rotation = rest.rotation;
        let k = &mut self.counters;
        k.forward += 1;
        k.forward_substituted += u64::from(out.signal.flags.intersects(Flags::SUBSTITUTED));
        k.forward_corrupted += u64::from(fate == Fate::Corrupt);
        k.forward_dropped += u64::from(fate == Fate::Drop);
        k.forward_packets_lost += u64::from(lost);
        k.forward_duplicated += u64::from(duplicated);
        *record = Some(Passage {
            dir: Direction::Forward,
            n: c.seq,
            input: c.signal.value,
            out: out.signal,
            rotational: (c.signal.flags.intersects(Flags::POSE)).then_some(out.rotation),
            noise,
            jitter,
            lost,
            fate,
        });
        if fate == Fate::Drop {
            *v = None;
        }
    }

    /// h(n) in: q(n) into `q` (`None` when the channel's `loss` drops the sample) and
    /// the record of it into `record`, filled where they lie as [`Emulator::forward`]
    /// does.
    pub fn backward(
        &mut self,
        h: &Backward,
        q: &mut Option<Backward>,
        record: &mut Option<Passage>,
    ) {
        let out = q.insert(*h);
        let m = &h.model;
        let mut rest = Rest {
            rotation: [h.torque[0], h.torque[1], h.torque[2], 0.0],
            model: [m.normal[0], m.normal[1], m.normal[2], m.offset, m.stiffness],
            model_seq: m.seq,
            ..Rest::default()
        };
        let (fate, noise, jitter, lost, duplicated) = pass(
            &mut self.backward,
            &mut self.backward_faults,
            h.seq,
            &mut out.signal,
            &mut rest,
        );
        let (t, m) = (rest.rotation, rest.model);
        out.torque = [t[0], t[1], t[2]];
        out.model = Model {
            normal: [m[0], m[1], m[2]],
            offset: m[3],
            stiffness: m[4],
            seq: rest.model_seq,
        };
        let k = &mut self.counters;
        k.backward += 1;
        k.backward_substituted += u64::from(out.signal.flags.intersects(Flags::SUBSTITUTED));
        k.backward_corrupted += u64::from(fate == Fate::Corrupt);
        k.backward_dropped += u64::from(fate == Fate::Drop);
        k.backward_packets_lost += u64::from(lost);
        k.backward_duplicated += u64::from(duplicated);
        *record = Some(Passage {
            dir: Direction::Backward,
            n: h.seq,
            input: h.signal.value,
            out: out.signal,
            rotational: (h.signal.flags.intersects(Flags::POSE)).then_some(rest.rotation),
            noise,
            jitter,
            lost,
            fate,
        });
        if fate == Fate::Drop {
            *q = None;
        }
    }
}

/// One sample through one channel: delay and noise into `signal`, then the fault
/// model's decision (a corrupted signal is already NaN when this returns); `rest` is
/// the sample's rotational half and model, carried in the same packet (its flags are
/// taken from `signal`'s). Returns the decision, the noise added, the jitter drawn,
/// whether a replayed network lost the packet and whether it was duplicated.
fn pass(
    channel: &mut Channel,
    faults: &mut Faults,
    seq: u64,
    signal: &mut Signal,
    rest: &mut Rest,
) -> (Fate, [f64; 3], f64, bool, bool) {
    // A sample its sender's codec did not send carries no packet, nor one the loss
    // model loses (netem's loss is of packets: the receiver still ticks and fills the
    // sample from what it has); `loss` instead drops the whole sample (the receiver
    // gets nothing). What leaves is what the network delivers at this sample.
    let unsent = signal.flags.intersects(Flags::UNSENT);
    let model_lost = faults.packet_lost() && !unsent;
    rest.flags = (signal.flags & CARRIED).bits();
    let e = channel.push_packet(seq, values(signal), *rest, !unsent && !model_lost);
    signal.flags.remove(Flags::UNSENT);
    apply(signal, &e);
    *rest = e.extra;
    signal.flags = signal.flags.without(CARRIED) | (Flags::from_bits(rest.flags) & CARRIED);
    let fate = faults.fate();
    if fate == Fate::Corrupt {
        signal.value = [f64::NAN; 3];
        if signal.flags.intersects(Flags::POSE) {
            rest.rotation = [f64::NAN; 4];
        }
        // A model in a corrupted packet is garbage too: the master must refuse it.
        if rest.model_seq != 0 {
            rest.model = [f64::NAN; 5];
        }
        signal.flags |= Flags::CORRUPTED;
    }
    (fate, e.noise, e.jitter, e.lost || model_lost, e.duplicated)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(seq: u64) -> Forward {
        let mut c = Forward {
            seq,
            run: 7,
            ..Forward::default()
        };
        c.signal.value = [0.1, 0.2, seq as f64];
        c.stamps[0] = 1000 + seq;
        c
    }

    #[test]
    fn a_passed_sample_fills_both_slots_whatever_they_held() {
        let mut e = Emulator::new(&Scenario::paper());
        let mut v = Some(Forward::default());
        let mut record = None;
        for seq in 0..3 {
            e.forward(&sample(seq), &mut v, &mut record);
            let (v, r) = (v.expect("passed on"), record.expect("recorded"));
            // No delay, no noise: c(n) through, and its record says so.
            assert_eq!((v.seq, v.run, v.stamps), (seq, 7, sample(seq).stamps));
            assert_eq!(v.signal.value, sample(seq).signal.value);
            assert_eq!((r.n, r.fate, r.out), (seq, Fate::Deliver, v.signal));
            assert_eq!(r.input, sample(seq).signal.value);
        }
    }

    /// Slots reused from sample to sample, through drops and passes, hold what fresh
    /// ones would: nothing of the sample before leaks into the next.
    #[test]
    fn kept_slots_hold_each_sample_as_fresh_ones_would() {
        let mut sc = Scenario::paper();
        sc.network.forward.loss = 0.5;
        sc.network.forward.delay = [2, 0, 1];
        sc.network.forward.noise_std = [1e-3, 0.0, 1e-3];
        let (mut kept, mut fresh) = (Emulator::new(&sc), Emulator::new(&sc));
        let (mut v, mut record) = (None, None);
        let mut fates = Vec::new();
        for seq in 0..64 {
            kept.forward(&sample(seq), &mut v, &mut record);
            let (mut v1, mut r1) = (None, None);
            fresh.forward(&sample(seq), &mut v1, &mut r1);
            assert_eq!((v, record), (v1, r1), "sample {seq}");
            fates.push(record.map(|r| r.fate));
        }
        // Both kinds came, and a pass right after a drop.
        let dropped = |f: &Option<Fate>| *f == Some(Fate::Drop);
        assert!(fates.windows(2).any(|w| dropped(&w[0]) && !dropped(&w[1])));
    }

    /// MMT's model rides in the force's packet: delayed with it, held with it, never
    /// noised; in a corrupted packet it is garbage (NaN) for the master to refuse.
    #[test]
    fn the_model_arrives_with_its_force_and_is_corrupted_with_it() {
        let mut sc = Scenario::paper();
        sc.network.backward.delay = [3, 3, 3];
        sc.network.backward.noise_std = [1e-3; 3];
        let mut e = Emulator::new(&sc);
        let model = |n: u64| Model {
            normal: [0.0, 0.0, 1.0],
            offset: -0.06 + n as f64 * 1e-4,
            stiffness: 600.0,
            seq: n / 2,
        };
        let (mut q, mut record) = (None, None);
        for n in 0..20u64 {
            let mut h = Backward {
                seq: n,
                model: model(n),
                ..Backward::default()
            };
            h.signal.value = [0.0, 0.0, n as f64];
            h.signal.sent_seq = [n; 3];
            e.backward(&h, &mut q, &mut record);
            let q = q.expect("passed");
            let from = q.signal.sent_seq[0];
            assert_eq!(q.model, model(from), "sample {n}");
            assert_eq!(from, n.saturating_sub(3));
        }
        sc.network.backward.corrupt = 1.0;
        let mut e = Emulator::new(&sc);
        let h = Backward {
            model: model(4),
            ..Backward::default()
        };
        e.backward(&h, &mut q, &mut record);
        let q = q.expect("passed");
        assert!(q.signal.flags.intersects(Flags::CORRUPTED));
        assert!(q.model.offset.is_nan() && q.model.stiffness.is_nan());
        assert_eq!(q.model.seq, 2);
    }

    #[test]
    fn a_dropped_sample_empties_its_slot_and_is_recorded() {
        let mut sc = Scenario::paper();
        sc.network.backward.loss = 1.0;
        let mut e = Emulator::new(&sc);
        let h = Backward {
            seq: 4,
            ..Backward::default()
        };
        let mut q = Some(Backward::default());
        let mut record = None;
        e.backward(&h, &mut q, &mut record);
        assert_eq!(q, None);
        let r = record.expect("recorded");
        assert_eq!((r.n, r.dir, r.fate), (4, Direction::Backward, Fate::Drop));
        assert_eq!(e.counters().backward_dropped, 1);
    }

    /// A forward link drops what it cannot carry and counts it: at 1 kHz, 278-byte
    /// packets on a 1 Mbit/s link with a 10-packet drop-tail queue carry 1e6 / 2224 =
    /// 450 packets a second; the other 550 are lost, each counted once.
    #[test]
    fn a_link_counts_what_it_carries_and_drops() {
        let mut sc = Scenario::paper();
        sc.rate_hz = 1000.0;
        sc.network.forward.link = Some(tactile_scenario::LinkConfig {
            rate: Some(1e6),
            path: None,
            queue: tactile_scenario::QueueKind::Droptail,
            packets: Some(10),
            ..tactile_scenario::LinkConfig::mahimahi("")
        });
        let replays = crate::replay::load(&sc, std::path::Path::new(".")).expect("a rate");
        let mut e = Emulator::with_replays(&sc, replays);
        let (mut v, mut record) = (None, None);
        for n in 0..1000 {
            e.forward(&sample(n), &mut v, &mut record);
        }
        let [Some(f), None] = e.link_stats() else {
            panic!("a forward link only");
        };
        assert_eq!(f.offered, 1000);
        assert_eq!(f.dropped, e.counters().forward_packets_lost);
        assert!(f.departed.abs_diff(450) <= 1, "{f:?}");
        // The rest are in the queue (10) or in transit (1).
        assert!(1000 - f.departed - f.dropped <= 11, "{f:?}");
    }
}
