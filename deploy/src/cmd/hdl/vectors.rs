//! Test vectors from the hybrid model: one line a sample, hexadecimal fields (inputs
//! and outputs as f32 bits, the fixed-point values at the stage boundaries as
//! two's-complement words), read by the testbench with `$readmemh`.
//!
//! Each function's vectors are its edges (zero, +-pi and the reduction's thresholds,
//! the fold thresholds, the format's limits, acos at +-1, atan2 on the axes and at
//! infinities, subnormals, NaN), an even sweep of its whole input range, and random
//! inputs from the seed (uniform in the range, and random bit patterns).

use super::Bench as _;
use super::Block;
use std::f32::consts::PI;
use std::io::Write;
use tactile_math::cordic::hdl::RtlConstants;
use tactile_math::cordic::Cordic;

/// f32 bits of the quiet NaN the model and the RTL return.
const NAN_BITS: u32 = 0x7fc0_0000;

/// A word of the TFB as the RTL's vector files write it: hexadecimal, as wide as the
/// word.
struct Code {
    width: usize,
    mask: u64,
}

impl Code {
    fn of(&self, v: i64) -> String {
        format!("{:0w$x}", v as u64 & self.mask, w = self.width)
    }
}

/// Writes the vector file for `function` to `out`: a comment header naming the
/// fields, then one line per sample, each written as it is made (10^7 sincos samples
/// are a 510 MB file, measured in docs/09; a 1.7 GB file of vectors held whole with
/// its lines took 4.86 GB). Returns the number of samples.
pub fn vectors(
    cordic: &Cordic,
    k: &RtlConstants,
    function: Block,
    count: usize,
    seed: u64,
    out: &mut dyn Write,
) -> std::io::Result<usize> {
    let mut rng = SplitMix(seed);
    let code = Code {
        width: k.config.word.div_ceil(4) as usize,
        mask: (1u64 << k.config.word) - 1, // word <= 32
    };
    writeln!(
        out,
        "// tactile hdl vectors: {} for [s{}.{}], {} iterations, {:?}; seed {seed}\n// fields: {}",
        function.name(),
        k.config.word,
        k.config.frac,
        k.config.iterations,
        k.config.rounding,
        function.fields()
    )?;
    let mut n = 0;
    let mut line = |text: String| {
        n += 1;
        writeln!(out, "{text}")
    };
    match function {
        Block::Sincos => sincos_inputs(k, count, &mut rng)
            .into_iter()
            .try_for_each(|a| line(sincos_line(cordic, &code, f32::from_bits(a))))?,
        Block::Atan2 => atan2_inputs(count, &mut rng)
            .into_iter()
            .try_for_each(|(y, x)| {
                line(atan2_line(
                    cordic,
                    &code,
                    f32::from_bits(y),
                    f32::from_bits(x),
                ))
            })?,
        Block::Acos => acos_inputs(count, &mut rng)
            .into_iter()
            .try_for_each(|a| line(acos_line(cordic, &code, f32::from_bits(a))))?,
        // The units' and modules' vectors are made by their own generators.
        _ => {}
    }
    Ok(n)
}

/// One sin/cos vector: input, invalid flag, the stages' codes and the outputs.
fn sincos_line(cordic: &Cordic, code: &Code, a: f32) -> String {
    match cordic.sin_cos_stages(a) {
        Some(s) => format!(
            "{:08x} 0 {} {} {} {} {} {:08x} {:08x}",
            a.to_bits(),
            code.of(s.code),
            code.of(s.folded),
            u8::from(s.flip),
            code.of(s.sin_code),
            code.of(s.cos_code),
            s.sin.to_bits(),
            s.cos.to_bits()
        ),
        None => format!(
            "{:08x} 1 {z} {z} 0 {z} {z} {NAN_BITS:08x} {NAN_BITS:08x}",
            a.to_bits(),
            z = code.of(0)
        ),
    }
}

/// One atan2 vector: inputs, valid flag, the vectoring's codes and the output.
fn atan2_line(cordic: &Cordic, code: &Code, y: f32, x: f32) -> String {
    match cordic.atan2_stages(y, x) {
        Some(s) => format!(
            "{:08x} {:08x} 1 {} {} {} {:08x}",
            y.to_bits(),
            x.to_bits(),
            code.of(s.x_code),
            code.of(s.y_code),
            code.of(s.z_code),
            s.out.to_bits()
        ),
        None => format!(
            "{:08x} {:08x} 0 {z} {z} {z} {NAN_BITS:08x}",
            y.to_bits(),
            x.to_bits(),
            z = code.of(0)
        ),
    }
}

/// One acos vector: input, valid flag, the root, the vectoring's codes and the output.
fn acos_line(cordic: &Cordic, code: &Code, a: f32) -> String {
    match cordic.acos_stages(a) {
        Some(s) => format!(
            "{:08x} 1 {:08x} {} {} {} {:08x}",
            a.to_bits(),
            s.root.to_bits(),
            code.of(s.vector.x_code),
            code.of(s.vector.y_code),
            code.of(s.vector.z_code),
            s.vector.out.to_bits()
        ),
        None => format!(
            "{:08x} 0 00000000 {z} {z} {z} {NAN_BITS:08x}",
            a.to_bits(),
            z = code.of(0)
        ),
    }
}

/// Both signs of each value.
fn signed(values: impl IntoIterator<Item = u32>) -> Vec<u32> {
    values
        .into_iter()
        .flat_map(|b| [b, b ^ 0x8000_0000])
        .collect()
}

/// `b` and its `r` neighbours on each side (positive bit patterns).
fn around(b: u32, r: u32) -> impl Iterator<Item = u32> {
    b.saturating_sub(r)..=b.saturating_add(r)
}

fn sincos_inputs(k: &RtlConstants, count: usize, rng: &mut SplitMix) -> Vec<u32> {
    let frac = k.config.frac as i32;
    let lsb = 2f32.powi(-frac);
    // The fold thresholds: the angles whose codes are Q(pi/2) and its neighbours.
    let fold = (-2..=2).map(|d| ((k.half_pi + d) as f32 * lsb).to_bits());
    let mut edges = signed(
        [0, 1, 0x0080_0000, 1e-30f32.to_bits(), 1.0f32.to_bits()]
            .into_iter()
            .chain(around((PI / 2.0).to_bits(), 2))
            .chain(fold)
            .chain(around(k.pi_up, 3))
            .chain(around((2.0 * PI).to_bits(), 2))
            .chain(around(k.three_pi_up - 1, 2))
            .chain([
                10.0f32.to_bits(),
                1e6f32.to_bits(),
                0x7f80_0000,
                0x7fc0_0000,
            ]),
    );
    let limit = f32::from_bits(k.three_pi_up - 1);
    let half = count / 2;
    edges.extend(
        (0..half).map(|i| (-limit + 2.0 * limit * (i as f32 + 0.5) / half as f32).to_bits()),
    );
    edges.extend((half..count).map(|i| {
        if i % 2 == 0 {
            (rng.unit() as f32 * 2.0 * limit - limit).to_bits()
        } else {
            // Any bit pattern below the limit: every exponent, subnormals included.
            let b = rng.next() as u32;
            let mag = (b & 0x7fff_ffff) % k.three_pi_up;
            mag | (b & 0x8000_0000)
        }
    }));
    edges
}

fn atan2_inputs(count: usize, rng: &mut SplitMix) -> Vec<(u32, u32)> {
    // The axes, the infinities, NaN, the smallest and largest magnitudes, both signs.
    let special = signed([
        0,
        1,
        0x0080_0000,
        1e-38f32.to_bits(),
        0.5f32.to_bits(),
        1.0f32.to_bits(),
        f32::MAX.to_bits(),
        0x7f80_0000,
        0x7fc0_0000,
    ]);
    let mut v: Vec<(u32, u32)> = special
        .iter()
        .flat_map(|&y| special.iter().map(move |&x| (y, x)))
        .collect();
    let half = count / 2;
    v.extend((0..half).map(|i| {
        let t = -PI + 2.0 * PI * (i as f32 + 0.5) / half as f32;
        (t.sin().to_bits(), t.cos().to_bits())
    }));
    v.extend((half..count).map(|i| {
        if i % 2 == 0 {
            // A uniform direction at a log-uniform radius over the finite range.
            let t = (rng.unit() * std::f64::consts::TAU - std::f64::consts::PI) as f32;
            let r = 2f32.powf((rng.unit() * 270.0 - 145.0) as f32);
            ((r * t.sin()).to_bits(), (r * t.cos()).to_bits())
        } else {
            let b = rng.next();
            ((b >> 32) as u32, b as u32)
        }
    }));
    v
}

fn acos_inputs(count: usize, rng: &mut SplitMix) -> Vec<u32> {
    let one = 1.0f32.to_bits();
    let mut v = signed(
        [
            0,
            1,
            0x0080_0000,
            0.5f32.to_bits(),
            2.0f32.to_bits(),
            0x7f80_0000,
            0x7fc0_0000,
        ]
        .into_iter()
        .chain(around(one, 3))
        .chain(
            [-24, -25, -26]
                .into_iter()
                .flat_map(|e| around(2f32.powi(e).to_bits(), 1)),
        ),
    );
    let half = count / 2;
    v.extend((0..half).map(|i| (-1.0 + 2.0 * (i as f32 + 0.5) / half as f32).to_bits()));
    v.extend((half..count).map(|i| {
        if i % 2 == 0 {
            (rng.unit() as f32 * 2.0 - 1.0).to_bits()
        } else {
            rng.next() as u32
        }
    }));
    v
}

/// SplitMix64: a seeded stream, the same on every platform.
pub(super) struct SplitMix(pub(super) u64);

impl SplitMix {
    pub(super) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub(super) fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}
