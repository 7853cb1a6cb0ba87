//! What the TFB's RTL (`common/rtl/hdl/`) takes from this model: the quantised constants
//! of a format, the range reduction done in integers, and each function's values at
//! the stage boundaries. The Verilog parameters and the co-simulation's test vectors
//! are made here, from the same [`Cordic`] the kernels use, so the hardware and the
//! model cannot drift apart: a format [`CordicConfig::validate`] refuses has no
//! constants, and so no RTL.
//!
//! # The range reduction in hardware
//! The model reduces an angle to `[-pi, pi]` in f64 (Cody-Waite). The RTL has no f64
//! unit; it computes the same angle code exactly in fixed point:
//! `code = floor((A - k T + h) / 2^G)` with `A = floor(angle 2^(N+G))` (exact for
//! every angle the model reduces, whose f32 lsb is at least `2^-22`), `T = 2 pi
//! 2^(N+G)` rounded, `h` the rounding addend and `G` = [`REDUCE_GUARD`] guard bits. The
//! RTL takes `|k| <= 1`, i.e. angles below `3 pi`, which covers every joint angle and
//! angle sum the kernels feed it. [`Cordic::rtl_reduction_mismatch`] checks, for every
//! f32 the RTL reduces, that this equals the model's f64 code; the generator runs it
//! before it emits a format.

use super::*;

/// Guard bits of the RTL's range reduction below the angle lsb.
pub const REDUCE_GUARD: u32 = 32;

/// `2 pi 2^96` rounded to nearest: the first 24 hexadecimal digits of 2 pi's fraction
/// (6.487ED5110B4611A62633145C06E0E689...; the next digit is 0, so it rounds down).
const TWO_PI_96: u128 = 0x6_487E_D511_0B46_11A6_2633_145C;

/// The constants a format's RTL is built with (Verilog parameters), all from the model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RtlConstants {
    /// The format.
    pub config: CordicConfig,
    /// `Q(atan(2^-i) 2^N)` for each iteration, angle lsb.
    pub atan: Vec<i64>,
    /// `Q(2^(N+1) / K_n)`: the rotation's start vector, x/y lsb.
    pub gain: i64,
    /// `Q(pi 2^N)`: fold offset (rotation) and half-plane offset (vectoring).
    pub pi: i64,
    /// `Q(pi/2 2^N)`: fold threshold.
    pub half_pi: i64,
    /// `floor(pi 2^N)`: saturation of atan2.
    pub pi_floor: i64,
    /// `2^(N+1)`: +-1.0 in x/y lsb, saturation of sin/cos.
    pub one_xy: i64,
    /// `2 pi 2^(N+G)` rounded to nearest, `G` = [`REDUCE_GUARD`].
    pub two_pi: u128,
    /// f32 bits of the smallest positive angle the model reduces by 2 pi.
    pub pi_up: u32,
    /// f32 bits of the smallest positive angle it reduces by 4 pi: the RTL's rotation
    /// input range ends just below.
    pub three_pi_up: u32,
}

/// `sin_cos` at its stage boundaries (all codes as the RTL's registers hold them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinCosStages {
    /// F2FP output: the reduced angle code, angle lsb.
    pub code: i64,
    /// After the quadrant fold.
    pub folded: i64,
    /// Whether the fold negates the outputs.
    pub flip: bool,
    /// CORDIC output after sign and saturation, x/y lsb.
    pub sin_code: i64,
    /// As `sin_code`, for the cosine.
    pub cos_code: i64,
    /// FP2F outputs.
    pub sin: f32,
    /// FP2F outputs.
    pub cos: f32,
}

/// `atan2` (or `acos`'s vectoring) at its stage boundaries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VectorStages {
    /// F2FP output of x, angle lsb after the common power-of-two scaling.
    pub x_code: i64,
    /// F2FP output of y.
    pub y_code: i64,
    /// The angle code after the offset, saturation (and for acos the clamp at 0).
    pub z_code: i64,
    /// FP2F output.
    pub out: f32,
}

/// `acos` at its stage boundaries: the f32 front end, then the vectoring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AcosStages {
    /// The input clamped to `[-1, 1]`.
    pub clamped: f32,
    /// `sqrt((1 - a)(1 + a))` in f32.
    pub root: f32,
    /// The vectoring of `(a, root)`.
    pub vector: VectorStages,
}

impl Cordic {
    /// The constants of this format's RTL.
    pub fn rtl_constants(&self) -> RtlConstants {
        let n = self.n;
        let shift = 96 - self.cfg.frac - REDUCE_GUARD;
        RtlConstants {
            config: self.cfg,
            atan: self.atan[..n].to_vec(),
            gain: self.gain,
            pi: self.pi,
            half_pi: self.half_pi,
            pi_floor: self.pi_floor,
            one_xy: self.one_xy,
            two_pi: (TWO_PI_96 + (1u128 << (shift - 1))) >> shift,
            pi_up: first_with_turns(1),
            three_pi_up: first_with_turns(2),
        }
    }

    /// `sin_cos` with its stage values, for angles the RTL takes (`|k| <= 1`); `None`
    /// for the rest (non-finite, or at least 3 pi), where the RTL flags a range error.
    pub fn sin_cos_stages(&self, angle: f32) -> Option<SinCosStages> {
        if !angle.is_finite() || turns(angle).abs() > 1 {
            return None;
        }
        let code = i64::from(floor_code(self.angle_prefloor(f64::from(angle))));
        let (folded, flip) = self.fold(code);
        let (sin_code, cos_code) = self.rotate(folded, flip);
        Some(SinCosStages {
            code,
            folded,
            flip: flip != 0,
            sin_code,
            cos_code,
            sin: sin_code as f32 * self.xy_out,
            cos: cos_code as f32 * self.xy_out,
        })
    }

    /// `atan2` with its stage values; `None` when an input is NaN (output NaN).
    pub fn atan2_stages(&self, y: f32, x: f32) -> Option<VectorStages> {
        if x.is_nan() || y.is_nan() {
            return None;
        }
        let (y, x) = sanitize(y, x);
        Some(self.vector_stages(y, x, y.is_sign_negative(), false))
    }

    /// `acos` with its stage values; `None` for NaN (output NaN).
    pub fn acos_stages(&self, a: f32) -> Option<AcosStages> {
        if a.is_nan() {
            return None;
        }
        let clamped = a.clamp(-1.0, 1.0);
        let root = ((1.0 - clamped) * (1.0 + clamped)).sqrt();
        Some(AcosStages {
            clamped,
            root,
            vector: self.vector_stages(root, clamped, false, true),
        })
    }

    fn vector_stages(&self, y: f32, x: f32, y_negative: bool, acos: bool) -> VectorStages {
        let (wx, wy) = self.vector_prefloor(y, x);
        let (x_code, y_code) = (i64::from(floor_code(wx)), i64::from(floor_code(wy)));
        let (xf, yf, z0) = self.half_plane(x_code, y_code, y_negative);
        let z = self.vector(xf, yf, z0);
        let z_code = if acos { z.max(0) } else { z };
        VectorStages {
            x_code,
            y_code,
            z_code,
            out: z_code as f32 * self.angle_out,
        }
    }

    /// The RTL's angle code, computed as the RTL does (integers only, see the module
    /// doc); `None` where the RTL flags a range error.
    pub fn rtl_angle_code(&self, angle: f32, two_pi: u128) -> Option<i64> {
        let k = turns(angle);
        if !angle.is_finite() || k.abs() > 1 {
            return None;
        }
        let bits = angle.to_bits();
        let (exp, frac) = ((bits >> 23) & 0xff, bits & 0x7f_ffff);
        let mag = i128::from(if exp == 0 { frac } else { frac | 0x80_0000 });
        // angle = +-mag 2^(max(exp, 1) - 150); A = angle 2^(N+G), floored.
        let shift = exp.max(1) as i32 - 150 + (self.cfg.frac + REDUCE_GUARD) as i32;
        let (trunc, sticky) = if shift >= 0 {
            (mag << shift, 0)
        } else if shift > -64 {
            let s = -shift;
            (mag >> s, i128::from(mag & ((1i128 << s) - 1) != 0))
        } else {
            (0, i128::from(mag != 0))
        };
        let a = if bits >> 31 == 1 {
            -(trunc + sticky)
        } else {
            trunc
        };
        let h = if self.half > 0.0 {
            1i128 << (REDUCE_GUARD - 1)
        } else {
            0
        };
        let w = a - i128::from(k) * two_pi as i128 + h;
        Some((w >> REDUCE_GUARD) as i64)
    }

    /// The first f32 at which the RTL's reduction (with `two_pi`) and the model's
    /// disagree, searching every f32 the RTL reduces by 2 pi (`pi_up..three_pi_up`,
    /// both signs; below `pi_up` both are exact floors of the same value). `None`
    /// when they agree everywhere.
    pub fn rtl_reduction_mismatch(&self, c: &RtlConstants) -> Option<f32> {
        (c.pi_up..c.three_pi_up)
            .flat_map(|b| [b, b | 0x8000_0000])
            .map(f32::from_bits)
            .find(|&a| {
                let model = i64::from(floor_code(self.angle_prefloor(f64::from(a))));
                self.rtl_angle_code(a, c.two_pi) != Some(model)
            })
    }
}

/// How many turns the model's range reduction takes off `angle`: its `k`.
fn turns(angle: f32) -> i64 {
    if !fast_path(angle) {
        return i64::MAX;
    }
    ((f64::from(angle) * (1.0 / TAU) + ROUND_MAGIC) - ROUND_MAGIC) as i64
}

/// Bits of the smallest positive f32 whose `k` is `k` (found by bisection on the
/// ordered bit patterns of positive floats; `k` grows with the angle).
fn first_with_turns(k: i64) -> u32 {
    let (mut lo, mut hi) = (0u32, 0x4b00_0000u32); // 0 and 2^23 rad
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if turns(f32::from_bits(mid)) >= k {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_pi_constant_is_two_pi() {
        // Rounded to f64 it is TAU, and the model's own two-part 2 pi (TAU_HI exact,
        // TAU_LO good to about 2^-82) agrees with it to within TAU_LO's rounding.
        assert_eq!(TWO_PI_96 as f64 * pow2(-96), TAU);
        let hi = (TAU_HI * pow2(96)) as u128;
        let lo = TAU_LO * pow2(96);
        assert!(((TWO_PI_96 - hi) as f64 - lo).abs() < 65536.0);
    }

    #[test]
    fn the_range_thresholds_are_pi_and_three_pi() {
        let c = Cordic::new(CordicConfig::S16_13)
            .expect("the default format")
            .rtl_constants();
        let pi_up = f32::from_bits(c.pi_up);
        assert!(f64::from(pi_up) > PI && f64::from(f32::from_bits(c.pi_up - 1)) < PI);
        let three = f32::from_bits(c.three_pi_up);
        assert!(
            f64::from(three) > 3.0 * PI && f64::from(f32::from_bits(c.three_pi_up - 1)) < 3.0 * PI
        );
    }

    #[test]
    fn the_stages_end_where_the_functions_do() {
        let c = Cordic::new(CordicConfig::new(24, 21, None, Rounding::Truncate).expect("valid"))
            .expect("valid");
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..20_000 {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let (a, b) = (
                f32::from_bits((seed >> 32) as u32),
                f32::from_bits(seed as u32),
            );
            if let Some(s) = c.sin_cos_stages(a) {
                let (sin, cos) = c.sin_cos(a);
                assert_eq!(
                    (s.sin.to_bits(), s.cos.to_bits()),
                    (sin.to_bits(), cos.to_bits())
                );
                assert_eq!(c.rtl_angle_code(a, c.rtl_constants().two_pi), Some(s.code));
            }
            if let Some(s) = c.atan2_stages(a, b) {
                assert_eq!(s.out.to_bits(), c.atan2(a, b).to_bits(), "atan2({a}, {b})");
            }
            let x = (a.to_bits() % 2001) as f32 / 1000.0 - 1.0;
            for x in [x, a] {
                if let Some(s) = c.acos_stages(x) {
                    assert_eq!(s.vector.out.to_bits(), c.acos(x).to_bits(), "acos({x})");
                }
            }
        }
    }

    #[test]
    fn a_wrong_two_pi_is_found() {
        let c = Cordic::new(CordicConfig::S16_13).expect("the default format");
        let mut k = c.rtl_constants();
        k.two_pi += 1 << REDUCE_GUARD; // one angle lsb off
        assert!(c.rtl_reduction_mismatch(&k).is_some());
    }
}
