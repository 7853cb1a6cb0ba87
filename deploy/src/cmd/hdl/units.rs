//! Vectors for the f32 units (`f32_add.v` .. `f32_sqrt.v`): IEEE binary32, round to
//! nearest even, subnormals kept, exactly as the kernels' f32 steps compute on this
//! machine (Rust's `+ - * /` and `sqrt`). One line a sample: the operands and the
//! result as f32 bits. A NaN result is compared as a class (IEEE leaves the payload
//! open, and LLVM may swap the operands of a commutative operation).
//!
//! Each op's vectors are every pair of the special values (zeros, subnormals, the
//! normal limits, ones and their neighbours, infinities, quiet and signalling NaN),
//! exact ties and results that overflow or underflow, then half random bit patterns
//! and half operands of nearby exponents (alignment, cancellation, subnormal results).

use super::vectors::SplitMix;

/// An f32 unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// a + b.
    Add,
    /// a - b.
    Sub,
    /// a * b.
    Mul,
    /// a / b.
    Div,
    /// sqrt(a).
    Sqrt,
}

impl Unit {
    /// The result, as the model computes it.
    pub fn eval(self, a: f32, b: f32) -> f32 {
        match self {
            Unit::Add => a + b,
            Unit::Sub => a - b,
            Unit::Mul => a * b,
            Unit::Div => a / b,
            Unit::Sqrt => a.sqrt(),
        }
    }

    fn binary(self) -> bool {
        self != Unit::Sqrt
    }
}

/// Special values (positive; both signs are used).
const SPECIAL: [u32; 14] = [
    0x0000_0000, // +0
    0x0000_0001, // smallest subnormal
    0x0000_0003,
    0x0040_0000, // a mid subnormal
    0x007f_ffff, // largest subnormal
    0x0080_0000, // smallest normal
    0x0080_0001, //
    0x3f7f_ffff, // 1 - ulp
    0x3f80_0000, // 1
    0x3f80_0001, // 1 + ulp
    0x3fc0_0000, // 1.5
    0x7f7f_ffff, // largest finite
    0x7f80_0000, // infinity
    0x7fc0_0000, // quiet NaN
];

/// A signalling NaN (the units must quiet it).
const SNAN: u32 = 0x7f80_0001;

fn signed(v: &[u32]) -> Vec<u32> {
    v.iter().flat_map(|&b| [b, b | 0x8000_0000]).collect()
}

/// Operands that round exactly half way, and results that leave the normal range.
fn ties(op: Unit) -> Vec<(u32, u32)> {
    let f = |x: f32| x.to_bits();
    let p = |e: i32| 2f32.powi(e);
    match op {
        Unit::Add | Unit::Sub => vec![
            (f(1.0), f(p(-24))),                 // tie to even: stays 1
            (f(1.0 + p(-23)), f(p(-24))),        // tie to even: rounds up
            (f(1.0), f(p(-24) + p(-40))),        // just above the tie
            (f(p(-125)), f(-p(-125) + p(-140))), // cancellation into a subnormal
            (0x0000_0001, 0x0000_0001),          // subnormal sum, exact
            (0x0080_0000, 0x8000_0001),          // normal minus subnormal
            (f(f32::MAX), f(f32::MAX)),          // overflow
            (f(f32::MAX), f(p(103))),            // rounds to inf (tie above MAX)
            (f(f32::MAX), f(p(103) - p(80))),    // stays MAX
            (f(16_777_216.0), f(1.0)),           // 2^24 + 1: tie
        ],
        Unit::Mul => vec![
            (f(1.0 + p(-23)), f(1.0 + p(-23))), // 1 + 2^-22 + 2^-46: rounds down
            (f(1.5), 0x0000_0001),              // tie in the subnormals: to even (2)
            (f(2.5), 0x0000_0001),              // tie: to even (2)
            (f(0.5), 0x0000_0001),              // tie: to even (0)
            (f(0.75), 0x0000_0001),             // rounds up to the smallest
            (f(p(-75)), f(p(-75))),             // underflow to zero
            (f(p(-63)), f(p(-63))),             // exact subnormal
            (f(p(64)), f(p(64))),               // overflow
            (f(1.0 - p(-24)), 0x0080_0000),     // rounds up into the normals
        ],
        Unit::Div => vec![
            (f(1.0), f(3.0)),
            (0x0000_0001, f(2.0)),          // tie: to even (0)
            (0x0000_0003, f(2.0)),          // tie: to even (2)
            (f(1.0), f(f32::MAX)),          // subnormal quotient
            (f(f32::MAX), f(0.5)),          // overflow
            (0x0080_0000, f(1.0 + p(-23))), // just below the normals
            (f(1.0), 0x0000_0001),          // 2^149: overflow
            (0x007f_ffff, 0x0000_0001),
        ],
        Unit::Sqrt => [
            0x0000_0001,
            0x0000_0002,
            0x007f_ffff,
            f(2.0),
            f(0.5),
            f(f32::MAX),
        ]
        .into_iter()
        .map(|a| (a, 0))
        .collect(),
    }
}

/// Two operands of nearby exponents: alignment and cancellation in add, subnormal
/// and overflowing results in mul and div.
fn nearby(op: Unit, rng: &mut SplitMix) -> (u32, u32) {
    let r = rng.next();
    let sign = |bit: u64| ((r >> bit) as u32 & 1) << 31;
    let man_a = (r as u32) & 0x007f_ffff;
    let man_b = ((r >> 23) as u32) & 0x007f_ffff;
    let ea = 1 + (rng.next() % 254) as i32;
    let spread = (rng.next() % 60) as i32 - 30;
    let eb = match op {
        // The product's or quotient's exponent lands anywhere from zero to overflow.
        Unit::Mul => 127 + (rng.next() % 300) as i32 - 170 - (ea - 127),
        Unit::Div => ea - (rng.next() % 300) as i32 + 150,
        _ => ea + spread,
    }
    .clamp(0, 254);
    let a = sign(46) | (ea as u32) << 23 | man_a;
    let mut b = sign(47) | (eb as u32) << 23 | man_b;
    if matches!(op, Unit::Add | Unit::Sub) && r >> 48 & 3 == 0 {
        // Massive cancellation: b within a few ulps of -a (or a, for sub).
        let near = (a & 0x7fff_ffff)
            .wrapping_add((r >> 50) as u32 % 8)
            .min(0x7f7f_ffff);
        let flip = if op == Unit::Add { 0x8000_0000 } else { 0 };
        b = (a & 0x8000_0000 ^ flip) | near;
    }
    (a, b)
}

/// The operands for `op`: edges first, then `count` more from `seed`.
fn inputs(op: Unit, count: usize, rng: &mut SplitMix) -> Vec<(u32, u32)> {
    let mut special = signed(&SPECIAL);
    special.push(SNAN);
    let mut v: Vec<(u32, u32)> = if op.binary() {
        special
            .iter()
            .flat_map(|&a| special.iter().map(move |&b| (a, b)))
            .collect()
    } else {
        special.iter().map(|&a| (a, 0)).collect()
    };
    v.extend(ties(op));
    for i in 0..count {
        let pair = if i % 2 == 0 {
            let r = rng.next();
            ((r >> 32) as u32, r as u32)
        } else if op.binary() {
            nearby(op, rng)
        } else {
            // sqrt: every exponent, positive mostly, a dense sweep of the significand.
            let r = rng.next() as u32;
            (r & 0x7fff_ffff, 0)
        };
        v.push(pair);
    }
    v
}

/// Writes the vector file for `op` to `out`, a line at a time; returns its number
/// of samples.
pub fn unit_vectors(
    op: Unit,
    name: &str,
    count: usize,
    seed: u64,
    out: &mut dyn std::io::Write,
) -> std::io::Result<usize> {
    let mut rng = SplitMix(seed);
    let fields = if op.binary() { "a b r" } else { "a r" };
    writeln!(
        out,
        "// tactile hdl vectors: {name}, IEEE binary32 round to nearest even (the model's f32); seed {seed}\n// fields: {fields}"
    )?;
    let v = inputs(op, count, &mut rng);
    for &(a, b) in &v {
        let r = op.eval(f32::from_bits(a), f32::from_bits(b)).to_bits();
        if op.binary() {
            writeln!(out, "{a:08x} {b:08x} {r:08x}")?;
        } else {
            writeln!(out, "{a:08x} {r:08x}")?;
        }
    }
    Ok(v.len())
}
