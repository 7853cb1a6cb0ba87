//! The models against their closed forms: jitter moments and correlation, loss
//! rates and burst lengths, replays.

use crate::jitter::*;
use crate::loss::*;
use crate::replay::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tactile_scenario::{JitterConfig, JitterDistribution, LossModel};

const N: usize = 100_000;

/// A series' mean, standard deviation and lag-1 correlation.
pub(crate) fn stats(x: &[f64]) -> (f64, f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    let lag = x
        .windows(2)
        .map(|w| (w[0] - mean) * (w[1] - mean))
        .sum::<f64>()
        / (n - 1.0);
    (mean, var.sqrt(), lag / var)
}

/// Each value's rank in the series, 0 to N - 1.
pub(crate) fn ranks(x: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..x.len()).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut r = vec![0.0; x.len()];
    for (rank, &k) in order.iter().enumerate() {
        r[k] = rank as f64;
    }
    r
}

fn draw(cfg: JitterConfig, seed: u64) -> Vec<f64> {
    let mut j = Jitter::new(&cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..N).map(|_| j.next(&mut rng)).collect()
}

/// Tolerances from the sample count: for an AR(1) series of lag-1 correlation c the
/// effective count is N (1 - c) / (1 + c), so the mean's standard error is
/// sd sqrt((1 + c) / (N (1 - c))); the sample standard deviation's relative error
/// about sqrt((1 + c^2) / (2 N (1 - c^2))) for Gaussian data (heavier tails need
/// more: Pareto shape 3 has no fourth moment, so its spread is checked to 5 %);
/// the lag-1 correlation's about sqrt((1 - c^2) / N). Five standard errors each.
/// The spread's error depends on the tail (kurtosis): see `spread_tolerance`.
#[test]
fn jitter_matches_its_distribution_spread_and_correlation() {
    // The sample variance's relative standard error is sqrt((kurtosis - 1) / N_eff)
    // (half that for the standard deviation), N_eff = N (1 - c^2) / (1 + c^2).
    let spread_tolerance = |d: JitterDistribution, c: f64| {
        let kurtosis = match d {
            JitterDistribution::Uniform => 1.8,
            JitterDistribution::Normal => 3.0,
            d => shape_moments(d).2,
        };
        let n_eff = N as f64 * (1.0 - c * c) / (1.0 + c * c);
        5.0 * 0.5 * ((kurtosis - 1.0) / n_eff).sqrt()
    };
    for distribution in [
        JitterDistribution::Uniform,
        JitterDistribution::Normal,
        JitterDistribution::Pareto,
        JitterDistribution::Paretonormal,
    ] {
        for c in [0.0, 0.5, 0.9] {
            let x = draw(
                JitterConfig {
                    jitter: 4.0,
                    correlation: c,
                    distribution,
                },
                7,
            );
            let (mean, sd, rho) = stats(&x);
            // netem's uniform takes `jitter` as the half-width: sd = J / sqrt(3).
            let want_sd = if distribution == JitterDistribution::Uniform {
                4.0 / 3f64.sqrt()
            } else {
                4.0
            };
            let se_mean = want_sd * ((1.0 + c) / (N as f64 * (1.0 - c))).sqrt();
            assert!(
                mean.abs() < 5.0 * se_mean,
                "{distribution:?} c {c}: mean {mean}"
            );
            let rel = (sd - want_sd).abs() / want_sd;
            assert!(
                rel < spread_tolerance(distribution, c),
                "{distribution:?} c {c}: sd {sd}"
            );
            // Through the copula the rank (Spearman) correlation of successive
            // values is (6/pi) asin(c/2) whatever the distribution; the Pearson
            // correlation is c itself for normal. Bartlett: the lag-1 estimate's
            // standard error is about sqrt((1 - c^2) / N); at least 1/sqrt(N) here.
            let se_rho = ((1.0 - c * c) / N as f64)
                .sqrt()
                .max(1.0 / (N as f64).sqrt());
            let want_rank = 6.0 / std::f64::consts::PI * (c / 2.0).asin();
            let rank = stats(&ranks(&x)).2;
            assert!(
                (rank - want_rank).abs() < 5.0 * se_rho,
                "{distribution:?} c {c}: rank correlation {rank} vs {want_rank}"
            );
            if distribution == JitterDistribution::Normal {
                assert!((rho - c).abs() < 5.0 * se_rho, "c {c}: rho {rho}");
            }
        }
    }
    // Pareto's tail: skewed right, so the median sits below the mean.
    let mut x = draw(
        JitterConfig {
            jitter: 1.0,
            correlation: 0.0,
            distribution: JitterDistribution::Pareto,
        },
        3,
    );
    x.sort_by(f64::total_cmp);
    assert!(x[N / 2] < -0.2, "median {}", x[N / 2]);
}

/// Loss runs: the loss rate against the stationary probability, and the mean burst
/// length against 1/r (simple Gilbert: every packet in the bad state is lost).
/// A Markov chain's loss indicator has lag correlation lambda = 1 - p - r, so the
/// rate's standard error is sqrt(pi (1 - pi) (1 + lambda) / (N (1 - lambda))); a
/// burst length is geometric with mean 1/r and variance (1 - r)/r^2, averaged over
/// about N pi r bursts. Five standard errors each.
#[test]
fn gilbert_elliott_loss_rate_and_burst_length_match_the_closed_form() {
    for (p, r) in [(0.01, 0.3), (0.002, 0.05), (0.05, 0.5)] {
        let model = LossModel::Gemodel {
            p,
            r,
            bad_loss: 1.0,
            good_loss: 0.0,
        };
        let mut loss = Loss::new(&model);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let lost: Vec<bool> = (0..N).map(|_| loss.lose(&mut rng)).collect();
        let rate = lost.iter().filter(|l| **l).count() as f64 / N as f64;
        let pi = loss_rate(&model);
        assert!((pi - p / (p + r)).abs() < 1e-15);
        let lambda = 1.0 - p - r;
        let se = (pi * (1.0 - pi) * (1.0 + lambda) / (N as f64 * (1.0 - lambda))).sqrt();
        assert!(
            (rate - pi).abs() < 5.0 * se,
            "p {p} r {r}: rate {rate} vs {pi}"
        );
        let mut bursts = Vec::new();
        let mut run = 0u32;
        for l in &lost {
            if *l {
                run += 1;
            } else if run > 0 {
                bursts.push(f64::from(run));
                run = 0;
            }
        }
        let mean = bursts.iter().sum::<f64>() / bursts.len() as f64;
        let se_b = ((1.0 - r) / (r * r) / bursts.len() as f64).sqrt();
        assert!(
            (mean - 1.0 / r).abs() < 5.0 * se_b,
            "p {p} r {r}: burst {mean} vs {}",
            1.0 / r
        );
    }
}

#[test]
fn gilbert_elliott_with_partial_loss_and_the_four_state_model_match_their_rates() {
    let cases = [
        LossModel::Gemodel {
            p: 0.02,
            r: 0.2,
            bad_loss: 0.6,
            good_loss: 0.01,
        },
        LossModel::State {
            p13: 0.01,
            p31: 0.4,
            p32: 0.1,
            p23: 0.3,
            p14: 0.005,
        },
    ];
    for model in cases {
        let mut loss = Loss::new(&model);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let rate = (0..N).filter(|_| loss.lose(&mut rng)).count() as f64 / N as f64;
        let pi = loss_rate(&model);
        // Bursty: allow for correlation with a generous effective count of N / 20.
        let se = (pi * (1.0 - pi) / (N as f64 / 20.0)).sqrt();
        assert!((rate - pi).abs() < 5.0 * se, "{model:?}: {rate} vs {pi}");
    }
    // The 4-state chain's stationary distribution solves every balance equation
    // (pi = pi P, state by state), and the chains that are not irreducible end
    // where they must.
    let (p13, p31, p32, p23, p14) = (0.01, 0.4, 0.1, 0.3, 0.005);
    let s = StateChain::stationary(p13, p31, p32, p23, p14);
    assert!((s.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    let next = [
        s[0] * (1.0 - p13 - p14) + s[2] * p31 + s[3],
        s[1] * (1.0 - p23) + s[2] * p32,
        s[0] * p13 + s[1] * p23 + s[2] * (1.0 - p31 - p32),
        s[0] * p14,
    ];
    for k in 0..4 {
        assert!(
            (next[k] - s[k]).abs() < 1e-12,
            "state {}: {next:?} vs {s:?}",
            k + 1
        );
    }
    assert_eq!(
        StateChain::stationary(0.0, 0.4, 0.1, 0.3, 0.25),
        [0.8, 0.0, 0.0, 0.2]
    );
    let t = StateChain::stationary(0.1, 0.0, 0.1, 0.3, 0.0);
    assert!(
        (t[1] - 0.75).abs() < 1e-12 && (t[2] - 0.25).abs() < 1e-12,
        "{t:?}"
    );
}

#[test]
fn a_csv_replay_reads_back_row_by_row_and_loops() {
    let mut r = Replay::parse_csv("delay,lost\n3,0\n5,1\n0,0\n").expect("csv");
    let got: Vec<(u32, bool)> = (0..6).map(|_| r.packet(true)).collect();
    let want = [
        (3, false),
        (5, true),
        (0, false),
        (3, false),
        (5, true),
        (0, false),
    ];
    assert_eq!(got, want);
    // A sample not sent takes no row: the next packet gets the next one.
    assert_eq!(r.packet(false), (0, false));
    assert_eq!(r.packet(true), (3, false));
    assert_eq!(r.bound(), 5);
    for (text, needle) in [
        ("delay,lost\n1.5,0\n", "line 2: delay 1.5"),
        ("delay,lost\n-1,0\n", "line 2: delay -1"),
        ("delay,lost\n1\n", "line 2: expected 2 columns"),
        ("delay,lost\n1,2\n", "line 2: lost 2"),
        ("delay,lost\n", "no packets"),
        ("d,l\n1,0\n", "header"),
    ] {
        let e = Replay::parse_csv(text).expect_err(text).to_string();
        assert!(e.contains(needle), "{text}: {e}");
    }
}

/// A channel over a Mahimahi link that sends 1504 bytes every 2 ms (the trace
/// `2, 4`, looped), packets of 278 bytes (250 and UDP/IPv4's 28), one a ms: the
/// opportunity at a packet's own millisecond is burned before it is queued (mm-link's
/// `rationalize` before `enqueue`), so packets sent at even ms wait 2 ms and those at
/// odd ms 1 ms (the replay before this link gave 0 and 1: it used the arrival's own
/// millisecond); at ten packets a ms the 50-packet drop-tail queue refuses all but
/// the link's 1504 bytes / 2 ms; an idle hour is skipped, not walked.
#[test]
fn a_channel_over_a_mahimahi_link_delivers_at_mm_links_opportunities() {
    use crate::channel::{Channel, Emitted, Value};
    use tactile_scenario::{ChannelConfig, LinkConfig, QueueKind};
    let cfg = LinkConfig::mahimahi("x");
    let over = |cfg: &LinkConfig, t_s: f64| {
        let link = Replay::parse_mahimahi("2\n4\n", cfg).expect("trace");
        Channel::new(&ChannelConfig::default(), 1, 1).with_replay(link, t_s)
    };
    let sample = |n: u64| {
        [Value {
            v: n as f64,
            sent_seq: n,
            ..Value::default()
        }; 3]
    };
    // What the receiver got: the packet, its age, and whether it is the last again.
    let seen = |e: Emitted| {
        let v = e.values[0];
        (v.sent_seq, v.delay_samples, e.substituted)
    };
    let mut ch = over(&cfg, 1e-3);
    let got: Vec<(u64, u32, bool)> = (0..7).map(|n| seen(ch.push(n, sample(n)))).collect();
    let want = [
        (0, 0, true),
        (0, 1, true),
        (1, 1, false),
        (1, 2, true),
        (3, 1, false),
        (3, 2, true),
        (5, 1, false),
    ];
    assert_eq!(got, want);
    // A forged number far ahead, and one going back, move the link's time not at all.
    let mut forged = over(&cfg, 1e-3);
    let got: Vec<(u64, u32, bool)> = [0, 1, 1 << 40, 2, 1, 3, 4, 5, 6]
        .into_iter()
        .enumerate()
        .map(|(k, n)| (k, seen(forged.push(n, sample(n)))))
        .filter(|(k, _)| *k != 2 && *k != 4)
        .map(|(_, g)| g)
        .collect();
    assert_eq!(got, want);
    let tail = LinkConfig {
        queue: QueueKind::Droptail,
        packets: Some(50),
        ..cfg.clone()
    };
    let mut fast = over(&tail, 1e-4);
    let lost = (0..10_000)
        .filter(|&n| fast.push(n, sample(n)).lost)
        .count();
    // 1504 / 278 = 5.41 packets every 20 samples of the 10,000 sent (at most one
    // lost a sample): 2,705 carried, the rest refused.
    let departed = fast.link_stats().expect("a link").departed;
    assert!(
        (10_000 - lost as u64).abs_diff(2_705) <= 60,
        "{lost} lost, {departed} departed"
    );
    let mut late = over(&cfg, 1e-3);
    let t = 3_600_000;
    assert!(late.push(t, sample(t)).substituted);
    assert!(late.push(t + 1, sample(t + 1)).substituted);
    assert_eq!(seen(late.push(t + 2, sample(t + 2))), (t + 1, 1, false));
    assert!(Replay::parse_mahimahi("3\n2\n", &cfg).is_err());
    let e = Replay::parse_mahimahi("x\n", &cfg).expect_err("no number");
    let cause = std::error::Error::source(&e).expect("the integer's reason");
    assert!(cause.is::<std::num::ParseIntError>(), "{cause:?}");
    assert_eq!(
        e.to_string(),
        "line 1: \"x\" is not a whole number of milliseconds"
    );
}

#[test]
fn seeded_and_repeatable() {
    let cfg = JitterConfig {
        jitter: 3.0,
        correlation: 0.3,
        distribution: JitterDistribution::Paretonormal,
    };
    assert_eq!(draw(cfg.clone(), 1), draw(cfg.clone(), 1));
    assert_ne!(draw(cfg.clone(), 1), draw(cfg, 2));
}

#[test]
fn phi_is_the_normal_cdf() {
    for (z, want) in [
        (0.0, 0.5),
        (1.0, 0.841_344_746),
        (-1.96, 0.024_997_895),
        (3.0, 0.998_650_102),
    ] {
        assert!((phi(z) - want).abs() < 2e-7, "{z}: {}", phi(z));
    }
}

/// A sample's rest (a 6-DoF sample's rotational half, an MMT model) arrives in its
/// position's packet: delayed and held exactly as the first value, never noised, and
/// the values unchanged by it.
#[test]
fn the_rest_rides_the_first_values_packet() {
    use crate::channel::{Channel, Rest, Value, FORWARD_STREAM};
    use tactile_scenario::{ChannelConfig, JitterConfig};
    let cfg = ChannelConfig {
        delay: [4, 4, 4],
        noise_std: [1e-3; 3],
        jitter: Some(JitterConfig {
            jitter: 2.0,
            correlation: 0.0,
            distribution: Default::default(),
        }),
        reorder: true,
        ..Default::default()
    };
    let vals = |n: u64| {
        [0, 1, 2].map(|i| Value {
            v: n as f64 + i as f64,
            origin_seq: n,
            ..Default::default()
        })
    };
    let extra = |n: u64| Rest {
        rotation: [n as f64, -(n as f64), 0.5, 1.0],
        flags: (n % 3) as u32,
        model: [0.0, 0.0, 1.0, n as f64 * 1e-3, 600.0],
        model_seq: n / 4,
    };
    let (mut with, mut without) = (
        Channel::new(&cfg, 3, FORWARD_STREAM),
        Channel::new(&cfg, 3, FORWARD_STREAM),
    );
    for n in 0..2_000u64 {
        // Every fifth sample unsent: the receiver holds the last packet, rotation too.
        let sent = n % 5 != 1;
        let e = with.push_packet(n, vals(n), extra(n), sent);
        let plain = without.push_packet(n, vals(n), Rest::default(), sent);
        assert_eq!(e.values, plain.values, "sample {n}");
        assert_eq!(e.extra, extra(e.values[0].origin_seq), "sample {n}");
    }
}
