//! The error bounds documented on the bound accessors, evaluated for a format, and
//! the numeric check that every register fits V bits.

use super::*;

/// What every bound is built of, for one format.
struct Terms {
    frac: i32,
    /// One lsb, and half of one.
    ulp: f64,
    u: f64,
    nearest: bool,
    /// The input conversion's error, lsb.
    e_in: f64,
    /// The true atan(2^-i).
    atan_r: [f64; TABLE_LEN],
    /// The table's rounding error over the iterations, rad.
    table: f64,
    /// The error of pi in the format, rad.
    pi_err: f64,
}

impl Terms {
    fn of(c: &Cordic) -> Terms {
        let frac = c.cfg.frac as i32;
        let ulp = pow2(-frac);
        let nearest = c.cfg.rounding == Rounding::Nearest;
        let atan_r: [f64; TABLE_LEN] = std::array::from_fn(atan_pow2);
        let table: f64 = (0..c.n)
            .map(|i| (atan_r[i] - c.atan[i] as f64 * ulp).abs())
            .sum();
        Terms {
            frac,
            ulp,
            u: pow2(-frac - 1),
            nearest,
            e_in: if nearest { 0.5 } else { 1.0 },
            atan_r,
            table,
            pi_err: (c.pi as f64 * ulp - PI).abs(),
        }
    }

    /// Largest shift-rounding error of iteration i, in register lsb.
    fn e(&self, i: usize) -> f64 {
        if self.nearest {
            0.5
        } else {
            1.0 - pow2(-(i as i32))
        }
    }
}

/// The largest of |sin| + |cos| over angles up to `p`.
fn spread(p: f64) -> f64 {
    if p >= FRAC_PI_4 {
        SQRT_2
    } else {
        p.sin() + p.cos()
    }
}

impl Cordic {
    /// Evaluates the derivations documented on the three bound accessors.
    pub(super) fn derive_bounds(&self) -> [f64; 3] {
        let t = Terms::of(self);
        let (sin_cos, rounding) = self.sin_cos_bound(&t);
        let (atan2, r) = self.atan2_bound(&t);
        let rho = 3.0 * pow2(-24);
        let acos = atan2 + rho / (2.0 * (1.0 - 2.0 * rho));
        debug_assert!(
            self.registers_fit(rounding / t.u, r),
            "register bound violated"
        );
        [sin_cos, atan2, acos]
    }

    /// sin/cos, steps 1-6; also the rounding term, in rad.
    fn sin_cos_bound(&self, t: &Terms) -> (f64, f64) {
        let n = self.n;
        let (h, p) = (self.half_pi, self.pi);
        let mut b = h.max(p - h - 1).max(1);
        for &a in &self.atan[..n] {
            b = a.max((b - a).abs());
        }
        let k_n: f64 = (0..n).map(growth).product();
        let gain = (k_n * self.gain as f64 * t.u - 1.0).abs();
        let rounding: f64 = (1..n)
            .map(|i| {
                let k: f64 = (i + 1..n).map(growth).product();
                let phi: f64 = t.atan_r[i + 1..n].iter().sum();
                t.e(i) * t.u * k * spread(phi)
            })
            .sum();
        let out_sc = if t.frac + 1 > 24 { pow2(-25) } else { 0.0 };
        let bound = (t.e_in * t.ulp + t.pi_err)
            + b as f64 * t.ulp
            + t.table
            + gain
            + rounding
            + out_sc
            + SLACK;
        (bound, rounding)
    }

    /// atan2, steps 1-5, in lsb units for lengths and rad for angles; also the last
    /// residual angle bound.
    fn atan2_bound(&self, t: &Terms) -> (f64, f64) {
        let l0 = pow2(t.frac - 1);
        let eta_in = if SQRT_2 * t.e_in < l0 {
            (SQRT_2 * t.e_in / l0).asin()
        } else {
            PI
        };
        let (mut len, mut r, mut turn, mut valid) = (l0, FRAC_PI_2, 0.0, true);
        for (i, &at) in t.atan_r[..self.n].iter().enumerate() {
            let a_i = at.max((r - at).abs());
            let grown = growth(i) * len;
            let (d, eta) = if i == 0 {
                (0.0, 0.0) // a shift by 0 is exact
            } else {
                let d = SQRT_2 * t.e(i);
                let eta = if grown > d {
                    (t.e(i) * spread(a_i) / (grown - d)).atan()
                } else {
                    PI
                };
                (d, eta)
            };
            len = grown - d;
            r = a_i + eta;
            turn += eta;
            valid &= r < FRAC_PI_2; // else x might turn negative and flip a decision
        }
        let out_at = if self.pi_floor > 1 << 24 {
            pow2(-23)
        } else {
            0.0
        };
        let bound = if valid {
            (eta_in + r + turn + t.table + t.pi_err + out_at + SLACK)
                .max(PI - self.pi_floor as f64 * t.ulp)
        } else {
            TAU // both the result and the true angle lie in [-pi, pi]
        };
        (bound, r)
    }

    /// Debug check of the module-level register argument against `2^(V-1)`:
    /// x/y in both modes with their rounding-error bound and the largest rounding
    /// addend `2^N`, and the angle register (`|z| <= pi + 1` lsb before the fold,
    /// `sum a_i` while vectoring, `pi + residual` at the end).
    pub(super) fn registers_fit(&self, xy_rounding_lsb: f64, vec_residual: f64) -> bool {
        let limit = pow2(self.cfg.word as i32 - 1);
        let scale = pow2(self.cfg.frac as i32);
        let k = 1.646_760_3;
        let xy_rot = self.gain as f64 * k + xy_rounding_lsb + 1.0;
        let xy_vec = scale * SQRT_2 * k + self.n as f64 * SQRT_2 * 1.05 + 2.0;
        let z_sum = self.atan[..self.n].iter().sum::<i64>() as f64;
        let z = ((self.pi + 1) as f64)
            .max(z_sum)
            .max((PI + vec_residual) * scale + 1.0);
        xy_rot + scale < limit && xy_vec + scale < limit && z < limit
    }
}
