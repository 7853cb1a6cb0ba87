//! The IK as it was before its workspace (issue 66), kept verbatim (but for the
//! configuration's checks, which are `Ik::new`'s) as the reference the allocation-free
//! [`tactile_chain::Ik::step_into`] must equal bit for bit: its `DMatrix` products
//! (nalgebra's, through `matrixmultiply` where they are big enough), its eigenvalues
//! and Cholesky on the heap. Its parts that did not change (the velocity limit, the
//! counters) are copies on purpose: the reference is the whole call as it was. Used by
//! the test `ik_bits` and by the bench, which times both in one run.

#![allow(dead_code)]

use nalgebra::{DMatrix, DVector, Matrix6xX, SymmetricEigen};
use tactile_chain::spatial::log_rotation;
use tactile_chain::{Chain, Error, Frame, IkConfig, IkStats, Pose};

/// The middle of a joint's limits, the default posture (0 where a limit is
/// infinite). Halved before the sum: `(lower + upper) / 2` overflows to infinity for
/// finite limits above about 9e307, which a URDF may hold.
fn midpoint(lower: f64, upper: f64) -> f64 {
    if lower.is_finite() && upper.is_finite() {
        lower / 2.0 + upper / 2.0
    } else {
        0.0
    }
}

/// What one call did.
#[derive(Debug, Clone, PartialEq)]
pub struct RefStep {
    /// The joint values to command.
    pub q: Vec<f64>,
    /// Position error left at `q`, m.
    pub position_error: f64,
    /// Orientation error left at `q`, rad (0 when only the position is followed).
    pub orientation_error: f64,
    /// Newton steps taken.
    pub iterations: usize,
    /// Whether a joint limit clamped the solution.
    pub clamped: bool,
    /// Whether the velocity limit shortened the step.
    pub velocity_limited: bool,
    /// Whether the target is out of reach (error left, and not for speed).
    pub unreachable: bool,
    /// The largest damping used, m.
    pub damping: f64,
}

/// The IK of one chain, with its counters, as it was.
#[derive(Debug, Clone)]
pub struct Reference {
    chain: Chain,
    config: IkConfig,
    posture: Vec<f64>,
    /// Counters over every call.
    pub stats: IkStats,
    jac: Matrix6xX<f64>,
}

fn bad(field: &str, problem: String) -> Error {
    Error::Field {
        at: "ik".into(),
        field: field.into(),
        problem,
    }
}

impl Reference {
    /// The IK of `chain`; the configuration checked.
    pub fn new(chain: &Chain, config: IkConfig) -> Result<Reference, Error> {
        // The configuration's checks are the IK's, unchanged: not repeated here.
        tactile_chain::Ik::new(chain, config.clone())?;
        let posture = match &config.posture {
            Some(p) => {
                chain.check_len("ik posture", p)?;
                p.clone()
            }
            None => chain
                .dofs
                .iter()
                .map(|d| midpoint(d.lower, d.upper))
                .collect(),
        };
        Ok(Reference {
            jac: Matrix6xX::zeros(chain.dof()),
            chain: chain.clone(),
            config,
            posture,
            stats: IkStats::default(),
        })
    }

    /// The chain.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The task rows followed: 6, or 3 for a position.
    fn rows(&self) -> usize {
        if self.config.position_only {
            3
        } else {
            6
        }
    }

    /// The errors left at `q`: position (m), orientation (rad), and the weighted
    /// error vector.
    fn error(&self, tip: &Frame, target: &Pose) -> (f64, f64, DVector<f64>) {
        let ep = target.p - tip.p;
        let er = log_rotation(&(target.r * tip.r.transpose()));
        let w = self.config.orientation_weight;
        let e = if self.config.position_only {
            DVector::from_column_slice(ep.as_slice())
        } else {
            DVector::from_column_slice(&[ep.x, ep.y, ep.z, w * er.x, w * er.y, w * er.z])
        };
        let rot = if self.config.position_only {
            0.0
        } else {
            er.norm()
        };
        (ep.norm(), rot, e)
    }

    /// One Newton step from `q` toward `target` with the `locked` joints held: the
    /// damped step, plus the posture term when `posture` (once a call). Returns the
    /// step, the damping used, and whether `q` already meets the target.
    fn newton(
        &mut self,
        q: &[f64],
        target: &Pose,
        posture: bool,
        locked: &[bool],
    ) -> (DVector<f64>, f64, bool) {
        let tip = self.chain.jacobian(q, &mut self.jac);
        let (ep, er, e) = self.error(&tip, target);
        if ep < self.config.tolerance_m && er < self.config.tolerance_rad && !posture {
            return (DVector::zeros(q.len()), 0.0, true);
        }
        let (m, n, w) = (self.rows(), q.len(), self.config.orientation_weight);
        let jw = DMatrix::from_fn(m, n, |i, k| {
            let weight = if i >= 3 { w } else { 1.0 };
            if locked[k] {
                0.0
            } else {
                self.jac[(i, k)] * weight
            }
        });
        let a = &jw * jw.transpose();
        let smallest = SymmetricEigen::new(a.clone())
            .eigenvalues
            .min()
            .max(0.0)
            .sqrt();
        let eps = self.config.singular_threshold;
        let lambda2 = if smallest < eps {
            (1.0 - (smallest / eps).powi(2)) * self.config.damping_max.powi(2)
        } else {
            0.0
        };
        let damped = a + DMatrix::identity(m, m) * lambda2.max(1e-12);
        let Some(chol) = damped.cholesky() else {
            return (DVector::zeros(n), self.config.damping_max, false);
        };
        let mut dq = jw.transpose() * chol.solve(&e);
        if posture && n > m && self.config.posture_gain > 0.0 {
            // N = I - J# J, J# = J^T (J J^T + l^2 I)^-1.
            let pinv = jw.transpose() * chol.solve(&DMatrix::identity(m, m));
            let null = DMatrix::identity(n, n) - pinv * &jw;
            let pull = DVector::from_fn(n, |k, _| {
                if locked[k] {
                    0.0
                } else {
                    self.config.posture_gain * (self.posture[k] - q[k])
                }
            });
            dq += null * pull;
        }
        (dq, lambda2.sqrt(), false)
    }

    /// One Newton iteration from `q` that respects the joint limits: a joint the step
    /// would carry past a limit is put at the limit and held, and the step is solved
    /// again for the others (the clamping loop of Baerlocher and Boulic 2004), so the
    /// solution slides along the limits instead of fighting them. Returns the damping
    /// used, whether a limit was met, whether `q` already met the target, or `None`
    /// when the step was not finite.
    fn iterate(
        &mut self,
        q: &mut [f64],
        target: &Pose,
        posture: bool,
    ) -> Option<(f64, bool, bool)> {
        let mut locked = vec![false; q.len()];
        let mut clamped = false;
        for _ in 0..=q.len() {
            let (dq, lambda, converged) = self.newton(q, target, posture, &locked);
            if converged || dq.iter().any(|d| !d.is_finite()) {
                return converged.then_some((0.0, clamped, true));
            }
            let mut met = false;
            for (k, d) in self.chain.dofs.iter().enumerate() {
                let x = q[k] + dq[k];
                if !locked[k] && (x < d.lower || x > d.upper) {
                    q[k] = x.clamp(d.lower, d.upper);
                    locked[k] = true;
                    met = true;
                }
            }
            clamped |= met;
            if !met {
                for (x, d) in q.iter_mut().zip(dq.iter()) {
                    *x += d;
                }
                return Some((lambda, clamped, false));
            }
        }
        Some((self.config.damping_max, clamped, false))
    }

    /// One period's command toward `target` from the arm at `q_now`, for a period of
    /// `dt` seconds.
    pub fn step(&mut self, q_now: &[f64], target: &Pose, dt: f64) -> Result<RefStep, Error> {
        self.chain.check_len("ik q", q_now)?;
        if !(dt.is_finite() && dt > 0.0) || q_now.iter().any(|x| !x.is_finite()) {
            return Err(bad(
                "step",
                "the joint values and the period must be finite".into(),
            ));
        }
        let mut start = q_now.to_vec();
        let mut clamped = self.chain.clamp(&mut start) > 0;
        let mut q = start.clone();
        let (mut iterations, mut damping) = (0, 0.0f64);
        for it in 0..self.config.max_iterations {
            let before = q.clone();
            match self.iterate(&mut q, target, it == 0) {
                Some((_, c, true)) => {
                    clamped |= c;
                    break;
                }
                Some((lambda, c, false)) => {
                    iterations += 1;
                    damping = damping.max(lambda);
                    clamped |= c;
                }
                // Nothing non-finite leaves: the arm holds where the last step left it.
                None => {
                    q = before;
                    break;
                }
            }
        }
        // Out of reach: even unhurried, the solution leaves an error and gains little
        // on where the arm stands.
        let (ep0, er0, _) = self.error(&self.chain.fk(&start), target);
        let (ep1, er1, _) = self.error(&self.chain.fk(&q), target);
        let (cm, cr) = (self.config.unreachable_m, self.config.unreachable_rad);
        let unreachable = (ep1 > cm && ep1 > 0.9 * ep0) || (er1 > cr && er1 > 0.9 * er0);
        let velocity_limited = self.limit_speed(&start, &mut q, dt);
        let (position_error, orientation_error, _) = self.error(&self.chain.fk(&q), target);
        let s = &mut self.stats;
        s.calls += 1;
        s.iterations += iterations as u64;
        s.clamped += u64::from(clamped);
        s.velocity_limited += u64::from(velocity_limited);
        s.unreachable += u64::from(unreachable);
        s.damped += u64::from(damping > 0.0);
        Ok(RefStep {
            q,
            position_error,
            orientation_error,
            iterations,
            clamped,
            velocity_limited,
            unreachable,
            damping,
        })
    }

    /// Scales the move from `start` to `q` so that no joint exceeds its velocity
    /// limit over `dt`: the same fraction for every joint, so the direction stays.
    fn limit_speed(&self, start: &[f64], q: &mut [f64], dt: f64) -> bool {
        let over = self
            .chain
            .dofs
            .iter()
            .zip(start.iter().zip(q.iter()))
            .map(|(d, (a, b))| (b - a).abs() / (d.velocity * self.config.velocity_scale * dt))
            .fold(0.0f64, f64::max);
        if over <= 1.0 {
            return false;
        }
        for (x, a) in q.iter_mut().zip(start) {
            *x = a + (*x - a) / over;
        }
        true
    }
}
