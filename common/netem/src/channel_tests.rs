//! The channel against its definition: packets in flight, per-signal delay, jitter,
//! duplication, schedules, noise, and numbers with gaps.

use super::*;
use proptest::prelude::*;

proptest! {
    /// Packets in flight are held as the map they replace held them (arrival
    /// sample to newest sequence), sent and received in any order.
    #[test]
    fn in_flight_is_the_map_it_replaces(
        steps in proptest::collection::vec((0u64..40, 0u64..12, any::<bool>()), 0..200),
    ) {
        let (mut f, mut map) = (InFlight::default(), std::collections::BTreeMap::new());
        let ring = vec![None; 64];
        for (now, (seq, ahead, receive)) in steps.into_iter().enumerate() {
            let now = now as u64;
            f.send(seq, now + ahead);
            let e = map.entry(now + ahead).or_insert(seq);
            *e = (*e).max(seq);
            if receive {
                f.receive(now, &ring, 0);
                map.retain(|&at, _| at > now);
            }
            let held: Vec<(u64, u64)> = f.arriving.iter().copied().collect();
            prop_assert_eq!(held, map.iter().map(|(&a, &s)| (a, s)).collect::<Vec<_>>());
        }
    }
}

fn vals(n: u64) -> [Value; 3] {
    [0, 1, 2].map(|i| Value {
        v: n as f64 * 10.0 + i as f64,
        energy: n as f64 * 0.5,
        sent_seq: n,
        origin_seq: n,
        origin_ns: n * 1000,
        delay_samples: 0,
    })
}

#[test]
fn per_signal_delay_without_noise() {
    let cfg = ChannelConfig {
        delay: [0, 2, 5],
        ..Default::default()
    };
    let mut ch = Channel::new(&cfg, 7, FORWARD_STREAM);
    for n in 0..20u64 {
        let e = ch.push(n, vals(n));
        assert_eq!(e.values[0].origin_seq, n);
        assert_eq!(e.values[1].origin_seq, n.saturating_sub(2));
        assert_eq!(e.values[2].origin_seq, n.saturating_sub(5));
        // The injected delay is the value's age: n while the line fills.
        assert_eq!(e.values[2].delay_samples, 5.min(n as u32));
        // The energy and the sender's sample number travel with their value.
        assert_eq!(e.values[1].sent_seq, n.saturating_sub(2));
        assert_eq!(e.values[1].energy, n.saturating_sub(2) as f64 * 0.5);
        assert_eq!(e.substituted, n < 5);
        assert_eq!(e.noise, [0.0; 3]);
    }
}

/// Jitter: each packet's delay varies, the receiver never goes back in time, and
/// a packet that arrives after a newer one is not used.
#[test]
fn jitter_delays_packets_and_the_receiver_keeps_the_newest() {
    let run = |reorder: bool| {
        let cfg = ChannelConfig {
            delay: [20, 20, 20],
            jitter: Some(tactile_scenario::JitterConfig {
                jitter: 3.0,
                correlation: 0.0,
                distribution: tactile_scenario::JitterDistribution::Normal,
            }),
            reorder,
            ..Default::default()
        };
        let mut ch = Channel::new(&cfg, 9, FORWARD_STREAM);
        let (mut last, mut held, mut delays) = (0u64, 0u32, Vec::new());
        for n in 0..20_000u64 {
            let e = ch.push(n, vals(n));
            let src = e.values[0].origin_seq;
            assert!(src >= last, "{n}: went back from {last} to {src}");
            assert_eq!(e.values[0].delay_samples as u64, n - src.min(n));
            if n > 100 {
                if e.substituted {
                    held += 1;
                } else {
                    delays.push(f64::from(e.values[0].delay_samples));
                }
            }
            last = src;
        }
        let mean = delays.iter().sum::<f64>() / delays.len() as f64;
        (mean, held)
    };
    let (free, held_free) = run(true);
    let (fifo, _) = run(false);
    // The values used are the newest arrived, so fresher than the average packet
    // (20 samples: late ones are overtaken and never used); in sending order every
    // packet waits for the one before it, so older than the average.
    assert!(free < 19.5 && free > 15.0, "{free}");
    assert!(fifo > 20.5, "{fifo}");
    assert!(held_free > 100, "jitter leaves gaps: {held_free}");
}

/// netem's duplicate: about the configured share of packets go twice (binomial:
/// five standard deviations), the originals' jitter is what it was without
/// duplication, and no packet reaches the receiver fresh twice.
#[test]
fn duplicates_are_counted_and_never_used_twice() {
    let run = |duplicate: f64| {
        let cfg = ChannelConfig {
            delay: [10, 10, 10],
            jitter: Some(tactile_scenario::JitterConfig {
                jitter: 4.0,
                correlation: 0.3,
                distribution: tactile_scenario::JitterDistribution::Normal,
            }),
            duplicate,
            ..Default::default()
        };
        let mut ch = Channel::new(&cfg, 4, FORWARD_STREAM);
        let (mut dups, mut jitters, mut last) = (0u32, Vec::new(), None);
        for n in 0..100_000u64 {
            let e = ch.push(n, vals(n));
            dups += u32::from(e.duplicated);
            jitters.push(e.jitter);
            if !e.substituted {
                let src = e.values[0].origin_seq;
                assert!(last.is_none_or(|l| src > l), "{n}: packet {src} used twice");
                last = Some(src);
            }
        }
        (dups, jitters)
    };
    let (none, base) = run(0.0);
    let (dups, jitters) = run(0.3);
    assert_eq!(none, 0);
    assert_eq!(
        base, jitters,
        "duplication leaves the originals' jitter alone"
    );
    let (n, p): (f64, f64) = (100_000.0, 0.3);
    let sd = (n * p * (1.0 - p)).sqrt();
    assert!((f64::from(dups) - n * p).abs() < 5.0 * sd, "{dups}");
}

#[test]
fn schedule_changes_delay() {
    let cfg = ChannelConfig {
        delay: [1, 1, 1],
        schedule: vec![[10, 3, 3, 3], [20, 0, 0, 0]],
        ..Default::default()
    };
    let ch = Channel::new(&cfg, 0, FORWARD_STREAM);
    assert_eq!(ch.delay_at(5), [1; 3]);
    assert_eq!(ch.delay_at(10), [3; 3]);
    assert_eq!(ch.delay_at(25), [0; 3]);
}

#[test]
fn noise_is_seeded_and_has_the_configured_spread() {
    let cfg = ChannelConfig {
        noise_std: [0.5, 0.0, 2.0],
        ..Default::default()
    };
    let run = |seed| {
        let mut ch = Channel::new(&cfg, seed, BACKWARD_STREAM);
        (0..20_000u64)
            .map(|n| {
                let e = ch.push(n, vals(n));
                // Noise goes on the value only, never on the energy exchanged.
                assert!(e.values.iter().all(|v| v.energy == n as f64 * 0.5));
                e.noise
            })
            .collect::<Vec<_>>()
    };
    let a = run(3);
    assert_eq!(a, run(3));
    assert_ne!(a, run(4));
    for (i, want) in [0.5, 0.0, 2.0].into_iter().enumerate() {
        let n = a.len() as f64;
        let mean = a.iter().map(|r| r[i]).sum::<f64>() / n;
        let sd = (a.iter().map(|r| (r[i] - mean).powi(2)).sum::<f64>() / n).sqrt();
        // Standard error of the sample standard deviation: sigma / sqrt(2n) ~ 0.5 %.
        assert!(
            (sd - want).abs() <= 0.03 * want + 1e-12,
            "signal {i}: sd {sd}"
        );
        assert!(
            mean.abs() <= 5.0 * want / n.sqrt() + 1e-12,
            "signal {i}: mean {mean}"
        );
    }
}

/// A delay of 2 and numbers 8, 9, 10, then 13 or 14 (the ones between lost before the
/// channel): packet 10 arrived at 12, when no sample came, and is what the next one
/// gets, as old as it is. Its slot is 13's in a ring of three slots and 14's in a
/// ring of four (this one's): the packet must be read before its slot is reused.
#[test]
fn a_packet_that_arrived_in_a_gap_is_not_lost() {
    let cfg = ChannelConfig {
        delay: [2, 2, 2],
        ..Default::default()
    };
    for next in [13, 14] {
        let mut ch = Channel::new(&cfg, 1, BACKWARD_STREAM);
        for n in [8, 9, 10] {
            ch.push(n, vals(n));
        }
        let e = ch.push(next, vals(next));
        assert_eq!(e.values.map(|v| v.origin_seq), [10; 3], "then {next}");
        assert_eq!(u64::from(e.values[0].delay_samples), next - 10);
        assert!(!e.substituted);
    }
}

proptest! {
    /// Numbers with any gaps (samples lost before the channel), any delay: each
    /// output is the newest packet sent at least the delay before it, as old as it is
    /// (or the first value sent, held, before any has arrived).
    #[test]
    fn gaps_in_the_numbers_lose_no_packet(
        d in 0u64..9,
        steps in proptest::collection::vec(1u64..12, 1..80),
    ) {
        let cfg = ChannelConfig {
            delay: [d as i64; 3],
            ..Default::default()
        };
        let mut ch = Channel::new(&cfg, 1, BACKWARD_STREAM);
        let (mut seq, mut sent) = (0, Vec::new());
        for step in steps {
            seq += step;
            sent.push(seq);
            let e = ch.push(seq, vals(seq));
            match sent.iter().rev().find(|&&p| p + d <= seq) {
                Some(&p) => {
                    prop_assert_eq!(e.values.map(|v| v.origin_seq), [p; 3], "at {}", seq);
                    prop_assert_eq!(u64::from(e.values[2].delay_samples), seq - p);
                }
                None => {
                    prop_assert_eq!(e.values[1].origin_seq, sent[0]);
                    prop_assert!(e.substituted);
                }
            }
        }
    }
}

proptest! {
    /// The direct path (every packet arrives the sample it is sent) emits what the
    /// general path emits, bit for bit, noise draws included, for numbers in order,
    /// repeated, backwards, with gaps or absurd jumps, and packets not sent.
    #[test]
    fn the_direct_path_is_the_general_one(
        noise in any::<bool>(),
        seed in any::<u64>(),
        steps in proptest::collection::vec((0u8..40, any::<bool>()), 0..200),
    ) {
        let cfg = ChannelConfig {
            noise_std: if noise { [1e-3, 0.0, 2e-3] } else { [0.0; 3] },
            ..Default::default()
        };
        let mut direct = Channel::new(&cfg, seed, FORWARD_STREAM);
        let mut general = Channel::new(&cfg, seed, FORWARD_STREAM);
        prop_assert!(direct.direct);
        general.direct = false;
        let mut seq = 0u64;
        for (step, sent) in steps {
            seq = match step {
                0 => seq,
                1 => seq.saturating_sub(3),
                2 => seq + 5,
                3 => seq + MAX_SEQ_JUMP + 1,
                _ => seq + 1,
            };
            let extra = Rest {
                rotation: [seq as f64, 0.5, -0.0, 1.0],
                flags: seq as u32,
                model: [0.25, seq as f64, 0.0, -1.0, 600.0],
                model_seq: seq / 3,
            };
            // Values that come with a delay already (from a channel before this one).
            let v = vals(seq).map(|v| Value {
                delay_samples: (seq % 7) as u32,
                ..v
            });
            let a = direct.push_packet(seq, v, extra, sent);
            let b = general.push_packet(seq, v, extra, sent);
            // Debug shows -0.0 and 0.0 apart, as bit-for-bit must.
            prop_assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }
}

#[test]
fn only_a_channel_whose_packets_arrive_at_once_goes_direct() {
    let direct = |cfg: ChannelConfig| Channel::new(&cfg, 1, FORWARD_STREAM).direct;
    assert!(direct(ChannelConfig::default()));
    // Noise and losses (the emulator's) leave each packet's arrival as it is.
    assert!(direct(ChannelConfig {
        noise_std: [1e-3; 3],
        loss: 0.1,
        reorder: false,
        ..Default::default()
    }));
    assert!(!direct(ChannelConfig {
        delay: [0, 0, 1],
        ..Default::default()
    }));
    assert!(!direct(ChannelConfig {
        schedule: vec![[10, 0, 0, 0]],
        ..Default::default()
    }));
    assert!(!direct(ChannelConfig {
        jitter: Some(tactile_scenario::JitterConfig {
            jitter: 1.0,
            correlation: 0.0,
            distribution: tactile_scenario::JitterDistribution::Normal,
        }),
        ..Default::default()
    }));
    assert!(!direct(ChannelConfig {
        duplicate: 0.1,
        ..Default::default()
    }));
    let replay = Replay::parse_csv("delay,lost\n0,0\n").expect("csv");
    let ch = Channel::new(&ChannelConfig::default(), 1, FORWARD_STREAM).with_replay(replay, 1e-3);
    assert!(!ch.direct);
}

/// A sample not sent still moves the channel's numbers on, on either path: after a
/// stretch of unsent samples longer than [`MAX_SEQ_JUMP`] (a deadband codec in free
/// space) the next packet is taken, and a packet repeating an unsent sample's number
/// is refused.
#[test]
fn samples_not_sent_move_the_numbers_on() {
    for delay in [0, 2] {
        let cfg = ChannelConfig {
            delay: [delay; 3],
            ..Default::default()
        };
        let mut ch = Channel::new(&cfg, 1, FORWARD_STREAM);
        assert_eq!(ch.direct, delay == 0);
        ch.push_packet(0, vals(0), Rest::default(), true);
        let quiet = MAX_SEQ_JUMP + 1;
        for seq in 1..=quiet {
            ch.push_packet(seq, vals(seq), Rest::default(), false);
        }
        let s = quiet + 1;
        let mut e = ch.push_packet(s, vals(s), Rest::default(), true);
        for seq in s + 1..=s + delay as u64 {
            e = ch.push_packet(seq, vals(seq), Rest::default(), false);
        }
        assert!(
            !e.substituted,
            "delay {delay}: the packet after the stretch is taken"
        );
        assert_eq!(e.values[0].origin_seq, s);
        let mut ch = Channel::new(&cfg, 1, FORWARD_STREAM);
        ch.push_packet(5, vals(5), Rest::default(), false);
        for seq in 5..=5 + delay as u64 {
            e = ch.push_packet(seq, vals(seq), Rest::default(), seq == 5);
        }
        assert!(
            e.substituted,
            "delay {delay}: a repeated number is no packet"
        );
        assert_eq!(e.values[0], Value::default());
    }
}

/// A link's memory cap bounds what a channel holds for it: the samples on the link,
/// at most the cap of them, each a slot (docs/04 says 240 bytes, 24 MB).
#[test]
fn a_links_held_samples_are_bounded_by_its_cap() {
    let held = std::mem::size_of::<Slot>() * crate::link::MAX_QUEUE_PACKETS;
    assert_eq!(std::mem::size_of::<Slot>(), 240);
    assert!(held <= 24_000_000, "{held} bytes");
}
