//! The IK's Newton steps (see [`super`]) in a workspace made once. The arithmetic is
//! the allocating version's, operation for operation (issue 66): the task's square
//! matrices are of fixed size (3 or 6 rows: nalgebra's generic eigenvalues and
//! Cholesky, on the stack), the others are buffers of the workspace, and every
//! product goes through [`crate::matmul::mul_to`], the bits of nalgebra's `*` without
//! the allocations of `matrixmultiply`.

use super::{Ik, Pose};
use crate::matmul::mul_to;
use crate::spatial::Frame;
use crate::Chain;
use nalgebra::allocator::Allocator;
use nalgebra::{
    Cholesky, DMatrix, DVector, DefaultAllocator, DimDiff, DimName, DimSub, Matrix6xX, OMatrix,
    OVector, U1, U3, U6,
};

/// The IK's scratch memory (Pinocchio's `Data` beside its `Model`, which [`Ik`] is):
/// made once for an IK, it lets [`Ik::step_into`] run in a slave's loop without
/// allocating. Any workspace serves any IK; one made for another is remade on its
/// first call.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    /// The joints' frames in the base and the tip's Jacobian.
    frames: Vec<Frame>,
    jac: Matrix6xX<f64>,
    /// The task's rows of the Jacobian, weighted, a locked joint's column zero; its
    /// transpose.
    jw: DMatrix<f64>,
    jwt: DMatrix<f64>,
    /// The posture term's `J# = J^T (J J^T + l^2 I)^-1`, `J# J` and `N = I - J# J`.
    pinv: DMatrix<f64>,
    jp: DMatrix<f64>,
    null: DMatrix<f64>,
    /// The step, the posture's pull and its projection into the null space.
    dq: DVector<f64>,
    pull: DVector<f64>,
    pulled: DVector<f64>,
    /// The joints a limit holds in this iteration.
    locked: Vec<bool>,
    /// The call's start (the arm, clamped into its limits) and an iteration's.
    pub(super) start: Vec<f64>,
    pub(super) before: Vec<f64>,
}

impl Workspace {
    /// A workspace sized for `ik`: its first call allocates nothing either.
    pub fn new(ik: &Ik) -> Workspace {
        Workspace::sized(&ik.chain, ik.rows())
    }

    fn sized(chain: &Chain, m: usize) -> Workspace {
        let n = chain.dof();
        Workspace {
            frames: Vec::with_capacity(chain.joints.len()),
            jac: Matrix6xX::zeros(n),
            jw: DMatrix::zeros(m, n),
            jwt: DMatrix::zeros(n, m),
            pinv: DMatrix::zeros(n, m),
            jp: DMatrix::zeros(n, n),
            null: DMatrix::zeros(n, n),
            dq: DVector::zeros(n),
            pull: DVector::zeros(n),
            pulled: DVector::zeros(n),
            locked: vec![false; n],
            start: vec![0.0; n],
            before: vec![0.0; n],
        }
    }

    /// Remade for `ik` unless it fits it already.
    pub(super) fn fit(&mut self, ik: &Ik) {
        if self.jw.shape() != (ik.rows(), ik.chain.dof()) {
            *self = Workspace::new(ik);
        }
    }
}

impl Ik {
    /// One Newton iteration from `q` that respects the joint limits: a joint the step
    /// would carry past a limit is put at the limit and held, and the step is solved
    /// again for the others (the clamping loop of Baerlocher and Boulic 2004), so the
    /// solution slides along the limits instead of fighting them. Returns the damping
    /// used, whether a limit was met, whether `q` already met the target, or `None`
    /// when the step was not finite.
    pub(super) fn iterate(
        &self,
        ws: &mut Workspace,
        q: &mut [f64],
        target: &Pose,
        posture: bool,
    ) -> Option<(f64, bool, bool)> {
        ws.locked.iter_mut().for_each(|l| *l = false);
        let mut clamped = false;
        for _ in 0..=q.len() {
            let (lambda, converged) = match self.config.position_only {
                true => self.newton::<U3>(ws, q, target, posture),
                false => self.newton::<U6>(ws, q, target, posture),
            };
            if converged || ws.dq.iter().any(|d| !d.is_finite()) {
                return converged.then_some((0.0, clamped, true));
            }
            let mut met = false;
            for (k, d) in self.chain.dofs.iter().enumerate() {
                let x = q[k] + ws.dq[k];
                if !ws.locked[k] && (x < d.lower || x > d.upper) {
                    q[k] = x.clamp(d.lower, d.upper);
                    ws.locked[k] = true;
                    met = true;
                }
            }
            clamped |= met;
            if !met {
                for (x, d) in q.iter_mut().zip(ws.dq.iter()) {
                    *x += d;
                }
                return Some((lambda, clamped, false));
            }
        }
        Some((self.config.damping_max, clamped, false))
    }

    /// One Newton step from `q` toward `target` with the workspace's locked joints
    /// held, into `ws.dq`: the damped step, plus the posture term when `posture` (once
    /// a call). `D` is the task's rows. Returns the damping used and whether `q`
    /// already meets the target.
    fn newton<D>(&self, ws: &mut Workspace, q: &[f64], target: &Pose, posture: bool) -> (f64, bool)
    where
        D: DimName + DimSub<U1>,
        DefaultAllocator: Allocator<D, D> + Allocator<D> + Allocator<DimDiff<D, U1>>,
    {
        let tip = self.chain.jacobian_with(q, &mut ws.jac, &mut ws.frames);
        let (ep, er, e) = self.error(&tip, target);
        if ep < self.config.tolerance_m && er < self.config.tolerance_rad && !posture {
            ws.dq.fill(0.0);
            return (0.0, true);
        }
        let (m, n, w) = (D::dim(), q.len(), self.config.orientation_weight);
        for k in 0..n {
            for i in 0..m {
                let weight = if i >= 3 { w } else { 1.0 };
                ws.jw[(i, k)] = match ws.locked[k] {
                    true => 0.0,
                    false => ws.jac[(i, k)] * weight,
                };
            }
        }
        ws.jw.transpose_to(&mut ws.jwt);
        let mut a = OMatrix::<f64, D, D>::zeros();
        mul_to(&ws.jw, &ws.jwt, &mut a);
        let smallest = a.symmetric_eigenvalues().min().max(0.0).sqrt();
        let eps = self.config.singular_threshold;
        let lambda2 = if smallest < eps {
            (1.0 - (smallest / eps).powi(2)) * self.config.damping_max.powi(2)
        } else {
            0.0
        };
        // A + l^2 I, as `a + DMatrix::identity(m, m) * l^2` computes it.
        let l2 = lambda2.max(1e-12);
        let damped = OMatrix::<f64, D, D>::from_fn(|i, j| a[(i, j)] + identity(i, j) * l2);
        let Some(chol) = Cholesky::new(damped) else {
            ws.dq.fill(0.0);
            return (self.config.damping_max, false);
        };
        let mut solved = OVector::<f64, D>::from_fn(|i, _| e[i]);
        chol.solve_mut(&mut solved);
        mul_to(&ws.jwt, &solved, &mut ws.dq);
        if posture && n > m && self.config.posture_gain > 0.0 {
            self.posture_term(ws, &chol, q);
        }
        (lambda2.sqrt(), false)
    }

    /// The pull toward the rest posture in the task's null space, added to `ws.dq`:
    /// `N = I - J# J`, `J# = J^T (J J^T + l^2 I)^-1`.
    fn posture_term<D>(&self, ws: &mut Workspace, chol: &Cholesky<f64, D>, q: &[f64])
    where
        D: DimName,
        DefaultAllocator: Allocator<D, D>,
    {
        let n = q.len();
        let mut inverse = OMatrix::<f64, D, D>::identity();
        chol.solve_mut(&mut inverse);
        mul_to(&ws.jwt, &inverse, &mut ws.pinv);
        mul_to(&ws.pinv, &ws.jw, &mut ws.jp);
        for j in 0..n {
            for i in 0..n {
                ws.null[(i, j)] = identity(i, j) - ws.jp[(i, j)];
            }
        }
        for (k, x) in q.iter().enumerate() {
            ws.pull[k] = match ws.locked[k] {
                true => 0.0,
                false => self.config.posture_gain * (self.posture[k] - x),
            };
        }
        mul_to(&ws.null, &ws.pull, &mut ws.pulled);
        ws.dq += &ws.pulled;
    }
}

/// The identity's entry `(i, j)`.
fn identity(i: usize, j: usize) -> f64 {
    if i == j {
        1.0
    } else {
        0.0
    }
}
