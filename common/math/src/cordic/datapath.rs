//! The integer datapath: F2FP range reduction, quadrant fold, rotation and
//! vectoring iterations, each register a V-bit integer.

use super::*;

impl Cordic {
    /// Fast-path range reduction (`|a| <= FAST_REDUCE_LIMIT`) and the F2FP scaling:
    /// `r 2^N` plus the rounding addend, whose floor is the angle code.
    #[inline(always)]
    pub(super) fn angle_prefloor(&self, a: f64) -> f64 {
        let k = (a * (1.0 / TAU) + ROUND_MAGIC) - ROUND_MAGIC;
        let r = (a - k * TAU_HI) - k * TAU_LO;
        r * self.angle_scale + self.half
    }

    /// Quadrant fold by comparator masks (no data-dependent branch, and no
    /// intermediate sum that could leave the V-bit range): `(z', flip)`, `flip = -1`
    /// when the outputs must be negated.
    #[inline(always)]
    pub(super) fn fold(&self, z: i64) -> (i64, i64) {
        let up = -i64::from(z > self.half_pi);
        let down = -i64::from(z < -self.half_pi);
        (z - (self.pi & up) + (self.pi & down), up | down)
    }

    /// Rotation-mode iterations and output stage; returns x/y codes `(sin, cos)`.
    ///
    /// Unrolled so every shift count is an immediate. The x/y registers carry the
    /// rounding addend `b_i` of the coming shift (a constant adder off the critical
    /// path), so a step is shift, xor, add: the same integers as
    /// `x_{i+1} = x_i - d_i ((y_i + b_i) >> i)`, the form the batch code uses.
    #[allow(unused_assignments)] // the last unrolled step's z is not read
    pub(super) fn rotate(&self, z: i64, flip: i64) -> (i64, i64) {
        let (n, t) = (self.n, &self.atan);
        let (mut x, mut y, mut z) = (self.gain, 0i64, z);
        macro_rules! steps {
            ($($i:literal)*) => {'run: {$(
                if n == $i {
                    break 'run;
                }
                let m = z >> 63; // -1: z < 0, rotate clockwise
                let db = self.dbias[$i];
                let (xs, ys) = (x >> $i, y >> $i);
                // (v ^ m) - m is v or -v: the conditional negation of each adder.
                x = (x + db + m) - (ys ^ m);
                y = (y + db - m) + (xs ^ m);
                z -= if z < 0 { -t[$i] } else { t[$i] };
            )*}};
        }
        steps!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31);
        let bn = self.bias[n];
        let one = self.one_xy;
        let s = (((y - bn) ^ flip) - flip).clamp(-one, one);
        let c = (((x - bn) ^ flip) - flip).clamp(-one, one);
        (s, c)
    }

    /// [`Self::rotate`] on three angles at once. The three dependency chains are
    /// independent, so interleaving them lets the core overlap their latencies (the
    /// FPGA computes the three in parallel TFBs). Same integers, lane by lane.
    #[allow(unused_assignments)] // the last unrolled step's z is not read
    pub(super) fn rotate3(&self, z: [i64; 3], flip: [i64; 3]) -> ([i64; 3], [i64; 3]) {
        let (n, t) = (self.n, &self.atan);
        let (mut x, mut y, mut z) = ([self.gain; 3], [0i64; 3], z);
        macro_rules! steps {
            ($($i:literal)*) => {'run: {$(
                if n == $i {
                    break 'run;
                }
                let db = self.dbias[$i];
                for k in 0..3 {
                    let m = z[k] >> 63;
                    let (xs, ys) = (x[k] >> $i, y[k] >> $i);
                    x[k] = (x[k] + db + m) - (ys ^ m);
                    y[k] = (y[k] + db - m) + (xs ^ m);
                    z[k] -= if z[k] < 0 { -t[$i] } else { t[$i] };
                }
            )*}};
        }
        steps!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31);
        let bn = self.bias[n];
        let one = self.one_xy;
        let mut s = [0i64; 3];
        let mut c = [0i64; 3];
        for k in 0..3 {
            s[k] = (((y[k] - bn) ^ flip[k]) - flip[k]).clamp(-one, one);
            c[k] = (((x[k] - bn) ^ flip[k]) - flip[k]).clamp(-one, one);
        }
        (s, c)
    }

    /// Scaling and F2FP of a vectoring input (after [`sanitize`]): `x 2^(N-e)` and
    /// `y 2^(N-e)` plus the rounding addend, with `e` chosen so that
    /// `max(|x|, |y|) 2^-e` is in `[0.5, 1)` (the f64 exponent field is `e + 1022`; the
    /// `max(..)` keeps the scale finite for `(0, 0)`, whose output is forced to 0).
    #[inline(always)]
    pub(super) fn vector_prefloor(&self, y: f32, x: f32) -> (f64, f64) {
        let (xd, yd) = (f64::from(x), f64::from(y));
        let biased = ((xd.abs().max(yd.abs()).to_bits() >> 52) as i32).max(1023 - 149);
        let scale = f64::from_bits(((2045 + self.cfg.frac as i32 - biased) as u64) << 52);
        (xd * scale + self.half, yd * scale + self.half)
    }

    /// Half-plane fold: negate both codes when x < 0 and start z at `+-pi` by the sign
    /// bit of y. Returns `(x, y, z0)` with `x >= 0`.
    #[inline(always)]
    pub(super) fn half_plane(&self, x: i64, y: i64, y_negative: bool) -> (i64, i64, i64) {
        let neg = x >> 63;
        let z0 = neg & if y_negative { -self.pi } else { self.pi };
        ((x ^ neg) - neg, (y ^ neg) - neg, z0)
    }

    /// Vectoring iterations and output stage; returns the angle code. Unrolled like
    /// [`Self::rotate`]; the decision is the sign of y.
    #[inline(always)]
    pub(super) fn vector(&self, x: i64, y: i64, z0: i64) -> i64 {
        self.vector_lanes([(x, y, z0)])[0]
    }

    /// [`Self::vector`] on `L` independent inputs `(x, y, z0)` at once, lane by lane the
    /// same integers: interleaving the dependency chains (each step waits for the sign
    /// of the step before) lets the core overlap their latencies, as [`Self::rotate3`]
    /// does for rotations. IK-HSD's four angles are four lanes.
    #[allow(unused_assignments)] // the last unrolled step's x and y are not read
    #[inline(always)]
    pub(super) fn vector_lanes<const L: usize>(&self, lanes: [(i64, i64, i64); L]) -> [i64; L] {
        let (n, t) = (self.n, &self.atan);
        let (mut x, mut y, mut z) = (lanes.map(|l| l.0), lanes.map(|l| l.1), [0i64; L]);
        macro_rules! steps {
            ($($i:literal)*) => {'run: {$(
                if n == $i {
                    break 'run;
                }
                let b = self.bias[$i];
                for k in 0..L {
                    let m = y[k] >> 63; // -1: y < 0, rotate counter-clockwise
                    let (xs, ys) = ((x[k] + b) >> $i, (y[k] + b) >> $i);
                    x[k] += (ys ^ m) - m;
                    y[k] -= (xs ^ m) - m;
                    z[k] += (t[$i] ^ m) - m;
                }
            )*}};
        }
        steps!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31);
        std::array::from_fn(|k| {
            let (x0, y0, z0) = lanes[k];
            let code = (z[k] + z0).clamp(-self.pi_floor, self.pi_floor);
            if (x0 | y0) == 0 {
                0
            } else {
                code
            }
        })
    }
}
