//! The three arithmetics the kernels run in.
//!
//! Every kernel is written once, generic over a scalar type [`Real`] (f64 or f32) and a
//! trigonometric block [`Trig`] (the standard library's functions, or the CORDIC model of
//! the FPGA's TFB). Monomorphisation gives three separate, fully inlined kernels:
//!
//! | [`ArithKind`] | scalar | trigonometric block |
//! |---|---|---|
//! | `f64` | f64 | `std` (the reference) |
//! | `f32` | f32 | `std` (the paper's "software model") |
//! | `hybrid` | f32 | CORDIC in `[sV.N]` fixed point (the paper's FPGA datapath) |

use crate::cordic::Cordic;
use serde::{Deserialize, Serialize};
use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A floating-point scalar the kernels can run in.
pub trait Real:
    Copy
    + Debug
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Send
    + Sync
    + 'static
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// pi / 2, rounded to this type.
    const FRAC_PI_2: Self;
    /// Machine epsilon of this type.
    const EPSILON: Self;
    /// Converts from f64, rounding to nearest.
    fn from_f64(v: f64) -> Self;
    /// Converts to f64 exactly.
    fn to_f64(self) -> f64;
    /// Correctly rounded square root (IEEE 754, as the FPGA's Sqrt unit).
    fn sqrt(self) -> Self;
    /// True unless NaN or infinite.
    fn is_finite(self) -> bool;
    /// Absolute value.
    fn abs(self) -> Self;
    /// The larger of two values (the first if they compare equal or unordered).
    #[inline(always)]
    fn max_of(self, other: Self) -> Self {
        if other > self {
            other
        } else {
            self
        }
    }
}

macro_rules! impl_real {
    ($t:ty) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const FRAC_PI_2: Self = core::f64::consts::FRAC_PI_2 as $t;
            const EPSILON: Self = <$t>::EPSILON;
            #[inline(always)]
            fn from_f64(v: f64) -> Self {
                v as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                f64::from(self)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
        }
    };
}
impl_real!(f64);
impl_real!(f32);

/// The trigonometric function block (TFB) a kernel uses.
pub trait Trig<R: Real> {
    /// (sin x, cos x).
    fn sin_cos(&self, x: R) -> (R, R);
    /// Four-quadrant arctangent of y / x.
    fn atan2(&self, y: R, x: R) -> R;
    /// Arccosine; the argument is in [-1, 1] by the caller's contract.
    fn acos(&self, a: R) -> R;
    /// sin and cos of three angles at once (FK, the Jacobian and KFF need exactly
    /// three). The default is three calls; the CORDIC model runs the three rotations
    /// side by side so their dependency chains overlap, as the FPGA's parallel TFBs do.
    #[inline(always)]
    fn sin_cos3(&self, x: [R; 3]) -> ([R; 3], [R; 3]) {
        let (a, b, c) = (self.sin_cos(x[0]), self.sin_cos(x[1]), self.sin_cos(x[2]));
        ([a.0, b.0, c.0], [a.1, b.1, c.1])
    }
    /// IK's four angles, `[atan2(a.0, a.1), acos(b), atan2(c.0, c.1), acos(d)]`, which
    /// do not depend on one another. The default is four calls; the CORDIC model runs
    /// the four vectorings side by side, bit for bit the same.
    #[inline(always)]
    fn ik_angles(&self, a: (R, R), b: R, c: (R, R), d: R) -> [R; 4] {
        [
            self.atan2(a.0, a.1),
            self.acos(b),
            self.atan2(c.0, c.1),
            self.acos(d),
        ]
    }
    /// sin and cos over a slice. The default is the scalar loop; the CORDIC model
    /// overrides it with a structure-of-arrays version the compiler vectorises.
    fn sin_cos_batch(&self, x: &[R], sin: &mut [R], cos: &mut [R]) {
        for ((x, s), c) in x.iter().zip(sin.iter_mut()).zip(cos.iter_mut()) {
            (*s, *c) = self.sin_cos(*x);
        }
    }
}

/// The standard library's trigonometry, in the scalar's own precision.
#[derive(Debug, Clone, Copy, Default)]
pub struct StdTrig;

macro_rules! impl_std_trig {
    ($t:ty) => {
        impl Trig<$t> for StdTrig {
            #[inline(always)]
            fn sin_cos(&self, x: $t) -> ($t, $t) {
                <$t>::sin_cos(x)
            }
            #[inline(always)]
            fn atan2(&self, y: $t, x: $t) -> $t {
                <$t>::atan2(y, x)
            }
            #[inline(always)]
            fn acos(&self, a: $t) -> $t {
                <$t>::acos(a)
            }
        }
    };
}
impl_std_trig!(f64);
impl_std_trig!(f32);

impl Trig<f32> for Cordic {
    #[inline(always)]
    fn sin_cos(&self, x: f32) -> (f32, f32) {
        Cordic::sin_cos(self, x)
    }
    #[inline(always)]
    fn atan2(&self, y: f32, x: f32) -> f32 {
        Cordic::atan2(self, y, x)
    }
    #[inline(always)]
    fn acos(&self, a: f32) -> f32 {
        Cordic::acos(self, a)
    }
    #[inline(always)]
    fn sin_cos3(&self, x: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        Cordic::sin_cos3(self, x)
    }
    #[inline(always)]
    fn ik_angles(&self, a: (f32, f32), b: f32, c: (f32, f32), d: f32) -> [f32; 4] {
        Cordic::ik_angles(self, a, b, c, d)
    }
    fn sin_cos_batch(&self, x: &[f32], sin: &mut [f32], cos: &mut [f32]) {
        Cordic::sin_cos_batch(self, x, sin, cos);
    }
}

/// Which arithmetic a kernel runs in; chosen on the command line or in a scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ArithKind {
    /// f64 with the standard library's trigonometry: the reference.
    F64,
    /// f32 with the standard library's trigonometry: the paper's software model.
    F32,
    /// f32 with CORDIC in signed fixed point: the paper's FPGA datapath.
    #[default]
    Hybrid,
    /// The paper's modules as RTL, simulated clock by clock (Verilator): bit for bit
    /// `Hybrid`, and the clocks each sample took (built with the feature `rtl`).
    Rtl,
}

impl ArithKind {
    /// Every arithmetic computed in software, in reporting order (`Rtl` computes
    /// `Hybrid`'s results in simulated hardware).
    pub const ALL: [ArithKind; 3] = [ArithKind::F64, ArithKind::F32, ArithKind::Hybrid];

    /// The name used on the command line and in scenario files.
    pub fn name(self) -> &'static str {
        match self {
            ArithKind::F64 => "f64",
            ArithKind::F32 => "f32",
            ArithKind::Hybrid => "hybrid",
            ArithKind::Rtl => "rtl",
        }
    }
}

impl std::fmt::Display for ArithKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ArithKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "f64" => Ok(ArithKind::F64),
            "f32" => Ok(ArithKind::F32),
            "hybrid" => Ok(ArithKind::Hybrid),
            "rtl" => Ok(ArithKind::Rtl),
            other => Err(format!(
                "unknown arithmetic {other:?}: expected f64, f32, hybrid or rtl"
            )),
        }
    }
}
