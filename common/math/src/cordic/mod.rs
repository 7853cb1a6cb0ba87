//! Bit-accurate model of the FPGA's trigonometric function block (TFB).
//!
//! The hardware receives f32 values, converts them to signed fixed point `[sV.N]`
//! (module F2FP: a V-bit two's-complement word with N fractional bits, so V-N-1
//! integer bits), runs CORDIC on integers and converts the result back to f32 (FP2F).
//! This module reproduces that datapath bit for bit: every intermediate value is an
//! integer (held in an `i64`, or an `i32` lane in the batch functions) that provably
//! fits a V-bit register, every right shift is an arithmetic shift followed by the
//! configured [`Rounding`], and every constant (arctangent table, 1/K gain, pi, pi/2)
//! is quantised once in [`Cordic::new`] with that same rounding.
//!
//! # Registers and why they fit in V bits
//! `frac <= word - 3` leaves at least 2 integer bits, so a register spans at least
//! `[-4, 4)` in units of its own scale.
//! * Angle register `z`, scale `2^-N`: it holds a reduced angle `|r| <= pi + 2^-N`,
//!   then the folded angle (`|z| <= pi/2`), then the CORDIC residual, which never
//!   exceeds `max(|z_0|, atan 1) <= pi/2`. In vectoring mode `z` starts at 0, only ever
//!   adds `+-atan(2^-i)` while tracking a vector angle in `[-pi/2, pi/2]` (so
//!   `|z| <= pi/2 + pi/4`), and the fold offset `+-pi` is added once at the end to a
//!   result that lies in `[-pi - 2^-N, pi + 2^-N]` before it is saturated to `+-pi`.
//! * Rotation mode `x, y`, scale `2^-(N+1)`: the rotated vector has length
//!   `<= 1 + 0.01` (it starts at `1/K`, grows by at most `K`, plus the rounding error
//!   derived in [`Cordic::sin_cos_error_bound`]). Only one integer bit is needed, so the
//!   datapath spends the second integer bit as a guard bit: x/y are `[sV.(N+1)]`,
//!   which is the 1QN output format of common FPGA CORDIC cores for a 2QN phase and
//!   halves every rounding error. `(x + 2^(i-1))`, the rounding adder before the
//!   shift, stays below `1.01 * 2^(N+1) + 2^N < 2^(N+2) <= 2^(V-1)`.
//! * Vectoring mode `x, y`, scale `2^-N`: inputs are scaled so `max(|x|,|y|)` is in
//!   `[0.5, 1)`, so the vector length is below `sqrt 2`; after growth by
//!   `K ~ 1.6468` it is below `2.33`; with rounding error and the rounding adder it
//!   stays below `3.4 < 4`.
//!
//! `Cordic::new` re-checks these limits numerically in debug builds.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, SQRT_2, TAU};

/// Shortest supported word (V).
pub const MIN_WORD: u32 = 8;
/// Longest supported word (V); every register therefore also fits an `i32` lane.
pub const MAX_WORD: u32 = 32;
/// Table capacity: at most `frac + 2 <= MAX_WORD - 1` iterations.
const TABLE_LEN: usize = MAX_WORD as usize;
/// Lanes per chunk in the batch functions (fixed so the inner loops vectorise).
const LANES: usize = 16;
/// Angles up to this magnitude take the fast, accurate range reduction.
const FAST_REDUCE_LIMIT: f64 = 4_194_304.0; // 2^22 rad
/// `1.5 * 2^52`: adding and subtracting it rounds an f64 below `2^51` to an integer.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;
/// 2*pi split for Cody-Waite reduction: `TAU_HI` keeps 30 significant bits so that
/// `k * TAU_HI` is exact for `k < 2^23`; `TAU_LO` is the rest of the *real* 2*pi
/// (`TAU` itself falls short of 2*pi by 2.449e-16).
const TAU_HI: f64 = f64::from_bits(TAU.to_bits() & !((1u64 << 23) - 1));
const TAU_LO: f64 = (TAU - TAU_HI) + 2.449_293_598_294_706_4e-16;
/// Absolute slack added to every bound: covers f64 rounding in the range reduction
/// (< 1e-15 for angles within [`FAST_REDUCE_LIMIT`]) and in evaluating the bound.
const SLACK: f64 = 1e-12;

/// Rounding applied by F2FP, by every right shift and to every quantised constant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Rounding {
    /// Floor: what a plain arithmetic shift does (error in `(-1, 0]` lsb).
    Truncate,
    /// Round half up: `(v + 2^(s-1)) >> s`, one carry-in on the shifter's adder
    /// (error in `(-1/2, 1/2]` lsb).
    Nearest,
}

/// Word, fraction and iteration count of the TFB datapath.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CordicConfig {
    /// Word length V in bits, `8..=32`.
    pub word: u32,
    /// Fractional bits N of the angle register, `1..=word-3`.
    pub frac: u32,
    /// CORDIC iterations, `1..=frac+2`.
    pub iterations: u32,
    /// Rounding mode.
    pub rounding: Rounding,
}

/// Why a [`CordicConfig`] is not a valid datapath.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum CordicError {
    /// The word does not fit the supported register widths.
    #[error("word length {word} is outside {MIN_WORD}..={MAX_WORD}")]
    WordOutOfRange {
        /// Requested word length.
        word: u32,
    },
    /// A zero-length fraction cannot represent any CORDIC step below 1 rad.
    #[error("fraction length 0 is not supported: need at least 1 fractional bit")]
    NoFractionBits,
    /// pi needs two integer bits (`[-4, 4)`).
    #[error(
        "need at least 2 integer bits to hold pi (word {word}, frac {frac} leaves {integer_bits})"
    )]
    TooFewIntegerBits {
        /// Requested word length.
        word: u32,
        /// Requested fraction length.
        frac: u32,
        /// `word - frac - 1`.
        integer_bits: i64,
    },
    /// Iterations beyond `frac + 2` only shift zeros (and would break the register proof).
    #[error("iterations {iterations} is outside 1..={max} (frac + 2 for frac {frac})")]
    IterationsOutOfRange {
        /// Requested iterations.
        iterations: u32,
        /// Largest allowed value, `frac + 2`.
        max: u32,
        /// Fraction length the limit derives from.
        frac: u32,
    },
}

impl CordicConfig {
    /// `[s16.13]` (range `[-4, 4)`, the 2QN phase format of FPGA CORDIC cores),
    /// `frac + 1 = 14` iterations, [`Rounding::Nearest`].
    ///
    /// Why: with `n` iterations the angle left over is at most `atan(2^-(n-1))`, one
    /// angle lsb for `n = N + 1`; the next step, `atan(2^-(N+1)) ~ lsb/2`, quantises to
    /// 0 (or a whole lsb) and would only add rounding. The derived sin/cos bound is
    /// smallest at `n = N + 1` (7.7e-4 at [s16.13], 8.6e-4 for `N` or `N + 2`).
    /// Nearest, because truncation biases every shift and every table entry the same
    /// way, so the errors add up instead of cancelling (bound 3.6e-3, observed
    /// 1.4e-3, vs 7.7e-4 and 4.3e-4), while round-half-up costs only a carry-in per
    /// adder on an FPGA.
    pub const S16_13: CordicConfig = CordicConfig {
        word: 16,
        frac: 13,
        iterations: Self::default_iterations(13),
        rounding: Rounding::Nearest,
    };

    /// Validated configuration; `iterations: None` picks [`Self::default_iterations`].
    pub fn new(
        word: u32,
        frac: u32,
        iterations: Option<u32>,
        rounding: Rounding,
    ) -> Result<Self, CordicError> {
        let iterations = iterations.unwrap_or(Self::default_iterations(frac));
        let cfg = CordicConfig {
            word,
            frac,
            iterations,
            rounding,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    /// Checks word, fraction and iterations, in that order.
    pub fn validate(&self) -> Result<(), CordicError> {
        let (word, frac, iterations) = (self.word, self.frac, self.iterations);
        if !(MIN_WORD..=MAX_WORD).contains(&word) {
            return Err(CordicError::WordOutOfRange { word });
        }
        if frac == 0 {
            return Err(CordicError::NoFractionBits);
        }
        let integer_bits = i64::from(word) - i64::from(frac) - 1;
        if integer_bits < 2 {
            return Err(CordicError::TooFewIntegerBits {
                word,
                frac,
                integer_bits,
            });
        }
        let max = frac + 2;
        if !(1..=max).contains(&iterations) {
            return Err(CordicError::IterationsOutOfRange {
                iterations,
                max,
                frac,
            });
        }
        Ok(())
    }

    /// `frac + 1`: the last iteration rotates by `atan(2^-N)`, one angle lsb (see
    /// [`Self::S16_13`] for why neither fewer nor more is better).
    pub const fn default_iterations(frac: u32) -> u32 {
        frac.saturating_add(1)
    }

    /// One lsb of the angle register, `2^-frac` rad.
    pub fn ulp(&self) -> f64 {
        pow2(-(self.frac as i32))
    }
}

impl Default for CordicConfig {
    fn default() -> Self {
        Self::S16_13
    }
}

/// The TFB with all constants and error bounds precomputed (about 0.9 KB), and for
/// short fractions the rotation's outputs tabled ([`table`]).
#[derive(Debug, Clone)]
pub struct Cordic {
    cfg: CordicConfig,
    /// `Q(atan(2^-i) * 2^N)`, angle lsb.
    atan: [i64; TABLE_LEN],
    /// Iterations, `<= TABLE_LEN`.
    n: usize,
    /// Rounding addend of a shift by `i`: `2^(i-1)` for Nearest (`i >= 1`), else 0.
    bias: [i64; TABLE_LEN + 1],
    /// `bias[i + 1] - bias[i]`, loaded rather than folded into immediates so the
    /// compiler keeps it off the critical path (see [`Self::rotate`]).
    dbias: [i64; TABLE_LEN],
    /// `Q(2^(N+1) / K_n)`: start vector in x/y lsb `2^-(N+1)`, cancels the CORDIC gain.
    gain: i64,
    /// `Q(pi * 2^N)` and `Q(pi/2 * 2^N)`: fold offset and fold threshold.
    pi: i64,
    half_pi: i64,
    /// `floor(pi * 2^N)`: saturation limit of atan2, never above the real pi.
    pi_floor: i64,
    /// `2^(N+1)`: +-1.0 in x/y lsb, saturation limit of sin/cos.
    one_xy: i64,
    /// F2FP: `2^N`, and the rounding addend 0.5 (Nearest) or 0 (Truncate).
    angle_scale: f64,
    half: f64,
    /// FP2F scales `2^-(N+1)` and `2^-N`.
    xy_out: f32,
    angle_out: f32,
    bounds: [f64; 3],
    /// The rotation's outputs by folded angle (short fractions only: [`table`]), made
    /// with the block, so a node's first sine costs no more than its others.
    table: Option<table::Table>,
}

impl Cordic {
    /// Validates `cfg` and precomputes tables, constants and error bounds.
    pub fn new(cfg: CordicConfig) -> Result<Self, CordicError> {
        cfg.validate()?;
        let frac = cfg.frac as i32;
        let n = cfg.iterations as usize;
        let nearest = cfg.rounding == Rounding::Nearest;
        let q = |v: f64| quantize(v, cfg.rounding);
        let mut atan = [0i64; TABLE_LEN];
        for (i, a) in atan.iter_mut().take(n).enumerate() {
            *a = q(atan_pow2(i) * pow2(frac));
        }
        let k_n: f64 = (0..n).map(growth).product();
        let mut c = Cordic {
            cfg,
            atan,
            n,
            bias: std::array::from_fn(|i| i64::from(nearest) * ((1i64 << i) >> 1)),
            dbias: std::array::from_fn(|i| {
                i64::from(nearest) * (((2i64 << i) >> 1) - ((1i64 << i) >> 1))
            }),
            gain: q(pow2(frac + 1) / k_n),
            pi: q(PI * pow2(frac)),
            half_pi: q(FRAC_PI_2 * pow2(frac)),
            pi_floor: (PI * pow2(frac)).floor() as i64,
            one_xy: 1i64 << (frac + 1),
            angle_scale: pow2(frac),
            half: if nearest { 0.5 } else { 0.0 },
            xy_out: pow2(-frac - 1) as f32,
            angle_out: pow2(-frac) as f32,
            bounds: [0.0; 3],
            table: None,
        };
        c.bounds = c.derive_bounds();
        c.table = table::Table::of(&c);
        Ok(c)
    }

    /// The configuration this block was built for.
    pub fn config(&self) -> &CordicConfig {
        &self.cfg
    }

    /// Rotation mode: `(sin, cos)` of `angle`.
    ///
    /// The angle is first reduced to `[-pi, pi]` in f64 (exact for f32 input: Cody-Waite
    /// with a 30-bit high part, error < 1e-15 for `|angle| <= 2^22`; larger angles use
    /// f64 `%` by 2*pi, still deterministic and in range, but their phase error grows
    /// like `|angle| * 4e-17`, and f32 spacing there exceeds 0.25 rad anyway). The
    /// reduced angle goes through F2FP, is folded into `[-pi/2, pi/2]` (subtract or add
    /// the quantised pi, negate the outputs), rotated, saturated to `[-1, 1]` and
    /// converted by FP2F. NaN or infinite input gives `(NaN, NaN)`.
    #[inline]
    pub fn sin_cos(&self, angle: f32) -> (f32, f32) {
        let a = f64::from(angle);
        if !fast_path(angle) {
            return self.sin_cos_cold(angle);
        }
        let (z, flip) = self.fold(i64::from(floor_code(self.angle_prefloor(a))));
        let (s, c) = self.rotated(z, flip);
        (s as f32 * self.xy_out, c as f32 * self.xy_out)
    }

    /// [`Self::rotate`]'s codes, from the table where there is one.
    #[inline(always)]
    fn rotated(&self, z: i64, flip: i64) -> (i64, i64) {
        match self.table.as_ref().and_then(|t| t.get(z, flip)) {
            Some(sc) => sc,
            None => self.rotate(z, flip),
        }
    }

    /// [`Self::sin_cos`] of three angles, bit-identical per angle, with the three
    /// rotations interleaved (what FK, the Jacobian and KFF need).
    #[inline]
    pub fn sin_cos3(&self, angles: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        if !angles.iter().all(|a| fast_path(*a)) {
            let r = angles.map(|a| self.sin_cos(a));
            return (r.map(|v| v.0), r.map(|v| v.1));
        }
        let mut z = [0i64; 3];
        let mut flip = [0i64; 3];
        for k in 0..3 {
            (z[k], flip[k]) = self.fold(i64::from(floor_code(
                self.angle_prefloor(f64::from(angles[k])),
            )));
        }
        let looked = self.table.as_ref().and_then(|t| {
            Some([
                t.get(z[0], flip[0])?,
                t.get(z[1], flip[1])?,
                t.get(z[2], flip[2])?,
            ])
        });
        let (s, c) = match looked {
            Some(sc) => (sc.map(|v| v.0), sc.map(|v| v.1)),
            None => self.rotate3(z, flip),
        };
        (
            s.map(|v| v as f32 * self.xy_out),
            c.map(|v| v as f32 * self.xy_out),
        )
    }

    #[cold]
    #[inline(never)]
    fn sin_cos_cold(&self, angle: f32) -> (f32, f32) {
        if !angle.is_finite() {
            return (f32::NAN, f32::NAN);
        }
        let r = f64::from(angle) % TAU;
        let r = if r > PI {
            r - TAU
        } else if r < -PI {
            r + TAU
        } else {
            r
        };
        let (z, flip) = self.fold(i64::from(floor_code(r * self.angle_scale + self.half)));
        let (s, c) = self.rotate(z, flip);
        (s as f32 * self.xy_out, c as f32 * self.xy_out)
    }

    /// Vectoring mode: the angle of `(x, y)` in `[-pi, pi]`.
    ///
    /// Both inputs are scaled by the same power of two (exact in floating point, an
    /// exponent adjustment in hardware) so that `max(|x|, |y|)` lies in `[0.5, 1)`,
    /// then F2FP, then folded into the right half plane by negating both when the
    /// quantised x is negative (the fold offset is `+pi` or `-pi` by the f32 sign bit
    /// of `y`, so `atan2(-0.0, -1.0)` is `-pi` as in `f32::atan2`), iterated, and
    /// saturated to `[-pi, pi]`. `atan2(+-0, +-0) = 0`. Infinite inputs become `+-1`
    /// and the other input a signed zero, which reproduces `f32::atan2` for them.
    /// NaN in gives NaN out.
    #[inline]
    pub fn atan2(&self, y: f32, x: f32) -> f32 {
        match self.atan2_input(y, x) {
            Some((x, y, z0)) => self.vector(x, y, z0) as f32 * self.angle_out,
            None => f32::NAN,
        }
    }

    /// [`Self::atan2`]'s vectoring input `(x, y, z0)`; `None` for NaN (NaN out).
    #[inline(always)]
    fn atan2_input(&self, y: f32, x: f32) -> Option<(i64, i64, i64)> {
        if x.is_nan() || y.is_nan() {
            return None;
        }
        let (y, x) = sanitize(y, x);
        let (wx, wy) = self.vector_prefloor(y, x);
        Some(self.half_plane(
            i64::from(floor_code(wx)),
            i64::from(floor_code(wy)),
            y.is_sign_negative(),
        ))
    }

    /// `acos(a) = atan2(sqrt(1 - a^2), a)` with the square root in f32, the radicand
    /// computed as `(1 - a) * (1 + a)` (exact factors near `|a| = 1`, where `1 - a*a`
    /// would lose up to 8e-7 rad). `a` is clamped to `[-1, 1]`, so no finite input
    /// gives NaN; the result is saturated to `[0, pi]`. NaN in gives NaN out.
    #[inline]
    pub fn acos(&self, a: f32) -> f32 {
        match self.acos_input(a) {
            Some((x, y, z0)) => self.vector(x, y, z0).max(0) as f32 * self.angle_out,
            None => f32::NAN,
        }
    }

    /// [`Self::acos`]'s vectoring input `(x, y, z0)`; `None` for NaN (NaN out).
    #[inline(always)]
    fn acos_input(&self, a: f32) -> Option<(i64, i64, i64)> {
        if a.is_nan() {
            return None;
        }
        let a = a.clamp(-1.0, 1.0);
        let s = ((1.0 - a) * (1.0 + a)).sqrt();
        let (wx, wy) = self.vector_prefloor(s, a);
        Some(self.half_plane(i64::from(floor_code(wx)), i64::from(floor_code(wy)), false))
    }

    /// `[atan2(a.0, a.1), acos(b), atan2(c.0, c.1), acos(d)]`, each bit for bit as its
    /// own call gives it, with the four vectorings interleaved: IK-HSD's angles, which
    /// do not depend on one another (the FPGA's IK module runs them in parallel TFBs).
    #[inline]
    pub fn ik_angles(&self, a: (f32, f32), b: f32, c: (f32, f32), d: f32) -> [f32; 4] {
        let inputs = [
            self.atan2_input(a.0, a.1),
            self.acos_input(b),
            self.atan2_input(c.0, c.1),
            self.acos_input(d),
        ];
        let codes = self.vector_lanes(inputs.map(|i| i.unwrap_or((0, 0, 0))));
        std::array::from_fn(|k| match inputs[k] {
            // The acos lanes' results are saturated at 0, as `acos` does.
            Some(_) if k % 2 == 1 => codes[k].max(0) as f32 * self.angle_out,
            Some(_) => codes[k] as f32 * self.angle_out,
            None => f32::NAN,
        })
    }

    /// Worst-case `|sin_cos(a) - (sin a, cos a)|` for `|a| <= 2^22` (`ulp = 2^-N`,
    /// `u = 2^-(N+1)` the x/y lsb, `e_i` the largest shift-rounding error of iteration
    /// `i`: `u/2` for Nearest, `(1 - 2^-i) u` for Truncate; `f(p) = sin p + cos p` for
    /// `p < pi/4`, else `sqrt 2`). Let `r` be the reduced angle and `Phi` the angle the
    /// x/y iterations really rotate by; the output error splits as
    /// `|K_n G u sin Phi - sin r| + |rounding in y|` (same for cos), so:
    /// 1. Input: F2FP of `r` errs by < 1 ulp (Truncate) or <= ulp/2 (Nearest); the
    ///    fold replaces pi by its quantised value, adding `|Q(pi) ulp - pi|`.
    /// 2. Residual: with the integer recursion `B_0 = max(H, P - H - 1, 1)` (largest
    ///    folded `|z|`), `B_{i+1} = max(a_i, |B_i - a_i|)`, the final `|z_n| <= B_n`
    ///    ulp; for the default this is 1 ulp = `atan(2^-(n-1))` after rounding.
    /// 3. Table: `Phi` uses the real `atan(2^-i)` while `z` subtracts `a_i ulp`:
    ///    `sum_i |atan(2^-i) - a_i ulp|` (a priori `<= n ulp/2` or `n ulp`; computed
    ///    exactly here from the table, 1.1 ulp at [s16.13] Nearest). Steps 1-3 bound
    ///    `|Phi - r|`, and sin/cos are 1-Lipschitz.
    /// 4. Gain: the start vector `G u` grows by exactly `K_n = prod sqrt(1 + 4^-i)`:
    ///    `|K_n G u - 1|`.
    /// 5. Rounding: iteration `i >= 1` adds `delta_i = d_i (-e^y_i, e^x_i)`, and the later
    ///    iterations map it linearly by `K_{i+1,n} R(phi_i)` with
    ///    `|phi_i| <= Phi_i = sum_{j>i} atan(2^-j)`. One output component of that is
    ///    `<= K_{i+1,n} e_i f(Phi_i)`, summed over `i = 1..n-1`. (The growth after a
    ///    rounding is at most `prod_{j>=2} sqrt(1 + 4^-j) = 1.042`: the big factors
    ///    `sqrt 2` and `sqrt 1.25` of iterations 0 and 1 come first. A blanket
    ///    `1.6468 sqrt(2) e` per step would overstate the term 2.2x.)
    /// 6. Saturation to `[-1, 1]` only moves towards the true value. FP2F is exact
    ///    when `N + 1 <= 24` (the integer fits the f32 mantissa), else it adds
    ///    half an f32 ulp below 1, `2^-25`.
    ///
    /// The sum plus 1e-12 slack is the bound: 7.7e-4 at [s16.13], 5.3e-8 at [s32.29]
    /// (of which 3.0e-8 is the f32 output rounding).
    pub fn sin_cos_error_bound(&self) -> f64 {
        self.bounds[0]
    }

    /// Worst-case `|atan2(y, x) - atan2_real(y, x)|` in rad over all finite inputs
    /// except `(0, 0)` (`ulp = 2^-N`, now also the x/y lsb; `e_i` and `f` as in
    /// [`Self::sin_cos_error_bound`], `e_in` the F2FP error, 1 or 1/2 ulp). Let
    /// `psi_i` be the real angle of the computed vector; scaling by `2^k` is exact.
    /// 1. Input: the scaled vector has length `>= 2^(N-1)` ulp (its larger component
    ///    is in `[0.5, 1)`, and `2^(N-1)` is a code, so it stays `>= 0.5` after F2FP).
    ///    F2FP moves it by `<= sqrt(2) e_in`, turning it by `eta_in <= asin(sqrt(2) e_in /
    ///    2^(N-1))`.
    /// 2. Rounding: iteration `i` rotates the vector exactly by `-+atan(2^-i)`, scales
    ///    it by `sqrt(1 + 4^-i)` and then adds `delta_i`, whose component across the
    ///    vector is `<= e_i f(A_i)` with `A_i` the angle bound below and whose length
    ///    is `<= sqrt(2) e_i`. With `L` a lower bound on the length (`L_0 = 2^(N-1)`,
    ///    `L_{i+1} = sqrt(1 + 4^-i) L_i - sqrt(2) e_i`), it turns the vector by
    ///    `eta_i <= atan(e_i f(A_i) / L_{i+1})`.
    /// 3. Residual: the decision is the sign of y (x stays >= 0), so
    ///    `|psi_0| <= R_0 = pi/2`, `A_i = max(atan 2^-i, |R_i - atan 2^-i|)`,
    ///    `R_{i+1} = A_i + eta_i`, and `|psi_n| <= R_n`.
    /// 4. Since `psi_0 = psi_n + sum s_i atan(2^-i) - sum eta_i` and the output is
    ///    `z = sum s_i a_i`, the error is `<= eta_in + R_n + sum eta_i + sum_i
    ///    |atan(2^-i) - a_i ulp|`, plus `|Q(pi) ulp - pi|` from the fold offset.
    /// 5. Saturation to `floor(pi 2^N)` ulp can only pull a result towards the true
    ///    value or leave it within `pi - floor(pi 2^N) ulp < ulp` of it. FP2F is exact
    ///    while `|z| < 2^24`, else it adds `2^-23` (half an f32 ulp below 4).
    ///
    /// If some `R_i >= pi/2` (only for tiny fractions or iteration counts) the decisions
    /// are no longer guaranteed and the bound is the trivial `2 pi`. Plus 1e-12 slack:
    /// 2.1e-3 at [s16.13], 1.9e-7 at [s32.29] (f32 output rounding 1.2e-7 of it).
    pub fn atan2_error_bound(&self) -> f64 {
        self.bounds[1]
    }

    /// Worst-case `|acos(a) - acos_real(a)|` over `a` in `[-1, 1]`: the atan2 bound
    /// for the f32 pair `(s, a)`, plus the f32 square root path. Each of `1 - a`,
    /// `1 + a`, their product and the square root rounds with relative error
    /// `<= 2^-24`, so `s = sqrt(1 - a^2) (1 + rho)` with `|rho| < 3 * 2^-24`. Scaling the
    /// y component of a unit vector `(a, s)` by `1 + rho` turns it by
    /// `<= |a s rho| / (1 - 2|rho|) <= |rho| / (2 (1 - 2|rho|))`, i.e. 9e-8 rad:
    /// 2.1e-3 at [s16.13], 2.8e-7 at [s32.29].
    pub fn acos_error_bound(&self) -> f64 {
        self.bounds[2]
    }
}

mod batch;
mod bounds;
mod datapath;
pub mod hdl;
mod table;

/// Whether `angle` takes the fast range reduction (false for NaN and infinities).
#[inline(always)]
fn fast_path(angle: f32) -> bool {
    f64::from(angle).abs() <= FAST_REDUCE_LIMIT
}

/// Vectoring inputs made finite: an infinite input becomes `+-1` and the other a
/// signed zero (what `f32::atan2` returns for infinities); NaN becomes a signed zero
/// (its output is replaced by NaN anyway).
#[inline(always)]
fn sanitize(y: f32, x: f32) -> (f32, f32) {
    let inf = x.is_infinite() | y.is_infinite();
    let fix = |v: f32| {
        if v.is_infinite() {
            v.signum()
        } else if inf | v.is_nan() {
            0.0f32.copysign(v)
        } else {
            v
        }
    };
    (fix(y), fix(x))
}

/// `2^e` as f64 (exact for the exponents used here).
fn pow2(e: i32) -> f64 {
    f64::from_bits(((1023 + i64::from(e)) as u64) << 52)
}

/// Growth of iteration `i`: `sqrt(1 + 4^-i)`.
fn growth(i: usize) -> f64 {
    (1.0 + pow2(-2 * i as i32)).sqrt()
}

/// Constant quantisation with the datapath's rounding (inputs are non-negative).
fn quantize(v: f64, rounding: Rounding) -> i64 {
    match rounding {
        Rounding::Truncate => v.floor() as i64,
        Rounding::Nearest => (v + 0.5).floor() as i64,
    }
}

/// F2FP rounding: `floor(w)` for `|w| < 2^31`, which holds for every F2FP input
/// (`|w| <= pi 2^29 + 1`). Adding `1.5 * 2^52` rounds `w` to an integer that lands
/// in the low mantissa bits (two's complement); one compare undoes a round-up.
/// Exact, libm-free, non-saturating, so the batch loops vectorise it.
#[inline(always)]
fn floor_code(w: f64) -> i32 {
    let r = w + ROUND_MAGIC;
    let t = r.to_bits() as i32;
    t - i32::from(r - ROUND_MAGIC > w)
}

/// `atan(2^-i)` from its Taylor series in plain IEEE arithmetic (summed smallest term
/// first), so the quantised table is the same on every platform whatever its libm.
fn atan_pow2(i: usize) -> f64 {
    if i == 0 {
        return FRAC_PI_4;
    }
    // Terms x^(2k+1) / (2k+1) with x = 2^-i <= 1/2: powers of two are exact, each
    // term rounds once, and 30 terms reach 2^-60 relative.
    let x = pow2(-(i as i32));
    let mut terms = [0.0f64; 30];
    let mut p = x;
    for (k, t) in terms.iter_mut().enumerate() {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        *t = sign * p / (2 * k + 1) as f64;
        p *= x * x;
    }
    terms.iter().rev().sum()
}
