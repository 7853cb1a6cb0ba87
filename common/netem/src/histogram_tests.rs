//! Delay histograms: the files read and refused, the draws against the file's
//! distribution (Kolmogorov-Smirnov, p99.99, rank correlation), and a channel driven
//! by one (reordering, seeded streams).

use super::*;
use crate::channel::{Channel, Value, FORWARD_STREAM};
use crate::tests::{ranks, stats};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tactile_scenario::{ChannelConfig, HistogramFormat as F, SHIPPED_HISTOGRAMS};

/// Uneven bins, an empty one inside and a long thin tail (counts of 3,233 packets):
/// its p99.99 lies in the last bin, which holds 3/3233 = 9.3e-4 of the mass.
const UNEVEN: &str =
    "delay_ms,count\n0,10\n0.5,300\n1,2000\n2,0\n2.5,800\n4,100\n8,20\n20,3\n50,0\n";

fn uneven() -> DelayHistogram {
    DelayHistogram::parse(UNEVEN, F::Csv).expect("the uneven histogram")
}

/// `n` draws from `h` with correlation `c`, seeded.
fn draws(h: &DelayHistogram, c: f64, n: usize, seed: u64) -> Vec<f64> {
    let mut d = HistogramDelay::new(h.clone(), c);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| d.next(&mut rng)).collect()
}

/// The Kolmogorov-Smirnov distance of sorted draws to `h`'s CDF.
fn ks(h: &DelayHistogram, sorted: &[f64]) -> f64 {
    let n = sorted.len() as f64;
    sorted
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let f = h.cdf(*x);
            (f - i as f64 / n).max((i + 1) as f64 / n - f)
        })
        .fold(0.0, f64::max)
}

/// The bin of `x` among `h`'s edges.
fn bin(h: &DelayHistogram, x: f64) -> usize {
    h.edges().partition_point(|e| *e <= x).saturating_sub(1)
}

const MILLION: usize = 1_000_000;

/// Over 10^6 independent draws the Kolmogorov-Smirnov distance to the file's CDF is
/// at most 0.005 and the draws' p99.99 lies within one bin of the file's, for the
/// uneven histogram and each shipped one. Tolerances from the count: 0.005 is
/// 5/sqrt(N), and by the Dvoretzky-Kiefer-Wolfowitz inequality (Massart's constant)
/// P(D > t/sqrt(N)) <= 2 exp(-2 t^2) = 4e-22 at t = 5; a draw of the bin's value
/// instead of uniform within the bin is off by up to a bin's mass (0.62 here, 0.1 for
/// the shipped ones). The p99.99's rank among N draws has standard deviation
/// sqrt(N q (1 - q)) = 10 draws, 1e-5 of the mass: five of them (5e-5) are far
/// inside the uneven histogram's last bin (9.3e-4), so "within one bin" holds by
/// five standard deviations there. The shipped files' tail bins hold one count of
/// 10^5 each (1e-5): there the quantile is checked in mass, |F(p) - 0.9999| within
/// five standard deviations, and the bins it lands from the file's are printed.
#[test]
fn a_million_draws_match_the_files_distribution_and_its_p9999() {
    let mut cases = vec![("uneven".to_string(), uneven())];
    for s in SHIPPED_HISTOGRAMS {
        let h = DelayHistogram::parse(s.text, s.format).expect(s.name);
        cases.push((s.name.to_string(), h));
    }
    let q = 0.9999;
    let sd = (q * (1.0 - q) / MILLION as f64).sqrt();
    for (k, (name, h)) in cases.iter().enumerate() {
        let mut x = draws(h, 0.0, MILLION, 17 + k as u64);
        x.sort_by(f64::total_cmp);
        let d = ks(h, &x);
        assert!(d <= 0.005, "{name}: KS distance {d}");
        let p = x[(q * MILLION as f64).ceil() as usize - 1];
        let want = h.quantile(q);
        let bins = bin(h, p).abs_diff(bin(h, want));
        println!("{name}: KS {d:.5}, p99.99 {p:.4} vs the file's {want:.4} ({bins} bins apart)");
        assert!(
            (h.cdf(p) - q).abs() <= 5.0 * sd,
            "{name}: p99.99 {p} vs {want}"
        );
        if name == "uneven" {
            assert!(bins <= 1, "p99.99 {p} vs {want}");
        }
    }
}

/// Draws uniform within the bin, not at its edge: the uneven histogram's second bin
/// (0.5 to 1 ms) gets draws all across it.
#[test]
fn a_bins_draws_spread_across_it() {
    let x = draws(&uneven(), 0.0, 100_000, 3);
    let inside: Vec<f64> = x.into_iter().filter(|v| (0.5..1.0).contains(v)).collect();
    // 300/3233 of 10^5: about 9,280 draws; their mean is the bin's middle, 0.75, to
    // within five standard errors (0.5/sqrt(12) / sqrt(9280) = 0.0015 each).
    assert!((8_500..10_000).contains(&inside.len()), "{}", inside.len());
    let mean = inside.iter().sum::<f64>() / inside.len() as f64;
    assert!((mean - 0.75).abs() < 5.0 * 0.0015, "mean {mean}");
    // No draw in the empty bin (2 to 2.5 ms).
    assert!(draws(&uneven(), 0.0, 100_000, 4)
        .iter()
        .all(|v| !(2.0..2.5).contains(v)));
}

/// Correlated: the lag-1 rank correlation of successive delays is (6/pi) asin(C/2)
/// (the copula's, whatever the histogram), and the marginal stays the file's. Over
/// 10^6 draws the lag-1 estimate's standard error is about sqrt((1 - c^2) / N), at
/// least 1/sqrt(N) here: five of them. The marginal's KS distance from a series of
/// effective count N (1 - c) / (1 + c) (5.3e4 at c = 0.9): 5/sqrt of that.
#[test]
fn correlated_delays_have_the_copulas_rank_correlation_and_the_files_marginal() {
    let h = uneven();
    for c in [0.0, 0.5, 0.9] {
        let x = draws(&h, c, MILLION, 5);
        let want = 6.0 / std::f64::consts::PI * (c / 2.0).asin();
        let se = ((1.0 - c * c) / MILLION as f64)
            .sqrt()
            .max(1.0 / (MILLION as f64).sqrt());
        let rank = stats(&ranks(&x)).2;
        assert!(
            (rank - want).abs() < 5.0 * se,
            "c {c}: rank correlation {rank} vs {want}"
        );
        let mut sorted = x;
        sorted.sort_by(f64::total_cmp);
        let n_eff = MILLION as f64 * (1.0 - c) / (1.0 + c);
        let d = ks(&h, &sorted);
        assert!(d <= 5.0 / n_eff.sqrt(), "c {c}: KS {d}");
    }
}

/// The three formats of one histogram read the same: the plain CSV in ms, D6G's
/// emulator CSV in ns (and in us, which it would misread; units are honoured here),
/// and the data repository's TAB-separated lines.
#[test]
fn the_three_formats_read_the_same_bins() {
    let csv = DelayHistogram::parse("delay_ms , count\n1,2\n1.5,6\n\n3,0\n", F::Csv).expect("csv");
    let d6g =
        DelayHistogram::parse("1000000,2,ns\n1500000,6,ns\n3000000,0,ns\n", F::D6g).expect("d6g");
    let us = DelayHistogram::parse("1000,2,us\n1500,6,us\n0.003,0,s\n", F::D6g).expect("us");
    let raw = DelayHistogram::parse(
        "1.000000\t0.25\n1.500000\t0.75\n3.000000\t0.000000\n",
        F::D6gData,
    )
    .expect("raw");
    for h in [&d6g, &us, &raw] {
        assert_eq!(h.edges(), csv.edges());
        for u in [0.0, 0.1, 0.25, 0.5, 0.99] {
            assert!((h.quantile(u) - csv.quantile(u)).abs() < 1e-12, "{u}");
        }
    }
    // A quarter of the mass in [1, 1.5), the rest in [1.5, 3), uniform within each.
    assert!((csv.quantile(0.125) - 1.25).abs() < 1e-12);
    assert!((csv.quantile(0.625) - 2.25).abs() < 1e-12);
    assert_eq!(csv.cdf(0.5), 0.0);
    assert_eq!(csv.cdf(3.5), 1.0);
    // In samples at 1 kHz: a sample a ms; at 200 Hz, 0.2.
    let s = csv.in_samples(200.0, 100_000).expect("in range");
    assert_eq!(s.edges(), [0.2, 0.30000000000000004, 0.6000000000000001]);
    assert!(csv.in_samples(1e8, 100_000).is_err());
}

/// Every bad file is refused, the message naming the line and the column.
#[test]
fn bad_files_are_refused_naming_the_line_and_the_column() {
    for (text, format, want) in [
        (
            "delay,count\n1,1\n2,0\n",
            F::Csv,
            "line 1: header is \"delay,count\", expected delay_ms,count",
        ),
        ("delay_ms,count\n", F::Csv, "no bin"),
        ("delay_ms,count\n1,1\n", F::Csv, "no bin"),
        (
            "delay_ms,count\n1,1\n2,1\n",
            F::Csv,
            "line 3: count 1 on the last line",
        ),
        (
            "delay_ms,count\n1,1\n2\n",
            F::Csv,
            "line 3: expected 2 columns (delay_ms,count)",
        ),
        (
            "delay_ms,count\n1,1\nNaN,0\n",
            F::Csv,
            "line 3: delay_ms \"NaN\" is not a finite number",
        ),
        (
            "delay_ms,count\n1,inf\n2,0\n",
            F::Csv,
            "line 2: count \"inf\" is not a finite number",
        ),
        (
            "delay_ms,count\n1,x\n2,0\n",
            F::Csv,
            "line 2: count \"x\" is not a finite number",
        ),
        (
            "delay_ms,count\n2,1\n1,0\n",
            F::Csv,
            "line 3: delay_ms 1 ms is not above the line before's 2 ms: bins must increase",
        ),
        (
            "delay_ms,count\n1,1\n1,0\n",
            F::Csv,
            "line 3: delay_ms 1 ms is not above",
        ),
        (
            "delay_ms,count\n-1,1\n1,0\n",
            F::Csv,
            "line 2: delay_ms -1 ms is negative",
        ),
        (
            "delay_ms,count\n1,1\n2,-3\n3,0\n",
            F::Csv,
            "line 3: count -3 is negative",
        ),
        (
            "delay_ms,count\n1,0\n2,0\n",
            F::Csv,
            "count: the counts add up to 0",
        ),
        (
            "delay_ms,count\n1,1e308\n2,1e308\n3,0\n",
            F::Csv,
            "count: the counts add up to inf",
        ),
        (
            "1000,1,ns\n2000,0,min\n",
            F::D6g,
            "line 2: unit \"min\" is not ns, us, ms or s",
        ),
        (
            "1000,1\n2000,0\n",
            F::D6g,
            "line 1: expected 3 columns (lower,count,unit)",
        ),
        (
            "1.0\t1\n0.5\t0\n",
            F::D6gData,
            "line 2: lower_ms 0.5 ms is not above",
        ),
        (
            "1.0,1\n2.0,0\n",
            F::D6gData,
            "line 1: expected 2 columns (lower_ms TAB count)",
        ),
    ] {
        let e = DelayHistogram::parse(text, format)
            .expect_err(text)
            .to_string();
        assert!(e.starts_with(want), "{text:?}: {e}");
    }
    let h = DelayHistogram::parse("delay_ms,count\n1,1\n\n200,0\n", F::Csv).expect("ok");
    let e = h.in_samples(1000.0, 100).expect_err("too long").to_string();
    assert_eq!(
        e,
        "line 4: delay_ms 200 ms is 200 samples at 1000 Hz, beyond 100"
    );
}

/// Packets `0..n` through a channel with histogram `h` (samples) and `reorder`; for
/// each sample, the newest packet the receiver holds and whether it is fresh; and
/// each packet's drawn delay.
fn through(h: &DelayHistogram, reorder: bool, n: u64) -> (Vec<(u64, bool)>, Vec<f64>) {
    let cfg = ChannelConfig {
        reorder,
        ..ChannelConfig::default()
    };
    let mut ch = Channel::new(&cfg, 9, FORWARD_STREAM).with_histogram(
        HistogramDelay::new(h.clone(), 0.0),
        9,
        FORWARD_STREAM,
    );
    let mut got = Vec::new();
    let mut drawn = Vec::new();
    for k in 0..n {
        let v = Value {
            sent_seq: k,
            origin_seq: k,
            ..Value::default()
        };
        let e = ch.push(k, [v; 3]);
        got.push((e.values[0].sent_seq, !e.substituted));
        drawn.push(e.jitter);
    }
    (got, drawn)
}

/// The newest packet arrived by each sample, from each packet's arrival: its sending
/// sample plus its drawn delay rounded, and (without reordering) no earlier than the
/// packet before it.
fn expected(drawn: &[f64], reorder: bool) -> Vec<Option<u64>> {
    let mut at = Vec::with_capacity(drawn.len());
    let mut last = 0u64;
    for (k, d) in drawn.iter().enumerate() {
        let a = k as u64 + d.round() as u64;
        let a = if reorder { a } else { a.max(last) };
        last = last.max(a);
        at.push(a);
    }
    (0..drawn.len() as u64)
        .map(|n| {
            (0..drawn.len())
                .filter(|k| at[*k] <= n)
                .map(|k| k as u64)
                .max()
        })
        .collect()
}

/// A channel driven by a histogram delivers each packet at its drawn delay, rounded
/// to whole samples: with `reorder` a short delay overtakes (and the overtaken packet
/// is never used), without it a packet waits for the one before. Both against the
/// definition, packet by packet, and the two differ on this histogram (0 to 20
/// samples, so successive delays cross).
#[test]
fn a_histogram_channel_delivers_at_the_drawn_delays_and_reorders_only_when_allowed() {
    let h = DelayHistogram::parse("delay_ms,count\n0,1\n10,3\n20,0\n", F::Csv).expect("h");
    let h = h.in_samples(1000.0, 100_000).expect("samples");
    let n = 2_000;
    let mut runs = Vec::new();
    for reorder in [true, false] {
        let (got, drawn) = through(&h, reorder, n);
        assert!(drawn.iter().all(|d| (0.0..=20.0).contains(d)));
        let want = expected(&drawn, reorder);
        for (k, ((seq, fresh), w)) in got.iter().zip(&want).enumerate() {
            if let Some(w) = w {
                assert_eq!(seq, w, "reorder {reorder}, sample {k}");
            } else {
                assert!(!fresh, "reorder {reorder}, sample {k}: nothing arrived yet");
            }
        }
        runs.push(got);
    }
    // The same draws (one seed): the two rules deliver differently.
    let differ = runs[0].iter().zip(&runs[1]).filter(|(a, b)| a != b).count();
    assert!(differ > 100, "reordering changes {differ} samples");
}

/// Seeded: the same seed draws the same delays; the histogram draws on a stream of
/// its own, so turning it on leaves the noise and the duplicates as they were.
#[test]
fn histogram_draws_are_seeded_and_leave_the_other_streams_alone() {
    let h = uneven().in_samples(1000.0, 100_000).expect("samples");
    let cfg = ChannelConfig {
        noise_std: [0.1, 0.2, 0.3],
        duplicate: 0.2,
        ..ChannelConfig::default()
    };
    let run = |with: Option<u64>| {
        let ch = Channel::new(&cfg, 4, FORWARD_STREAM);
        let mut ch = match with {
            Some(seed) => {
                ch.with_histogram(HistogramDelay::new(h.clone(), 0.5), seed, FORWARD_STREAM)
            }
            None => ch,
        };
        (0..5_000u64)
            .map(|k| ch.push(k, [Value::default(); 3]))
            .map(|e| (e.noise, e.duplicated, e.jitter))
            .collect::<Vec<_>>()
    };
    let (plain, a, b, other) = (run(None), run(Some(4)), run(Some(4)), run(Some(5)));
    assert_eq!(a, b, "same seed, same draws");
    assert_ne!(
        a.iter().map(|x| x.2).collect::<Vec<_>>(),
        other.iter().map(|x| x.2).collect::<Vec<_>>()
    );
    for (p, w) in plain.iter().zip(&a) {
        assert_eq!((p.0, p.1), (w.0, w.1), "noise and duplicates unchanged");
    }
    assert!(a.iter().any(|x| x.2 > 10.0), "delays drawn");
}
