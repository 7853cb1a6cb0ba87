//! The person against the closed forms of its processes, and its reactions sample by
//! sample.

use super::*;

const T_S: f64 = 1e-3;

fn person(cfg: HumanConfig, seed: u64) -> Human {
    Human::new(&cfg, T_S, seed).expect("on")
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

#[test]
fn off_is_no_person() {
    assert!(Human::new(&HumanConfig::default(), T_S, 1).is_none());
}

#[test]
fn tremor_has_the_asked_rms_and_peaks_in_its_band() {
    let cfg = HumanConfig {
        tremor_um: 100.0,
        ..HumanConfig::default()
    };
    let mut h = person(cfg, 7);
    // 400 s at 1 kHz: the resonator's correlation time (1 / (pi 4 Hz), 80 ms) leaves
    // about 5,000 independent stretches, so the measured variance is within about
    // 2 sqrt(2 / 5000) = 4 % (two sigma): the RMS within 2 %; 3 % allows for the start.
    let x: Vec<f64> = (0..400_000)
        .map(|n| h.step(n, [0.0; 3]).offset[0])
        .collect();
    let r = rms(&x[1000..]);
    assert!((r / 100e-6 - 1.0).abs() < 0.03, "rms {r}");
    // Its autocorrelation is the resonator's closed form (rho_k = a1 rho_{k-1} +
    // a2 rho_{k-2}, rho_1 = a1 / (1 - a2)): negative half a period (50 ms) on,
    // positive a period on; over 5,000 independent stretches each within 0.03.
    let t = Tremor::new(
        &HumanConfig {
            tremor_um: 100.0,
            ..HumanConfig::default()
        },
        T_S,
        0,
    );
    let (mut r2, mut r1) = (1.0, t.a1 / (1.0 - t.a2));
    let var = x.iter().map(|v| v * v).sum::<f64>();
    let mut at = [0.0; 151];
    for (lag, got) in at.iter_mut().enumerate().skip(2) {
        let rho = t.a1 * r1 + t.a2 * r2;
        (r2, r1) = (r1, rho);
        *got = got_rho(&x, lag, var);
        assert!((*got - rho).abs() < 0.03, "lag {lag}: {got} vs {rho}");
    }
    assert!(at[50] < -0.3 && at[100] > 0.2, "{} {}", at[50], at[100]);
}

fn got_rho(x: &[f64], lag: usize, var: f64) -> f64 {
    x.iter().zip(&x[lag..]).map(|(a, b)| a * b).sum::<f64>() / var
}

#[test]
fn the_wander_is_an_ou_process_of_the_asked_spread_and_time() {
    let cfg = HumanConfig {
        drift_mm: 2.0,
        drift_s: 0.01,
        ..HumanConfig::default()
    };
    let mut h = person(cfg, 3);
    let x: Vec<f64> = (0..1_000_000)
        .map(|n| h.step(n, [0.0; 3]).offset[1])
        .collect();
    let x = &x[1000..];
    // 10^6 samples over a 10-sample correlation time: 5 x 10^4 independent ones, the
    // variance within 2 sqrt(2 / 5e4) = 1.3 %; the lag-1 correlation within 0.01.
    assert!((rms(x) / 2e-3 - 1.0).abs() < 0.02, "rms {}", rms(x));
    let c = x.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / x.iter().map(|v| v * v).sum::<f64>();
    let phi = (-T_S / 0.01f64).exp();
    assert!((c - phi).abs() < 0.01, "lag-1 {c} vs {phi}");
}

fn reacting(response: Response) -> HumanConfig {
    HumanConfig {
        reaction_ms: 150.0,
        reaction_sd_ms: 0.0,
        response,
        ..HumanConfig::default()
    }
}

/// A force of `f` N along +z from sample 100 to `until`.
fn felt(n: u64, until: u64) -> [f64; 3] {
    match (100..until).contains(&n) {
        true => [0.0, 0.0, 2.0],
        false => [0.0; 3],
    }
}

#[test]
fn a_pause_starts_a_reaction_time_after_the_force_and_lasts_its_time() {
    let mut h = person(reacting(Response::Pause), 1);
    let p: Vec<u64> = (0..2000)
        .map(|n| h.step(n, felt(n, 5000)).progress)
        .collect();
    // Felt first at 100, noticed there, the response 150 samples later: the path
    // waits from 250 for 250 samples, then goes on; the lasting force is not
    // reacted to again.
    assert_eq!(p[250], 249);
    assert_eq!(p[499], 249);
    assert_eq!(p[500], 250);
    assert_eq!(p[1999], 1999 - 250);
    assert_eq!(h.reacted, 1);
}

#[test]
fn a_stop_waits_while_the_force_lasts() {
    let mut h = person(reacting(Response::Stop), 1);
    let p: Vec<u64> = (0..2000)
        .map(|n| h.step(n, felt(n, 1000)).progress)
        .collect();
    assert_eq!(p[250], 249);
    assert_eq!(p[999], 249);
    assert_eq!(p[1000], 250);
    // The force is gone: the next one is reacted to again.
    let q: Vec<u64> = (2000..2400)
        .map(|n| h.step(n, [0.0, 3.0, 0.0]).progress)
        .collect();
    assert_eq!(h.reacted, 2);
    // Noticed at 2000, so the path waits from 2150 on.
    assert_eq!(q[0] + 149, q[149]);
    assert_eq!(q[149], q[399]);
}

#[test]
fn a_back_off_retreats_along_the_force_holds_and_returns() {
    let mut h = person(reacting(Response::BackOff), 1);
    let s: Vec<Sway> = (0..1500).map(|n| h.step(n, felt(n, 5000))).collect();
    // Response at 250: 200 samples out, 250 held, 200 back; the path waits through
    // the first two.
    assert_eq!(s[250].offset, [0.0; 3]);
    assert!(
        (s[450].offset[2] - 2e-3).abs() < 1e-12,
        "{:?}",
        s[450].offset
    );
    assert!((s[699].offset[2] - 2e-3).abs() < 1e-12);
    assert_eq!(s[699].progress, 249);
    assert_eq!(s[700].progress, 250);
    assert_eq!(s[900].offset, [0.0; 3]);
    assert_eq!([s[450].offset[0], s[450].offset[1]], [0.0, 0.0]);
}

#[test]
fn reaction_times_have_the_asked_mean_and_spread() {
    let cfg = HumanConfig {
        reaction_ms: 150.0,
        reaction_sd_ms: 30.0,
        ..HumanConfig::default()
    };
    // 1 ms samples round each draw: mean within 0.1 ms of it; 20,000 draws put the
    // mean within 2 x 30 / sqrt(2e4) = 0.4 ms and the spread within 1 % (two sigma of
    // a log-normal's sample spread at this shape, 1.4 %: 2 % allowed).
    let mut h = person(cfg, 11);
    let d: Vec<f64> = (0..20_000).map(|_| h.reaction_time() as f64).collect();
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let sd = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
    assert!((mean - 150.0).abs() < 0.6, "mean {mean}");
    assert!((sd / 30.0 - 1.0).abs() < 0.02, "sd {sd}");
    assert!(d.iter().all(|v| *v > 0.0));
}

#[test]
fn the_same_seed_is_the_same_person_and_each_part_has_its_own_stream() {
    let both = HumanConfig {
        tremor_um: 80.0,
        drift_mm: 1.0,
        ..HumanConfig::default()
    };
    let run = |cfg: &HumanConfig, seed| {
        let mut h = person(cfg.clone(), seed);
        (0..3000)
            .map(|n| h.step(n, [0.0; 3]).offset)
            .collect::<Vec<_>>()
    };
    assert_eq!(run(&both, 5), run(&both, 5));
    assert_ne!(run(&both, 5), run(&both, 6));
    // The tremor alone equals the tremor part of both: the wander draws apart.
    let tremor = HumanConfig {
        drift_mm: 0.0,
        ..both.clone()
    };
    let mut t = person(tremor, 5);
    let mut tr = Tremor::new(&both, T_S, 5);
    for n in 0..3000 {
        assert_eq!(t.step(n, [0.0; 3]).offset, tr.step());
    }
}

#[test]
fn ar2_gain_matches_a_long_run() {
    // The closed form against a direct sum of the impulse response's squares.
    let (a1, a2) = (1.6, -0.8);
    let (mut x1, mut x2, mut sum) = (1.0, 0.0, 1.0);
    for _ in 0..10_000 {
        let x = a1 * x1 + a2 * x2;
        sum += x * x;
        (x2, x1) = (x1, x);
    }
    assert!((ar2_gain(a1, a2) / sum - 1.0).abs() < 1e-9);
}
