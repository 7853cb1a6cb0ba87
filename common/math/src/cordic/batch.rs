//! Many angles or points at once: the same datapath in chunks of `LANES` `i32`
//! lanes, branch-free, so the compiler vectorises it; bit-identical per element.

use super::*;

impl Cordic {
    /// `sin_cos` for many angles, bit-identical per element. Structure of arrays in
    /// chunks of 16 `i32` lanes (every register fits 32 bits), the iteration loop
    /// outside and the lane loop inside with branch-free selects, so the compiler
    /// vectorises it. Angles beyond `2^22` rad or non-finite go through the scalar path.
    ///
    /// # Panics
    /// If `sin_out` or `cos_out` is not as long as `angles` (caller contract).
    pub fn sin_cos_batch(&self, angles: &[f32], sin_out: &mut [f32], cos_out: &mut [f32]) {
        assert_eq!(
            angles.len(),
            sin_out.len(),
            "sin_out length must match angles"
        );
        assert_eq!(
            angles.len(),
            cos_out.len(),
            "cos_out length must match angles"
        );
        let chunks = angles.chunks(LANES).zip(sin_out.chunks_mut(LANES));
        for ((a, s), c) in chunks.zip(cos_out.chunks_mut(LANES)) {
            self.sin_cos_chunk(a, s, c);
        }
    }

    /// `atan2` for many points, bit-identical per element (same layout as
    /// [`Self::sin_cos_batch`]).
    ///
    /// # Panics
    /// If `x` or `out` is not as long as `y` (caller contract).
    pub fn atan2_batch(&self, y: &[f32], x: &[f32], out: &mut [f32]) {
        assert_eq!(y.len(), x.len(), "x length must match y");
        assert_eq!(y.len(), out.len(), "out length must match y");
        let chunks = y.chunks(LANES).zip(x.chunks(LANES));
        for ((y, x), o) in chunks.zip(out.chunks_mut(LANES)) {
            self.atan2_chunk(y, x, o);
        }
    }

    /// One chunk of [`Self::sin_cos_batch`]: padded to `LANES`, every stage a loop of
    /// fixed length over the lanes (indexed: clearer than five-way zips).
    #[allow(clippy::needless_range_loop)]
    pub(super) fn sin_cos_chunk(&self, angles: &[f32], sin_out: &mut [f32], cos_out: &mut [f32]) {
        let (len, mut a) = (angles.len(), [0.0f32; LANES]);
        a[..len].copy_from_slice(angles);
        let (mut w, mut z, mut flip) = ([0.0f64; LANES], [0i32; LANES], [0i32; LANES]);
        for l in 0..LANES {
            // Lanes off the fast path are redone by the scalar code at the end.
            let v = if fast_path(a[l]) {
                f64::from(a[l])
            } else {
                0.0
            };
            w[l] = self.angle_prefloor(v);
        }
        let (h, p) = (self.half_pi as i32, self.pi as i32);
        for l in 0..LANES {
            let code = floor_code(w[l]);
            let (up, down) = (-i32::from(code > h), -i32::from(code < -h));
            (z[l], flip[l]) = (code - (p & up) + (p & down), up | down);
        }
        let (mut x, mut y) = ([self.gain as i32; LANES], [0i32; LANES]);
        for (i, &a) in self.atan[..self.n].iter().enumerate() {
            let (a, b) = (a as i32, self.bias[i] as i32);
            for l in 0..LANES {
                let m = z[l] >> 31; // -1: z < 0, rotate clockwise
                let (xs, ys) = ((x[l] + b) >> i, (y[l] + b) >> i);
                x[l] -= (ys ^ m) - m;
                y[l] += (xs ^ m) - m;
                z[l] -= (a ^ m) - m;
            }
        }
        let (one, mut s, mut c) = (self.one_xy as i32, [0.0f32; LANES], [0.0f32; LANES]);
        for l in 0..LANES {
            let f = flip[l];
            s[l] = ((y[l] ^ f) - f).clamp(-one, one) as f32 * self.xy_out;
            c[l] = ((x[l] ^ f) - f).clamp(-one, one) as f32 * self.xy_out;
        }
        sin_out.copy_from_slice(&s[..len]);
        cos_out.copy_from_slice(&c[..len]);
        if a.iter().fold(false, |slow, &v| slow | !fast_path(v)) {
            for l in 0..len {
                if !fast_path(a[l]) {
                    (sin_out[l], cos_out[l]) = self.sin_cos_cold(a[l]);
                }
            }
        }
    }

    /// One chunk of [`Self::atan2_batch`], laid out like [`Self::sin_cos_chunk`].
    #[allow(clippy::needless_range_loop)]
    pub(super) fn atan2_chunk(&self, y_in: &[f32], x_in: &[f32], out: &mut [f32]) {
        let (len, mut ya, mut xa) = (y_in.len(), [0.0f32; LANES], [0.0f32; LANES]);
        ya[..len].copy_from_slice(y_in);
        xa[..len].copy_from_slice(x_in);
        let (mut wx, mut wy, mut yneg) = ([0.0f64; LANES], [0.0f64; LANES], [0i32; LANES]);
        for l in 0..LANES {
            let (ys, xs) = sanitize(ya[l], xa[l]);
            (wx[l], wy[l]) = self.vector_prefloor(ys, xs);
            yneg[l] = -i32::from(ys.is_sign_negative());
        }
        let (mut x, mut y, mut z0, mut zero) =
            ([0i32; LANES], [0i32; LANES], [0i32; LANES], [0i32; LANES]);
        let p = self.pi as i32;
        for l in 0..LANES {
            let (xq, yq) = (floor_code(wx[l]), floor_code(wy[l]));
            let neg = xq >> 31;
            (x[l], y[l]) = ((xq ^ neg) - neg, (yq ^ neg) - neg);
            z0[l] = neg & ((p ^ yneg[l]) - yneg[l]);
            zero[l] = -i32::from((xq | yq) == 0);
        }
        let mut z = [0i32; LANES];
        for (i, &a) in self.atan[..self.n].iter().enumerate() {
            let (a, b) = (a as i32, self.bias[i] as i32);
            for l in 0..LANES {
                let m = y[l] >> 31; // -1: y < 0, rotate counter-clockwise
                let (xs, ys) = ((x[l] + b) >> i, (y[l] + b) >> i);
                x[l] += (ys ^ m) - m;
                y[l] -= (xs ^ m) - m;
                z[l] += (a ^ m) - m;
            }
        }
        let (pf, mut o) = (self.pi_floor as i32, [0.0f32; LANES]);
        for l in 0..LANES {
            let v = ((z[l] + z0[l]).clamp(-pf, pf) & !zero[l]) as f32 * self.angle_out;
            o[l] = if xa[l].is_nan() | ya[l].is_nan() {
                f32::NAN
            } else {
                v
            };
        }
        out.copy_from_slice(&o[..len]);
    }
}
