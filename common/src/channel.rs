//! The paper's channel model, v_i(n) = c_i(n - d_i(n)) + r_i(n), as pure code.
//!
//! The emulator process feeds each arriving sample into a [`Channel`] and sends what
//! comes out; the in-process simulation does the same, so both produce identical
//! values. Each of the three signals has its own delay (whole samples, constant or
//! scheduled) and its own zero-mean Gaussian noise. Every output value carries the
//! origin (sequence and timestamp) of the input value it came from and the delay that
//! was injected, so the master can tell injected delay from system overhead; the noise
//! actually added is returned too.

use crate::scenario::ChannelConfig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

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
    /// Delay injected on purpose so far along its path, in samples.
    pub delay_samples: u32,
}

/// What a channel emits for one input sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Emitted {
    /// The delayed, noisy values.
    pub values: [Value; 3],
    /// The noise added to each value.
    pub noise: [f64; 3],
    /// True if a value had to stand in for one not yet (or no longer) in the history:
    /// the first `d` samples of a delayed channel, or after a gap.
    pub substituted: bool,
}

#[derive(Debug, Clone, Copy)]
struct Slot {
    seq: u64,
    values: [Value; 3],
}

/// One direction of the emulated network.
#[derive(Debug)]
pub struct Channel {
    delay: [u32; 3],
    schedule: Vec<(u64, [u32; 3])>,
    noise: [Option<Normal<f64>>; 3],
    rng: ChaCha8Rng,
    ring: Vec<Option<Slot>>,
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
        let max_delay = schedule
            .iter()
            .flat_map(|(_, d)| d.iter().copied())
            .chain(delay.iter().copied())
            .max()
            .unwrap_or(0) as usize;
        let noise = cfg
            .noise_std
            .map(|s| (s > 0.0).then(|| Normal::new(0.0, s).ok()).flatten());
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        Channel {
            delay,
            schedule,
            noise,
            rng,
            ring: vec![None; max_delay + 1],
        }
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
        let len = self.ring.len() as u64;
        self.ring[(seq % len) as usize] = Some(Slot { seq, values });
        let delay = self.delay_at(seq);
        let mut out = [Value::default(); 3];
        let mut noise = [0.0; 3];
        let mut substituted = false;
        for i in 0..3 {
            let want = seq.checked_sub(u64::from(delay[i]));
            let found = want.and_then(|w| self.ring[(w % len) as usize].filter(|s| s.seq == w));
            let src = match found {
                Some(s) => s.values[i],
                None => {
                    substituted = true;
                    // Nothing sent that long ago yet: hold the oldest value we have.
                    self.oldest_value(i)
                }
            };
            let r = match &self.noise[i] {
                Some(dist) => dist.sample(&mut self.rng),
                None => 0.0,
            };
            noise[i] = r;
            out[i] = Value {
                v: src.v + r,
                delay_samples: src.delay_samples.saturating_add(delay[i]),
                ..src
            };
        }
        Emitted {
            values: out,
            noise,
            substituted,
        }
    }

    fn oldest_value(&self, i: usize) -> Value {
        self.ring
            .iter()
            .flatten()
            .min_by_key(|s| s.seq)
            .map(|s| s.values[i])
            .unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            assert_eq!(e.values[2].delay_samples, 5);
            // The energy and the sender's sample number travel with their value.
            assert_eq!(e.values[1].sent_seq, n.saturating_sub(2));
            assert_eq!(e.values[1].energy, n.saturating_sub(2) as f64 * 0.5);
            assert_eq!(e.substituted, n < 5);
            assert_eq!(e.noise, [0.0; 3]);
        }
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
}
