//! nalgebra's matrix product into a buffer, bit for bit, without allocating.
//!
//! nalgebra hands a product to `matrixmultiply` when a dynamic matrix takes part and
//! every dimension of the result and of the left factor is above 5 (a 6-row task's
//! `J J^T` for an arm of 6 joints or more, its pseudo-inverse, its null-space
//! projector), and `matrixmultiply` allocates its packing buffers on every call, even
//! through `mul_to` into a buffer made once. A real-time loop must not allocate, and a
//! trace must not change by a bit: [`mul_to`] computes what that product computes,
//! the same sums in the same order with the same roundings, and leaves the others
//! (which allocate nothing) to nalgebra's own `mul_to`.
//!
//! What `matrixmultiply` 0.3 computes (its `dgemm`, whichever microkernel, with nalgebra's
//! `alpha = 1` and `beta = 0`): each entry is a sum over `k` in order, started from zero,
//! each term added by a fused multiply-add where the kernel it selects at run time has
//! one (AVX-512, FMA with AVX2, NEON), by a product then a sum otherwise (AVX, SSE2, the
//! portable kernel). The test of this module compares the two on every shape up to 16.

use nalgebra::constraint::{
    AreMultipliable, SameNumberOfColumns, SameNumberOfRows, ShapeConstraint,
};
use nalgebra::{Dim, Dyn, Matrix, Storage, StorageMut};

/// Whether nalgebra's `a * b` for these shapes goes through `matrixmultiply`
/// (`nalgebra::base::blas_uninit::gemm_uninit`, 0.33: a `Dyn` dimension, and the
/// result's rows and columns and the left factor's rows and columns all above 5).
fn delegated(dynamic: bool, out: (usize, usize), a: (usize, usize)) -> bool {
    const SMALL_DIM: usize = 5;
    dynamic && out.0 > SMALL_DIM && out.1 > SMALL_DIM && a.0 > SMALL_DIM && a.1 > SMALL_DIM
}

/// Whether the `dgemm` microkernel `matrixmultiply` selects on this CPU fuses its
/// multiply-adds (its `dgemm_kernel::detect`: AVX-512F, or FMA with AVX2, on x86).
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
fn fused() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
        || (std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("avx2"))
}

/// See the x86 version: on AArch64 its NEON kernel fuses.
#[cfg(target_arch = "aarch64")]
fn fused() -> bool {
    std::arch::is_aarch64_feature_detected!("neon")
}

/// See the x86 version: elsewhere its portable kernel does not fuse.
#[cfg(not(any(target_arch = "x86", target_arch = "x86_64", target_arch = "aarch64")))]
fn fused() -> bool {
    false
}

/// `out = a * b`, the bits of nalgebra's `a * b` (and of its `a.mul_to(b, out)`), with
/// no allocation whatever the shapes.
///
/// # Panics
///
/// When the shapes do not fit, as nalgebra's `mul_to` does.
pub fn mul_to<R1, C1, R2, C2, R3, C3, SA, SB, SC>(
    a: &Matrix<f64, R1, C1, SA>,
    b: &Matrix<f64, R2, C2, SB>,
    out: &mut Matrix<f64, R3, C3, SC>,
) where
    R1: Dim,
    C1: Dim,
    R2: Dim,
    C2: Dim,
    R3: Dim,
    C3: Dim,
    SA: Storage<f64, R1, C1>,
    SB: Storage<f64, R2, C2>,
    SC: StorageMut<f64, R3, C3>,
    ShapeConstraint:
        SameNumberOfRows<R3, R1> + SameNumberOfColumns<C3, C2> + AreMultipliable<R1, C1, R2, C2>,
{
    let dynamic = R1::is::<Dyn>()
        || C1::is::<Dyn>()
        || R2::is::<Dyn>()
        || C2::is::<Dyn>()
        || R3::is::<Dyn>()
        || C3::is::<Dyn>();
    if !delegated(dynamic, out.shape(), a.shape()) {
        a.mul_to(b, out);
        return;
    }
    let (m, k) = a.shape();
    let n = b.ncols();
    assert!(
        b.nrows() == k && out.shape() == (m, n),
        "mul_to: {m}x{k} times {}x{n} into {:?}",
        b.nrows(),
        out.shape()
    );
    let shape = (m, k, n);
    let (x, y) = (|i, l| a[(i, l)], |l, j| b[(l, j)]);
    let mut put = |i, j, v| out[(i, j)] = v;
    match fused() {
        true => fused_sums(shape, x, y, &mut put),
        false => sums::<false>(shape, x, y, &mut put),
    }
}

/// Rows of the result summed side by side.
const ROWS: usize = 8;

/// Each entry of the `m x n` product of `a` (`m x k`) and `b` (`k x n`) into `put`: a
/// sum over `k` in order from zero, each term added by a fused multiply-add when
/// `FUSED`. Eight rows side by side: eight independent chains of multiply-adds instead
/// of one (the order within each sum is what counts).
#[inline(always)]
fn sums<const FUSED: bool>(
    (m, k, n): (usize, usize, usize),
    a: impl Fn(usize, usize) -> f64,
    b: impl Fn(usize, usize) -> f64,
    put: &mut impl FnMut(usize, usize, f64),
) {
    for j in 0..n {
        for top in (0..m).step_by(ROWS) {
            let rows = (m - top).min(ROWS);
            let mut acc = [0.0f64; ROWS];
            for l in 0..k {
                let y = b(l, j);
                for (r, sum) in acc.iter_mut().enumerate().take(rows) {
                    let x = a(top + r, l);
                    *sum = if FUSED {
                        x.mul_add(y, *sum)
                    } else {
                        *sum + x * y
                    };
                }
            }
            for (r, sum) in acc.iter().enumerate().take(rows) {
                put(top + r, j, *sum);
            }
        }
    }
}

/// [`sums`] fused. An x86 build's baseline has no FMA instruction, so `f64::mul_add`
/// is a call to libm's `fma` per term there: where the CPU has the instruction, the
/// sums are compiled for it (`cargo bench -p tactile-chain --bench ik_ratio`: the
/// Panda's IK call took 1.08 times the IK as it was with libm's calls, 0.82 with the
/// instruction).
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[allow(unsafe_code)]
fn fused_sums(
    shape: (usize, usize, usize),
    a: impl Fn(usize, usize) -> f64,
    b: impl Fn(usize, usize) -> f64,
    put: &mut impl FnMut(usize, usize, f64),
) {
    if std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: `with_fma` asks only that the CPU have the FMA instructions, and it
        // has them (detected just above).
        unsafe { with_fma(shape, a, b, put) }
    } else {
        sums::<true>(shape, a, b, put)
    }
}

/// [`sums`] fused, compiled for the FMA instructions.
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[allow(unsafe_code)]
#[target_feature(enable = "fma")]
unsafe fn with_fma(
    shape: (usize, usize, usize),
    a: impl Fn(usize, usize) -> f64,
    b: impl Fn(usize, usize) -> f64,
    put: &mut impl FnMut(usize, usize, f64),
) {
    sums::<true>(shape, a, b, put)
}

/// [`sums`] fused: elsewhere (AArch64) the build's baseline has the instruction.
#[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
fn fused_sums(
    shape: (usize, usize, usize),
    a: impl Fn(usize, usize) -> f64,
    b: impl Fn(usize, usize) -> f64,
    put: &mut impl FnMut(usize, usize, f64),
) {
    sums::<true>(shape, a, b, put)
}

#[cfg(test)]
mod tests {
    use super::mul_to;
    use nalgebra::{DMatrix, Dyn, Matrix6, Matrix6xX, OMatrix, U6};
    use proptest::prelude::*;

    /// Entries of every magnitude and sign, zeros among them (a locked joint's column).
    fn entries(len: usize) -> impl Strategy<Value = Vec<f64>> {
        prop::collection::vec(
            prop_oneof![
                4 => -10.0f64..10.0,
                1 => Just(0.0),
                1 => Just(-0.0),
                1 => -1e-9f64..1e-9,
            ],
            len,
        )
    }

    fn bits(m: &[f64]) -> Vec<u64> {
        m.iter().map(|x| x.to_bits()).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// Every shape up to 16 (both sides of nalgebra's threshold of 5): the bits of
        /// nalgebra's `*`, which hands the big ones to `matrixmultiply`.
        #[test]
        fn the_product_is_nalgebras_bit_for_bit(
            (m, k, n, a, b) in (1usize..=16, 1usize..=16, 1usize..=16).prop_flat_map(|(m, k, n)| {
                (Just(m), Just(k), Just(n), entries(m * k), entries(k * n))
            })
        ) {
            let a = DMatrix::from_column_slice(m, k, &a);
            let b = DMatrix::from_column_slice(k, n, &b);
            let want = &a * &b;
            let mut got = DMatrix::from_element(m, n, f64::NAN);
            mul_to(&a, &b, &mut got);
            prop_assert_eq!(bits(got.as_slice()), bits(want.as_slice()));
        }

        /// The shapes the IK and the Cartesian servo take, static and dynamic mixed.
        #[test]
        fn mixed_shapes_give_nalgebras_bits(n in 1usize..=16, a in entries(6 * 16), s in entries(36)) {
            let j = Matrix6xX::from_column_slice(&a[..6 * n]);
            let jt = j.transpose();
            let s = Matrix6::from_column_slice(&s);
            let mut jjt = Matrix6::zeros();
            mul_to(&j, &jt, &mut jjt);
            prop_assert_eq!(bits(jjt.as_slice()), bits((&j * &jt).as_slice()));
            let mut pinv = OMatrix::<f64, Dyn, U6>::zeros(n);
            mul_to(&jt, &s, &mut pinv);
            prop_assert_eq!(bits(pinv.as_slice()), bits((&jt * s).as_slice()));
            let mut jp = DMatrix::zeros(n, n);
            mul_to(&pinv, &j, &mut jp);
            prop_assert_eq!(bits(jp.as_slice()), bits((&pinv * &j).as_slice()));
        }
    }
}
