//! Properties of the CORDIC model of the FPGA trigonometric block: every result within
//! the derived error bound (exhaustive code sweeps plus proptest, over the configured
//! formats and over random configurations), bounds tight enough that the sweeps could
//! fail, batch functions bit-identical to the scalar ones, configuration validation,
//! special inputs and determinism.

use std::sync::OnceLock;

use proptest::prelude::*;
use tactile_math::cordic::{Cordic, CordicConfig, CordicError, Rounding};

const PI: f64 = std::f64::consts::PI;
const PI_F32: f32 = std::f32::consts::PI;
const ROUNDINGS: [Rounding; 2] = [Rounding::Nearest, Rounding::Truncate];
/// `(word, frac)` of the accuracy tests, each with both roundings and default iterations.
const FORMATS: [(u32, u32); 4] = [(16, 13), (32, 29), (12, 9), (24, 21)];

fn cordic(word: u32, frac: u32, rounding: Rounding) -> Cordic {
    let cfg = CordicConfig::new(word, frac, None, rounding).expect("valid format");
    Cordic::new(cfg).expect("valid config")
}

/// The eight blocks of [`FORMATS`] x [`ROUNDINGS`], built once.
fn blocks() -> &'static [Cordic] {
    static BLOCKS: OnceLock<Vec<Cordic>> = OnceLock::new();
    BLOCKS.get_or_init(|| {
        FORMATS
            .iter()
            .flat_map(|&(w, f)| ROUNDINGS.map(|r| cordic(w, f, r)))
            .collect()
    })
}

fn name(c: &Cordic) -> String {
    let k = c.config();
    format!(
        "[s{}.{}] {:?} n={}",
        k.word, k.frac, k.rounding, k.iterations
    )
}

fn sin_cos_err(c: &Cordic, angle: f32) -> f64 {
    let (s, co) = c.sin_cos(angle);
    let a = f64::from(angle);
    (f64::from(s) - a.sin())
        .abs()
        .max((f64::from(co) - a.cos()).abs())
}

fn atan2_err(c: &Cordic, y: f32, x: f32) -> f64 {
    let want = if x == 0.0 && y == 0.0 {
        0.0 // the documented convention; f64::atan2 gives +-0 or +-pi by the zero signs
    } else {
        f64::from(y).atan2(f64::from(x))
    };
    (f64::from(c.atan2(y, x)) - want).abs()
}

fn acos_err(c: &Cordic, a: f32) -> f64 {
    (f64::from(c.acos(a)) - f64::from(a.clamp(-1.0, 1.0)).acos()).abs()
}

/// Largest error over `inputs`, with the input where it occurs.
fn worst<T: Copy>(inputs: &[T], err: impl Fn(T) -> f64) -> (f64, Option<T>) {
    inputs.iter().fold((0.0, None), |(w, at), &i| {
        let e = err(i);
        if e > w {
            (e, Some(i))
        } else {
            (w, at)
        }
    })
}

/// Checks `observed <= bound` and, so the bound is no blank cheque, `observed >=
/// bound / 10`.
fn assert_tight(what: &str, c: &Cordic, bound: f64, observed: f64, at: impl std::fmt::Debug) {
    eprintln!(
        "{} {what}: bound {bound:.3e}, observed {observed:.3e}",
        name(c)
    );
    assert!(
        observed <= bound,
        "{} {what}: error {observed:e} at {at:?} exceeds the bound {bound:e}",
        name(c)
    );
    assert!(
        observed >= bound / 10.0,
        "{} {what}: bound {bound:e} is more than 10x the worst observed {observed:e}",
        name(c)
    );
}

/// Every code of the angle register in `[-pi, pi]` and the midpoints between codes
/// (they exercise F2FP rounding ties) for words up to 16 bits; an even grid of
/// 2^16 codes plus off-code points for longer words; edge and out-of-range angles.
fn sin_cos_sweep(c: &Cordic) -> Vec<f32> {
    let cfg = c.config();
    let ulp = cfg.ulp();
    let top = (PI / ulp).ceil() as i64 + 1;
    let step = if cfg.word <= 16 { 1 } else { 2 * top / 65_536 };
    let mut v: Vec<f32> = (-top..=top)
        .step_by(step as usize)
        .flat_map(|k| [0.0, 0.5, 0.3].map(|o| ((k as f64 + o) * ulp) as f32))
        .collect();
    let h = std::f32::consts::FRAC_PI_2;
    for a in [PI_F32, h, 1.0, 0.0] {
        let below = f32::from_bits(a.to_bits().saturating_sub(1));
        v.extend([a, -a, below, -below, f32::from_bits(a.to_bits() + 1)]);
    }
    v.extend([
        1e-30,
        -0.0,
        7.0,
        -100.25,
        1234.567,
        -98_765.43,
        4.0e6,
        -4.194_304e6,
    ]);
    v
}

/// Circles of radius 1e-6 to 1e3 at 4096 angles each, the axes (signed zeros), both
/// sides of the branch cut, and the origin.
fn atan2_sweep() -> Vec<(f32, f32)> {
    let n = 4096;
    let radii = [1e-6, 3.3e-3, 0.7, 1.0, 123.0, 1e3];
    let mut v: Vec<(f32, f32)> = radii
        .iter()
        .enumerate()
        .flat_map(|(j, &r)| {
            (0..n).map(move |k| {
                let t = -PI + 2.0 * PI * (k as f64 + 0.5 + 0.13 * j as f64) / n as f64;
                ((r * t.sin()) as f32, (r * t.cos()) as f32)
            })
        })
        .collect();
    for r in [1e-6f32, 1.0, 1e3, f32::MAX] {
        v.extend([
            (0.0, r),
            (0.0, -r),
            (-0.0, -r),
            (r, 0.0),
            (-r, 0.0),
            (r, -0.0),
        ]);
        v.extend([(r * 1e-7, -r), (-r * 1e-7, -r), (r, r), (-r, -r)]);
    }
    v.extend([(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0)]);
    v.extend([
        (1e-45, 1.0),
        (-1e-45, -1.0),
        (1e-45, 1e-45),
        (3.0e38, -1e-45),
    ]);
    v
}

/// `[-1, 1]` in steps of 2^-15, the 64 f32 values next to each of -1, 0 and 1.
fn acos_sweep() -> Vec<f32> {
    let mut v: Vec<f32> = (0..=65_536)
        .map(|k| (-1.0 + f64::from(k) / 32_768.0) as f32)
        .collect();
    for j in 1..=64u32 {
        let below_one = f32::from_bits(1.0f32.to_bits() - j);
        v.extend([below_one, -below_one, f32::from_bits(j), -f32::from_bits(j)]);
    }
    v
}

#[test]
fn sin_cos_within_bound_on_dense_sweep() {
    for c in blocks() {
        let (observed, at) = worst(&sin_cos_sweep(c), |a| sin_cos_err(c, a));
        assert_tight("sin/cos", c, c.sin_cos_error_bound(), observed, at);
    }
}

#[test]
fn atan2_within_bound_on_dense_sweep() {
    let points = atan2_sweep();
    for c in blocks() {
        let (observed, at) = worst(&points, |(y, x)| atan2_err(c, y, x));
        assert_tight("atan2", c, c.atan2_error_bound(), observed, at);
    }
}

#[test]
fn acos_within_bound_on_dense_sweep() {
    let points = acos_sweep();
    for c in blocks() {
        let (observed, at) = worst(&points, |a| acos_err(c, a));
        assert_tight("acos", c, c.acos_error_bound(), observed, at);
    }
}

#[test]
fn bounds_are_small_and_shrink_with_the_word() {
    let s16 = Cordic::new(CordicConfig::S16_13).expect("default is valid");
    assert!(
        s16.sin_cos_error_bound() < 1e-3,
        "{}",
        s16.sin_cos_error_bound()
    );
    let s32 = cordic(32, 29, Rounding::Nearest);
    assert!(
        s32.sin_cos_error_bound() < 1e-7,
        "{}",
        s32.sin_cos_error_bound()
    );
    // An atan2 result in [2, pi] has an f32 ulp of 2^-22: rounding it to f32 alone
    // costs up to 2^-23 = 1.2e-7, so at [s32.29] only the rest must stay below 1e-7.
    let f32_rounding = 2f64.powi(-23);
    assert!(s32.atan2_error_bound() < 1e-7 + f32_rounding);
    assert!(s32.acos_error_bound() < 1e-7 + f32_rounding + 1e-7);
    for r in ROUNDINGS {
        let chain: Vec<Cordic> = [(12, 9), (16, 13), (24, 21), (32, 29)]
            .iter()
            .map(|&(w, f)| cordic(w, f, r))
            .collect();
        for pair in chain.windows(2) {
            assert!(pair[1].sin_cos_error_bound() < pair[0].sin_cos_error_bound() / 8.0);
            assert!(pair[1].atan2_error_bound() < pair[0].atan2_error_bound());
            assert!(pair[1].acos_error_bound() < pair[0].acos_error_bound());
        }
    }
}

#[test]
fn outputs_stay_in_range_and_special_inputs_behave() {
    for c in blocks() {
        let (s, co) = c.sin_cos(f32::NAN);
        assert!(s.is_nan() && co.is_nan());
        for a in [f32::INFINITY, f32::NEG_INFINITY] {
            let (s, co) = c.sin_cos(a);
            assert!(s.is_nan() && co.is_nan());
        }
        for a in [5.0e6f32, -1e10, 3.0e38, f32::MAX, f32::MIN] {
            let (s, co) = c.sin_cos(a);
            assert!(
                s.abs() <= 1.0 && co.abs() <= 1.0,
                "{} at {a}: {s} {co}",
                name(c)
            );
        }
        for a in sin_cos_sweep(c).into_iter().step_by(7) {
            let (s, co) = c.sin_cos(a);
            assert!(s.abs() <= 1.0 && co.abs() <= 1.0);
        }
        assert!(c.atan2(f32::NAN, 1.0).is_nan() && c.atan2(1.0, f32::NAN).is_nan());
        let inf = f32::INFINITY;
        let cases = [
            (inf, inf, PI / 4.0),
            (inf, -inf, 3.0 * PI / 4.0),
            (-inf, 5.0, -PI / 2.0),
            (1.0, -inf, PI),
            (-1.0, -inf, -PI),
            (0.0, inf, 0.0),
        ];
        for (y, x, want) in cases {
            let got = f64::from(c.atan2(y, x));
            assert!(
                (got - want).abs() <= c.atan2_error_bound(),
                "atan2({y}, {x}) = {got}"
            );
        }
        for (y, x) in atan2_sweep() {
            let r = c.atan2(y, x);
            assert!((-PI_F32..=PI_F32).contains(&r), "atan2({y}, {x}) = {r}");
        }
        assert_eq!(c.atan2(0.0, 0.0), 0.0);
        assert_eq!(c.atan2(-0.0, -0.0), 0.0);
        assert!(c.acos(f32::NAN).is_nan());
        for (a, clamped) in [(2.0, 1.0), (inf, 1.0), (-7.0, -1.0), (-inf, -1.0)] {
            assert_eq!(c.acos(a).to_bits(), c.acos(clamped).to_bits());
        }
        for a in acos_sweep().into_iter().step_by(5) {
            let r = c.acos(a);
            assert!((0.0..=PI_F32).contains(&r), "acos({a}) = {r}");
        }
    }
}

#[test]
fn results_are_deterministic() {
    let a = Cordic::new(CordicConfig::S16_13).expect("valid");
    let b = Cordic::new(CordicConfig::default()).expect("valid");
    let clone = a.clone();
    for angle in sin_cos_sweep(&a).into_iter().step_by(3) {
        let first = a.sin_cos(angle);
        for other in [a.sin_cos(angle), b.sin_cos(angle), clone.sin_cos(angle)] {
            assert_eq!(first.0.to_bits(), other.0.to_bits());
            assert_eq!(first.1.to_bits(), other.1.to_bits());
        }
    }
    for (y, x) in atan2_sweep().into_iter().step_by(3) {
        let first = a.atan2(y, x).to_bits();
        assert_eq!(first, a.atan2(y, x).to_bits());
        assert_eq!(first, b.atan2(y, x).to_bits());
        let s = (1.0 - x.clamp(-1.0, 1.0).powi(2)).sqrt();
        assert_eq!(a.acos(s).to_bits(), clone.acos(s).to_bits());
    }
}

#[test]
fn invalid_configs_are_rejected_with_clear_errors() {
    let err = |w, f, n| CordicConfig::new(w, f, n, Rounding::Nearest).expect_err("invalid");
    assert_eq!(err(40, 13, None), CordicError::WordOutOfRange { word: 40 });
    assert_eq!(
        err(40, 13, None).to_string(),
        "word length 40 is outside 8..=32"
    );
    assert_eq!(err(7, 4, None), CordicError::WordOutOfRange { word: 7 });
    assert_eq!(err(16, 0, None), CordicError::NoFractionBits);
    assert!(err(16, 0, None)
        .to_string()
        .contains("at least 1 fractional bit"));
    assert_eq!(
        err(16, 14, None).to_string(),
        "need at least 2 integer bits to hold pi (word 16, frac 14 leaves 1)"
    );
    let too_long = CordicError::TooFewIntegerBits {
        word: 16,
        frac: 20,
        integer_bits: -5,
    };
    assert_eq!(err(16, 20, None), too_long);
    assert_eq!(
        err(16, 13, Some(0)).to_string(),
        "iterations 0 is outside 1..=15 (frac + 2 for frac 13)"
    );
    let too_many = CordicError::IterationsOutOfRange {
        iterations: 16,
        max: 15,
        frac: 13,
    };
    assert_eq!(err(16, 13, Some(16)), too_many);
    // A struct built by hand (or deserialised) is validated by Cordic::new too.
    let raw = CordicConfig {
        word: 33,
        frac: 13,
        iterations: 14,
        rounding: Rounding::Truncate,
    };
    assert_eq!(
        raw.validate(),
        Err(CordicError::WordOutOfRange { word: 33 })
    );
    assert_eq!(
        Cordic::new(raw).err(),
        Some(CordicError::WordOutOfRange { word: 33 })
    );
    let raw = CordicConfig {
        iterations: 0,
        ..CordicConfig::S16_13
    };
    assert!(matches!(
        Cordic::new(raw),
        Err(CordicError::IterationsOutOfRange { .. })
    ));
    // The edges of every range are accepted.
    for (w, f) in [(8, 1), (8, 5), (32, 1), (32, 29)] {
        for n in [1, f + 2] {
            for r in ROUNDINGS {
                let cfg = CordicConfig::new(w, f, Some(n), r).expect("edge is valid");
                Cordic::new(cfg).expect("edge is valid");
            }
        }
    }
}

#[test]
fn defaults_and_serde() {
    let d = CordicConfig::S16_13;
    assert_eq!(CordicConfig::default(), d);
    let expected = CordicConfig {
        word: 16,
        frac: 13,
        iterations: 14,
        rounding: Rounding::Nearest,
    };
    assert_eq!(d, expected);
    assert_eq!(CordicConfig::default_iterations(13), 14);
    assert_eq!(CordicConfig::new(16, 13, None, Rounding::Nearest), Ok(d));
    assert_eq!(d.ulp(), 2f64.powi(-13));
    assert_eq!(Cordic::new(d).expect("valid").config(), &d);
    let text = "word = 16\nfrac = 13\niterations = 14\nrounding = \"nearest\"\n";
    assert_eq!(toml::from_str::<CordicConfig>(text), Ok(d));
    assert_eq!(toml::to_string(&d).expect("serialises"), text);
    let truncate = text.replace("nearest", "truncate");
    let parsed: CordicConfig = toml::from_str(&truncate).expect("valid toml");
    assert_eq!(parsed.rounding, Rounding::Truncate);
    assert!(toml::from_str::<CordicConfig>(&format!("{text}guard = 2\n")).is_err());
    assert!(toml::from_str::<CordicConfig>(&text.replace("nearest", "Nearest")).is_err());
}

/// Any valid configuration, iterations included.
fn any_config() -> impl Strategy<Value = CordicConfig> {
    (8u32..=32)
        .prop_flat_map(|w| (Just(w), 1..=w - 3))
        .prop_flat_map(|(w, f)| (Just(w), Just(f), 1..=f + 2, any::<bool>()))
        .prop_map(|(word, frac, iterations, nearest)| CordicConfig {
            word,
            frac,
            iterations,
            rounding: if nearest {
                Rounding::Nearest
            } else {
                Rounding::Truncate
            },
        })
}

/// Angles or coordinates of every kind: plain, large, tiny, zero, infinite, NaN.
fn any_input() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -4.0f32..4.0,
        2 => -5.0e6f32..5.0e6,
        2 => any::<f32>(),
        1 => prop::sample::select(vec![0.0, -0.0, 1e-45, PI_F32, -PI_F32, 1.0, -1.0]),
    ]
}

/// `sign * 10^exp` for exponents in `[-6, 3]`: every quadrant, every magnitude ratio.
fn coordinate() -> impl Strategy<Value = f32> {
    (any::<bool>(), -6.0f64..3.0).prop_map(|(neg, e)| {
        let v = 10f64.powf(e) as f32;
        if neg {
            -v
        } else {
            v
        }
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn sin_cos_within_bound(i in 0usize..8, angle in -PI_F32..=PI_F32, far in -4.0e6f32..4.0e6) {
        let c = &blocks()[i];
        prop_assert!(sin_cos_err(c, angle) <= c.sin_cos_error_bound(), "{} at {angle}", name(c));
        prop_assert!(sin_cos_err(c, far) <= c.sin_cos_error_bound(), "{} at {far}", name(c));
    }

    #[test]
    fn atan2_within_bound(i in 0usize..8, y in coordinate(), x in coordinate(), axis in any::<bool>()) {
        let c = &blocks()[i];
        let (y, x) = if axis { (0.0f32.copysign(y), x) } else { (y, x) };
        prop_assert!(atan2_err(c, y, x) <= c.atan2_error_bound(), "{} at ({y}, {x})", name(c));
        prop_assert!(atan2_err(c, x, 0.0) <= c.atan2_error_bound(), "{} at ({x}, 0)", name(c));
    }

    #[test]
    fn acos_within_bound(i in 0usize..8, a in -1.0f32..=1.0) {
        let c = &blocks()[i];
        prop_assert!(acos_err(c, a) <= c.acos_error_bound(), "{} at {a}", name(c));
    }

    /// The derivation holds for every configuration, not only the tuned ones.
    #[test]
    fn any_config_within_bounds(
        cfg in any_config(),
        angle in -4.0e3f32..4.0e3,
        y in coordinate(),
        x in coordinate(),
        a in -1.0f32..=1.0,
    ) {
        let c = Cordic::new(cfg).expect("strategy yields valid configs");
        prop_assert!(sin_cos_err(&c, angle) <= c.sin_cos_error_bound(), "{} at {angle}", name(&c));
        prop_assert!(atan2_err(&c, y, x) <= c.atan2_error_bound(), "{} at ({y}, {x})", name(&c));
        prop_assert!(acos_err(&c, a) <= c.acos_error_bound(), "{} at {a}", name(&c));
    }

    #[test]
    fn sin_cos_batch_is_bit_identical(
        cfg in any_config(),
        angles in prop::collection::vec(any_input(), 0..200),
    ) {
        let c = Cordic::new(cfg).expect("strategy yields valid configs");
        let (mut s, mut co) = (vec![0.0; angles.len()], vec![0.0; angles.len()]);
        c.sin_cos_batch(&angles, &mut s, &mut co);
        for (k, &a) in angles.iter().enumerate() {
            let (ws, wc) = c.sin_cos(a);
            prop_assert_eq!(s[k].to_bits(), ws.to_bits(), "sin {} at {}", name(&c), a);
            prop_assert_eq!(co[k].to_bits(), wc.to_bits(), "cos {} at {}", name(&c), a);
        }
    }

    #[test]
    fn sin_cos3_is_bit_identical(
        cfg in any_config(),
        a in any_input(),
        b in any_input(),
        d in any_input(),
    ) {
        let c = Cordic::new(cfg).expect("strategy yields valid configs");
        let (s, co) = c.sin_cos3([a, b, d]);
        for (k, x) in [a, b, d].into_iter().enumerate() {
            let (ws, wc) = c.sin_cos(x);
            prop_assert_eq!(s[k].to_bits(), ws.to_bits(), "sin {} at {}", name(&c), x);
            prop_assert_eq!(co[k].to_bits(), wc.to_bits(), "cos {} at {}", name(&c), x);
        }
    }

    /// IK's four angles side by side, each as its own call gives it: any inputs (NaN,
    /// infinities, zeros, acos arguments out of range) in any lane.
    #[test]
    fn ik_angles_are_bit_identical(
        cfg in any_config(),
        a in (any_input(), any_input()),
        b in any_input(),
        d in (any_input(), any_input()),
        e in any_input(),
    ) {
        let c = Cordic::new(cfg).expect("strategy yields valid configs");
        let got = c.ik_angles(a, b, d, e);
        let want = [c.atan2(a.0, a.1), c.acos(b), c.atan2(d.0, d.1), c.acos(e)];
        for k in 0..4 {
            prop_assert_eq!(got[k].to_bits(), want[k].to_bits(), "lane {} of {}", k, name(&c));
        }
    }

    #[test]
    fn atan2_batch_is_bit_identical(
        cfg in any_config(),
        points in prop::collection::vec((any_input(), any_input()), 0..200),
    ) {
        let c = Cordic::new(cfg).expect("strategy yields valid configs");
        let (y, x): (Vec<f32>, Vec<f32>) = points.iter().copied().unzip();
        let mut out = vec![0.0; y.len()];
        c.atan2_batch(&y, &x, &mut out);
        for (k, (&yk, &xk)) in y.iter().zip(&x).enumerate() {
            let want = c.atan2(yk, xk);
            prop_assert_eq!(out[k].to_bits(), want.to_bits(), "{} at ({}, {})", name(&c), yk, xk);
        }
    }
}

#[test]
fn batch_lengths_around_the_chunk_size() {
    let c = Cordic::new(CordicConfig::S16_13).expect("valid");
    for len in [0usize, 1, 7, 8, 9, 15, 16, 17, 63, 64, 65, 1000] {
        let a: Vec<f32> = (0..len).map(|k| k as f32 * 0.37 - 3.0).collect();
        let (mut s, mut co, mut t) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
        c.sin_cos_batch(&a, &mut s, &mut co);
        c.atan2_batch(&a, &s, &mut t);
        for k in 0..len {
            let (ws, wc) = c.sin_cos(a[k]);
            assert_eq!(
                (s[k].to_bits(), co[k].to_bits()),
                (ws.to_bits(), wc.to_bits())
            );
            assert_eq!(t[k].to_bits(), c.atan2(a[k], s[k]).to_bits());
        }
    }
}

#[test]
#[should_panic(expected = "cos_out length must match angles")]
fn batch_panics_on_mismatched_lengths() {
    let c = Cordic::new(CordicConfig::S16_13).expect("valid");
    c.sin_cos_batch(&[0.0; 4], &mut [0.0; 4], &mut [0.0; 3]);
}
