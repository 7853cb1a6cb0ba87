//! The simulated arm's integration (see [`super`]): at every integration step its
//! servo's efforts, the contact's, and the articulated-body algorithm, all into
//! buffers made with the arm (issues 52 and 66: a sample allocates nothing, as a
//! real-time loop must not, the IK's workspace among them). The arithmetic is the
//! allocating version's, operation for operation, so every figure is the same bit for
//! bit: the Cartesian servo's products of a Jacobian of 6 columns or more, which
//! nalgebra hands to `matrixmultiply` (whose packing buffers it allocates on every
//! call), go through `tactile_chain::matmul::mul_to`, the same sums without them.

use super::UrdfArm;
use crate::environment::deepest_contact;
use crate::world::Touch;
use nalgebra::{
    DMatrix, DVector, DVectorView, Dyn, Matrix6, Matrix6xX, OMatrix, Vector3, Vector6, U6,
};
use tactile_chain::dynamics::Workspace;
use tactile_chain::matmul::mul_to;
use tactile_chain::{ik, Chain, Frame, Ik};
use tactile_math::kernels;
use tactile_scenario::ArmServo;

/// The buffers of the integration, sized for the chain when the arm is made.
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    /// The IK's own (the sample's IK call, [`UrdfArm::follow`]).
    pub(super) ik: ik::Workspace,
    /// The dynamics' own.
    ws: Workspace,
    /// The joints' frames in the base (the Jacobian's).
    frames: Vec<Frame>,
    /// The tool's Jacobian at the joints.
    jac: Matrix6xX<f64>,
    /// Per joint: gravity's torques, the servo's efforts (after the limits), the
    /// contact's, the sum that drives the joint, its acceleration.
    g: Vec<f64>,
    tau: Vec<f64>,
    ext: Vec<f64>,
    drive: Vec<f64>,
    acc: Vec<f64>,
    /// The joints that hit their effort limit this period.
    clamped: Vec<bool>,
    /// The Cartesian impedance's.
    imp: Impedance,
}

/// The Cartesian impedance's intermediate matrices (see [`UrdfArm::impedance`]).
#[derive(Debug, Clone, Default)]
struct Impedance {
    /// `J^T`, the task's efforts `J^T w`, the damped pseudo-inverse `J^+` and its
    /// transpose, `J^T J^+T`, the null-space projector, the posture's PD efforts and
    /// their projection.
    jt: OMatrix<f64, Dyn, U6>,
    task: DVector<f64>,
    pinv: OMatrix<f64, Dyn, U6>,
    pinv_t: Matrix6xX<f64>,
    jp: DMatrix<f64>,
    null: DMatrix<f64>,
    posture: DVector<f64>,
    pulled: DVector<f64>,
}

impl Scratch {
    /// Buffers for `chain` and its `ik`.
    pub(super) fn new(chain: &Chain, ik: &Ik) -> Scratch {
        let n = chain.dof();
        let imp = Impedance {
            jt: OMatrix::<f64, Dyn, U6>::zeros(n),
            task: DVector::zeros(n),
            pinv: OMatrix::<f64, Dyn, U6>::zeros(n),
            pinv_t: Matrix6xX::zeros(n),
            jp: DMatrix::zeros(n, n),
            null: DMatrix::zeros(n, n),
            posture: DVector::zeros(n),
            pulled: DVector::zeros(n),
        };
        Scratch {
            ik: ik::Workspace::new(ik),
            ws: Workspace::new(chain),
            frames: Vec::with_capacity(chain.joints.len()),
            jac: Matrix6xX::zeros(n),
            g: vec![0.0; n],
            tau: vec![0.0; n],
            ext: vec![0.0; n],
            drive: vec![0.0; n],
            acc: vec![0.0; n],
            clamped: vec![false; n],
            imp,
        }
    }
}

impl UrdfArm {
    /// Integrates the arm over `dt` under its servo, pushed by whatever the tool
    /// `touch`es. Returns how many joints hit their effort limit.
    pub fn advance(&mut self, dt: f64, touch: Touch<'_>) -> u32 {
        let steps = (dt / self.cfg.step_s).ceil().max(1.0) as u32;
        let h = dt / f64::from(steps);
        // Out of the arm for the period, so that the steps borrow both apart (the
        // empty `Scratch` left meanwhile allocates nothing).
        let mut s = std::mem::take(&mut self.scratch);
        s.clamped.iter_mut().for_each(|c| *c = false);
        for _ in 0..steps {
            if !self.step(&mut s, touch, h) {
                break;
            }
        }
        let clamps = s.clamped.iter().filter(|c| **c).count() as u32;
        self.scratch = s;
        clamps
    }

    /// One integration step of `h`; false if the dynamics failed.
    fn step(&mut self, s: &mut Scratch, touch: Touch<'_>, h: f64) -> bool {
        self.servo(s);
        self.contact_torques(s, touch);
        for i in 0..s.drive.len() {
            s.drive[i] = s.tau[i] + s.ext[i] - self.chain.dofs[i].damping * self.state.qd[i];
        }
        let (q, qd) = (&self.state.q, &self.state.qd);
        match self
            .dynamics
            .aba_into(&mut s.ws, q, qd, &s.drive, &mut s.acc)
        {
            Ok(()) if s.acc.iter().all(|a| a.is_finite()) => {}
            // Never integrate a non-finite state: the joints stop where they are,
            // and the failure is counted and kept for the slave's log.
            failed => {
                self.state.qd.iter_mut().for_each(|v| *v = 0.0);
                self.failures.0 += 1;
                self.failures.1 = Some(match failed {
                    Err(e) => e.to_string(),
                    Ok(()) => "the joints' accelerations are not finite".into(),
                });
                return false;
            }
        }
        self.integrate(&s.acc, h);
        self.state.tau.copy_from_slice(&s.tau);
        true
    }

    /// The servo's efforts with gravity compensation into `s.tau`, clamped to each
    /// joint's effort limit: the joint PD, or the Cartesian impedance.
    fn servo(&self, s: &mut Scratch) {
        if self
            .dynamics
            .gravity_torques_into(&mut s.ws, &self.state.q, &mut s.g)
            .is_err()
        {
            s.g.iter_mut().for_each(|g| *g = 0.0);
        }
        let cartesian = match self.cfg.servo {
            ArmServo::Joint => false,
            ArmServo::Cartesian => true,
        };
        if cartesian {
            self.impedance(s);
        }
        let st = &self.state;
        for i in 0..s.g.len() {
            let u = match cartesian {
                false => {
                    self.cfg.kp[i] * (st.q_ref[i] - st.q[i])
                        + self.cfg.kd[i] * (st.qd_ref[i] - st.qd[i])
                        + s.g[i]
                }
                true => s.tau[i] + s.g[i],
            };
            let limit = self.chain.dofs[i].effort;
            let t = u.clamp(-limit, limit);
            s.clamped[i] |= t != u;
            s.tau[i] = t;
        }
    }

    /// The servo's efforts at the state now, as the next integration step applies them.
    #[cfg(test)]
    pub(super) fn servo_now(&self) -> Vec<f64> {
        let mut s = Scratch::new(&self.chain, &self.ik);
        self.servo(&mut s);
        s.tau
    }

    /// The Cartesian impedance without gravity into `s.tau`: `J^T (K e - D (v -
    /// v_ref))` toward the pose reference, and in the null space of the task (`I - J^T
    /// J^+T`, `J^+` damped) a PD toward the IK's references, so a redundant arm keeps
    /// its posture. (`mul_to` is `*` into a buffer: the same bits, no allocation.)
    fn impedance(&self, s: &mut Scratch) {
        let n = self.chain.dof();
        let tip = self
            .chain
            .jacobian_with(&self.state.q, &mut s.jac, &mut s.frames);
        let (r, v_ref) = &self.reference;
        let e_p = r.p - tip.p;
        let e_r = tactile_chain::spatial::log_rotation(&(r.r * tip.r.transpose()));
        let v = &s.jac * DVectorView::from_slice(&self.state.qd, n);
        let c = &self.cfg.cartesian;
        let (k, d) = (c.stiffness, c.damping());
        let e = [e_p.x, e_p.y, e_p.z, e_r.x, e_r.y, e_r.z];
        let w = Vector6::from_fn(|i, _| k[i] * e[i] - d[i] * (v[i] - v_ref[i]));
        let m = &mut s.imp;
        s.jac.transpose_to(&mut m.jt);
        mul_to(&m.jt, &w, &mut m.task);
        // J^+ = J^T (J J^T + lambda^2 I)^-1: damped, so a singular pose stays finite.
        let mut jjt = Matrix6::zeros();
        mul_to(&s.jac, &m.jt, &mut jjt);
        let jjt = jjt + Matrix6::identity() * 1e-6;
        let inv = jjt.try_inverse().unwrap_or_else(Matrix6::zeros);
        mul_to(&m.jt, &inv, &mut m.pinv);
        m.pinv.transpose_to(&mut m.pinv_t);
        mul_to(&m.jt, &m.pinv_t, &mut m.jp);
        m.null.fill_with_identity();
        m.null -= &m.jp;
        let kn = c.nullspace_stiffness;
        let dn = 2.0 * kn.sqrt();
        let st = &self.state;
        for i in 0..n {
            m.posture[i] = kn * (st.q_ref[i] - st.q[i]) - dn * st.qd[i];
        }
        mul_to(&m.null, &m.posture, &mut m.pulled);
        for i in 0..n {
            s.tau[i] = m.task[i] + m.pulled[i];
        }
    }

    /// The contact force at the tool as joint efforts into `s.ext`: J_v^T f. The
    /// analytic scene's is evaluated in the master's frame and turned into the base's;
    /// a physics world's comes in the base's.
    fn contact_torques(&self, s: &mut Scratch, touch: Touch<'_>) {
        let tip = self
            .chain
            .jacobian_with(&self.state.q, &mut s.jac, &mut s.frames);
        let f = match touch {
            Touch::Scene(objects) => {
                let tool = self.to_master(&tip.p);
                let Some(c) = deepest_contact(objects, tool) else {
                    s.ext.iter_mut().for_each(|e| *e = 0.0);
                    return;
                };
                self.cfg
                    .force_to_robot(kernels::fbf(c.surface, tool, c.stiffness))
            }
            Touch::Held(f) => f,
        };
        let f = Vector3::from(f);
        for (i, e) in s.ext.iter_mut().enumerate() {
            *e = s.jac.fixed_view::<3, 1>(0, i).dot(&f);
        }
    }

    /// Semi-implicit Euler; a joint that reaches its limit stops there.
    fn integrate(&mut self, acc: &[f64], h: f64) {
        let s = &mut self.state;
        for (i, d) in self.chain.dofs.iter().enumerate() {
            s.qd[i] += h * acc[i];
            s.q[i] += h * s.qd[i];
            if s.q[i] < d.lower || s.q[i] > d.upper {
                s.q[i] = s.q[i].clamp(d.lower, d.upper);
                s.qd[i] = 0.0;
            }
        }
    }
}
