//! The paper's five hardware modules as generic kernels.
//!
//! Each kernel follows the paper's equations literally (section "PHANToM Omni Device
//! Model"), with the erratum in `r` corrected. They are generic over the scalar `R` and
//! the trigonometric block `T`, so the same source is the f64 reference, the f32
//! software model and the hybrid FPGA model (see [`crate::arith`]).
//!
//! Batch versions take structure-of-arrays slices and run the trigonometric block over
//! a whole chunk before the multiply-adds, so the arithmetic loops vectorise.

use crate::arith::{Real, Trig};
use crate::geometry::Lengths;

/// Forward kinematics (FK-HMD, FK-HSD): joint angles in radians to tool xyz in metres.
///
/// x = -sin t1 (L2 sin t3 + L1 cos t2);  y = -L2 cos t3 + L1 sin t2 + L3;
/// z = L2 cos t1 sin t3 + L1 cos t1 cos t2 - L4.
#[inline(always)]
pub fn fk<R: Real, T: Trig<R>>(g: &Lengths<R>, trig: &T, theta: [R; 3]) -> [R; 3] {
    let ([s1, s2, s3], [c1, c2, c3]) = trig.sin_cos3(theta);
    fk_from_trig(g, s1, c1, s2, c2, s3, c3)
}

#[inline(always)]
fn fk_from_trig<R: Real>(g: &Lengths<R>, s1: R, c1: R, s2: R, c2: R, s3: R, c3: R) -> [R; 3] {
    let x = -(s1 * (g.l2 * s3 + g.l1 * c2));
    let y = -(g.l2 * c3) + g.l1 * s2 + g.l3;
    let z = g.l2 * c1 * s3 + g.l1 * c1 * c2 - g.l4;
    [x, y, z]
}

/// The Jacobian of [`fk`], `J[i][j] = d pos_i / d theta_j`, as the paper's JM block.
#[inline(always)]
pub fn jacobian<R: Real, T: Trig<R>>(g: &Lengths<R>, trig: &T, theta: [R; 3]) -> [[R; 3]; 3] {
    let ([s1, s2, s3], [c1, c2, c3]) = trig.sin_cos3(theta);
    jacobian_from_trig(g, s1, c1, s2, c2, s3, c3)
}

#[inline(always)]
fn jacobian_from_trig<R: Real>(
    g: &Lengths<R>,
    s1: R,
    c1: R,
    s2: R,
    c2: R,
    s3: R,
    c3: R,
) -> [[R; 3]; 3] {
    let j11 = -(c1 * (g.l2 * s3 + g.l1 * c2));
    let j21 = R::ZERO;
    let j31 = -(g.l1 * c2 * s1) - g.l2 * s3 * s1;
    let j12 = g.l1 * s1 * s2;
    let j22 = g.l1 * c2;
    let j32 = -(g.l1 * s2 * c1);
    let j13 = -(g.l2 * s1 * c3);
    let j23 = g.l2 * s3;
    let j33 = g.l2 * c3 * c1;
    [[j11, j12, j13], [j21, j22, j23], [j31, j32, j33]]
}

/// Kinesthetic feedback force (KFF-HMD): joint torques `tau = J(theta)^T F`, in N m.
#[inline(always)]
pub fn kff<R: Real, T: Trig<R>>(g: &Lengths<R>, trig: &T, theta: [R; 3], f: [R; 3]) -> [R; 3] {
    let ([s1, s2, s3], [c1, c2, c3]) = trig.sin_cos3(theta);
    kff_from_trig(g, s1, c1, s2, c2, s3, c3, f)
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn kff_from_trig<R: Real>(
    g: &Lengths<R>,
    s1: R,
    c1: R,
    s2: R,
    c2: R,
    s3: R,
    c3: R,
    f: [R; 3],
) -> [R; 3] {
    let j = jacobian_from_trig(g, s1, c1, s2, c2, s3, c3);
    [
        j[0][0] * f[0] + j[1][0] * f[1] + j[2][0] * f[2],
        j[0][1] * f[0] + j[1][1] * f[1] + j[2][1] * f[2],
        j[0][2] * f[0] + j[1][2] * f[1] + j[2][2] * f[2],
    ]
}

/// Feedback force (FBF-HSD): `F = h * (obj - env)` per axis, in N.
#[inline(always)]
pub fn fbf<R: Real>(obj: [R; 3], env: [R; 3], h: [R; 3]) -> [R; 3] {
    [
        h[0] * (obj[0] - env[0]),
        h[1] * (obj[1] - env[1]),
        h[2] * (obj[2] - env[2]),
    ]
}

/// What inverse kinematics could make of a target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IkStatus {
    /// Inside the workspace: the angles put the tool on the target.
    Reachable,
    /// Outside the workspace: the acos arguments were clamped to [-1, 1], so the angles
    /// point the arm at the target as far as it reaches.
    Clamped,
    /// The target had a NaN or infinite coordinate: the angles are all zero.
    Invalid,
}

/// Angles from [`ik`], with the status that says whether to trust them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution<R> {
    /// Joint angles in radians; always finite.
    pub theta: [R; 3],
    /// Whether the target was reachable.
    pub status: IkStatus,
}

impl<R> IkSolution<R> {
    /// True only for [`IkStatus::Reachable`].
    pub fn reachable(&self) -> bool {
        self.status == IkStatus::Reachable
    }
}

/// The constants of [`ik`], each computed in `R` from the lengths exactly as the kernel
/// always has (left to right): the RTL's `kin_params.vh` takes them from here, so the
/// hardware and the model cannot disagree on a rounding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkConstants<R> {
    /// `L1 L1 - L2 L2`, the numerator's constant of cos gamma.
    pub c_gamma: R,
    /// `2 L1`, the denominator's factor of cos gamma (times r).
    pub two_l1: R,
    /// `L1 L1 + L2 L2`, the numerator's constant of cos alpha.
    pub c_alpha: R,
    /// `2 L1 L2`, the denominator of cos alpha.
    pub d_alpha: R,
    /// Twice the reach `L1 + L2`: where a far target is pulled in to.
    pub reach2: R,
    /// Four times the reach: beyond it a target is pulled in.
    pub reach4: R,
    /// `1 + 16 eps`: an acos argument beyond it (either sign) is a clamp, not rounding.
    pub one_tol: R,
}

impl<R: Real> IkConstants<R> {
    /// The constants for `g`.
    #[inline(always)]
    pub fn of(g: &Lengths<R>) -> Self {
        let two = R::ONE + R::ONE;
        let reach = g.l1 + g.l2;
        IkConstants {
            c_gamma: g.l1 * g.l1 - g.l2 * g.l2,
            two_l1: two * g.l1,
            c_alpha: g.l1 * g.l1 + g.l2 * g.l2,
            d_alpha: two * g.l1 * g.l2,
            reach2: reach + reach,
            reach4: reach + reach + reach + reach,
            one_tol: R::ONE + R::from_f64(16.0) * R::EPSILON,
        }
    }
}

/// Clamps an acos argument into [-1, 1]. Overshoots of a few ulps are rounding at the
/// workspace boundary (a fully stretched arm), not an unreachable target.
#[inline(always)]
fn clamp_unit<R: Real>(a: R, one_tol: R, clamped: &mut bool) -> R {
    if a > R::ONE {
        *clamped |= a > one_tol;
        R::ONE
    } else if a < -R::ONE {
        *clamped |= a < -one_tol;
        -R::ONE
    } else if a.is_finite() {
        a
    } else {
        // NaN: no acos argument can be trusted; flag it and take the stretched arm.
        *clamped = true;
        R::ONE
    }
}

/// Every value [`ik`] computes on its way, as the RTL's IK-HSD has them at its stage
/// boundaries (the co-simulation compares each). Meaningful unless the status is
/// [`IkStatus::Invalid`], where only the (zero) angles are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkTaps<R> {
    /// x, y - L3 and z + L4, after pulling a far target in.
    pub shoulder: [R; 3],
    /// atan2(x, z + L4), before its negation into theta1.
    pub atan: R,
    /// x^2 + (z + L4)^2.
    pub rr2: R,
    /// Its square root, R.
    pub big_r: R,
    /// r^2 = R^2 + (y - L3)^2.
    pub r2: R,
    /// r.
    pub r: R,
    /// cos gamma as the acos takes it (clamped).
    pub cos_gamma: R,
    /// gamma.
    pub gamma: R,
    /// beta = atan2(y - L3, R).
    pub beta: R,
    /// cos alpha as the acos takes it (clamped).
    pub cos_alpha: R,
    /// alpha.
    pub alpha: R,
    /// The result.
    pub solution: IkSolution<R>,
}

/// Inverse kinematics (IK-HSD): tool xyz in metres to joint angles, elbow-up branch.
///
/// theta1 = -atan2(x, z + L4); R = sqrt(x^2 + (z + L4)^2);
/// r = sqrt(x^2 + (z + L4)^2 + (y - L3)^2) (the paper's printed r misses a parenthesis);
/// gamma = acos((L1^2 - L2^2 + r^2) / (2 L1 r)); beta = atan2(y - L3, R);
/// alpha = acos((L1^2 + L2^2 - r^2) / (2 L1 L2)); theta2 = gamma + beta;
/// theta3 = theta2 + alpha - pi/2.
///
/// Never returns NaN: a target outside the workspace is clamped and flagged
/// [`IkStatus::Clamped`]; a non-finite target gives zeros flagged [`IkStatus::Invalid`].
#[inline(always)]
pub fn ik<R: Real, T: Trig<R>>(g: &Lengths<R>, trig: &T, p: [R; 3]) -> IkSolution<R> {
    ik_taps(g, trig, p).solution
}

/// [`ik`] with every intermediate value ([`IkTaps`]); `ik` is this, so the two cannot
/// differ.
#[inline(always)]
pub fn ik_taps<R: Real, T: Trig<R>>(g: &Lengths<R>, trig: &T, p: [R; 3]) -> IkTaps<R> {
    let [x, y, z] = p;
    if !(x.is_finite() && y.is_finite() && z.is_finite()) {
        let z = R::ZERO;
        return IkTaps {
            shoulder: [z; 3],
            atan: z,
            rr2: z,
            big_r: z,
            r2: z,
            r: z,
            cos_gamma: z,
            gamma: z,
            beta: z,
            cos_alpha: z,
            alpha: z,
            solution: IkSolution {
                theta: [z; 3],
                status: IkStatus::Invalid,
            },
        };
    }
    let k = IkConstants::of(g);
    let (mut x, mut yl, mut zl) = (x, y - g.l3, z + g.l4);
    let mut clamped = false;
    // A target far beyond reach, possibly so far that squaring it overflows, is pulled
    // in along the same direction from the shoulder to twice the reach: the clamped
    // angles are the same and every intermediate stays finite.
    let far = x.abs().max_of(yl.abs()).max_of(zl.abs());
    if far > k.reach4 {
        let s = k.reach2 / far;
        (x, yl, zl) = (x * s, yl * s, zl * s);
        clamped = true;
    }
    let rr2 = x * x + zl * zl;
    let big_r = rr2.sqrt();
    let r2 = rr2 + yl * yl;
    let r = r2.sqrt();
    // At r = 0 (target on the shoulder joint) gamma is undefined; with L1 = L2 it is the
    // boundary of the workspace, otherwise outside it. Treat it as the limit r -> 0+.
    let cos_gamma = if r > R::ZERO {
        (k.c_gamma + r2) / (k.two_l1 * r)
    } else {
        clamped |= g.l1 != g.l2;
        R::ZERO
    };
    let cos_gamma = clamp_unit(cos_gamma, k.one_tol, &mut clamped);
    let cos_alpha = clamp_unit((k.c_alpha - r2) / k.d_alpha, k.one_tol, &mut clamped);
    // The four angles depend on none of one another: one call, so the CORDIC model can
    // run them side by side.
    let [atan, gamma, beta, alpha] = trig.ik_angles((x, zl), cos_gamma, (yl, big_r), cos_alpha);
    let theta2 = gamma + beta;
    let theta3 = theta2 + alpha - R::FRAC_PI_2;
    IkTaps {
        shoulder: [x, yl, zl],
        atan,
        rr2,
        big_r,
        r2,
        r,
        cos_gamma,
        gamma,
        beta,
        cos_alpha,
        alpha,
        solution: IkSolution {
            theta: [-atan, theta2, theta3],
            status: if clamped {
                IkStatus::Clamped
            } else {
                IkStatus::Reachable
            },
        },
    }
}

/// Chunk length of the batch kernels: the trigonometric scratch stays in L1 cache.
const CHUNK: usize = 256;

/// Structure-of-arrays view of three equally long columns.
#[derive(Debug)]
pub struct Columns<'a, R> {
    /// First column (theta1 or x).
    pub a: &'a [R],
    /// Second column.
    pub b: &'a [R],
    /// Third column.
    pub c: &'a [R],
}

/// Mutable structure-of-arrays output.
#[derive(Debug)]
pub struct ColumnsMut<'a, R> {
    /// First column.
    pub a: &'a mut [R],
    /// Second column.
    pub b: &'a mut [R],
    /// Third column.
    pub c: &'a mut [R],
}

/// Batch [`fk`]: the same results as the scalar kernel, element by element.
///
/// # Panics
/// If the six slices do not all have the same length.
pub fn fk_batch<R: Real, T: Trig<R>>(
    g: &Lengths<R>,
    trig: &T,
    theta: Columns<'_, R>,
    out: ColumnsMut<'_, R>,
) {
    let n = theta.a.len();
    assert!(
        [
            theta.b.len(),
            theta.c.len(),
            out.a.len(),
            out.b.len(),
            out.c.len()
        ]
        .iter()
        .all(|&l| l == n),
        "fk_batch: column lengths differ"
    );
    let mut sc = [[R::ZERO; CHUNK]; 6];
    let mut start = 0;
    while start < n {
        let len = CHUNK.min(n - start);
        let range = start..start + len;
        let [s1, c1, s2, c2, s3, c3] = &mut sc;
        trig.sin_cos_batch(&theta.a[range.clone()], &mut s1[..len], &mut c1[..len]);
        trig.sin_cos_batch(&theta.b[range.clone()], &mut s2[..len], &mut c2[..len]);
        trig.sin_cos_batch(&theta.c[range.clone()], &mut s3[..len], &mut c3[..len]);
        let (xo, yo, zo) = (
            &mut out.a[range.clone()],
            &mut out.b[range.clone()],
            &mut out.c[range],
        );
        for i in 0..len {
            let [x, y, z] = fk_from_trig(g, s1[i], c1[i], s2[i], c2[i], s3[i], c3[i]);
            xo[i] = x;
            yo[i] = y;
            zo[i] = z;
        }
        start += len;
    }
}

/// Batch [`kff`]: the same results as the scalar kernel, element by element.
///
/// # Panics
/// If the nine slices do not all have the same length.
pub fn kff_batch<R: Real, T: Trig<R>>(
    g: &Lengths<R>,
    trig: &T,
    theta: Columns<'_, R>,
    force: Columns<'_, R>,
    out: ColumnsMut<'_, R>,
) {
    let n = theta.a.len();
    assert!(
        [
            theta.b.len(),
            theta.c.len(),
            force.a.len(),
            force.b.len(),
            force.c.len(),
            out.a.len(),
            out.b.len(),
            out.c.len()
        ]
        .iter()
        .all(|&l| l == n),
        "kff_batch: column lengths differ"
    );
    let mut sc = [[R::ZERO; CHUNK]; 6];
    let mut start = 0;
    while start < n {
        let len = CHUNK.min(n - start);
        let range = start..start + len;
        let [s1, c1, s2, c2, s3, c3] = &mut sc;
        trig.sin_cos_batch(&theta.a[range.clone()], &mut s1[..len], &mut c1[..len]);
        trig.sin_cos_batch(&theta.b[range.clone()], &mut s2[..len], &mut c2[..len]);
        trig.sin_cos_batch(&theta.c[range.clone()], &mut s3[..len], &mut c3[..len]);
        let (fx, fy, fz) = (
            &force.a[range.clone()],
            &force.b[range.clone()],
            &force.c[range.clone()],
        );
        let (t1, t2, t3) = (
            &mut out.a[range.clone()],
            &mut out.b[range.clone()],
            &mut out.c[range],
        );
        for i in 0..len {
            let tau = kff_from_trig(
                g,
                s1[i],
                c1[i],
                s2[i],
                c2[i],
                s3[i],
                c3[i],
                [fx[i], fy[i], fz[i]],
            );
            t1[i] = tau[0];
            t2[i] = tau[1];
            t3[i] = tau[2];
        }
        start += len;
    }
}

/// Batch [`fbf`] with one stiffness for the whole batch (one object).
///
/// # Panics
/// If the nine slices do not all have the same length.
pub fn fbf_batch<R: Real>(
    obj: Columns<'_, R>,
    env: Columns<'_, R>,
    h: [R; 3],
    out: ColumnsMut<'_, R>,
) {
    let n = obj.a.len();
    assert!(
        [
            obj.b.len(),
            obj.c.len(),
            env.a.len(),
            env.b.len(),
            env.c.len(),
            out.a.len(),
            out.b.len(),
            out.c.len()
        ]
        .iter()
        .all(|&l| l == n),
        "fbf_batch: column lengths differ"
    );
    for (o, (p, e)) in out.a.iter_mut().zip(obj.a.iter().zip(env.a)) {
        *o = h[0] * (*p - *e);
    }
    for (o, (p, e)) in out.b.iter_mut().zip(obj.b.iter().zip(env.b)) {
        *o = h[1] * (*p - *e);
    }
    for (o, (p, e)) in out.c.iter_mut().zip(obj.c.iter().zip(env.c)) {
        *o = h[2] * (*p - *e);
    }
}

/// Batch [`ik`]: angles into `out`, statuses into `status`.
///
/// # Panics
/// If the slices do not all have the same length.
pub fn ik_batch<R: Real, T: Trig<R>>(
    g: &Lengths<R>,
    trig: &T,
    pos: Columns<'_, R>,
    out: ColumnsMut<'_, R>,
    status: &mut [IkStatus],
) {
    let n = pos.a.len();
    assert!(
        [
            pos.b.len(),
            pos.c.len(),
            out.a.len(),
            out.b.len(),
            out.c.len(),
            status.len()
        ]
        .iter()
        .all(|&l| l == n),
        "ik_batch: column lengths differ"
    );
    for (i, st) in status.iter_mut().enumerate() {
        let s = ik(g, trig, [pos.a[i], pos.b[i], pos.c[i]]);
        out.a[i] = s.theta[0];
        out.b[i] = s.theta[1];
        out.c[i] = s.theta[2];
        *st = s.status;
    }
}
