//! Rigid-body dynamics of a chain: inverse dynamics by the recursive Newton-Euler
//! algorithm, forward dynamics by the articulated-body algorithm (Featherstone,
//! *Rigid Body Dynamics Algorithms*, 2008, tables 5.1 and 7.1), in the base frame with
//! gravity given there. O(n) each, no mass matrix inverted.

use crate::chain::{Chain, Kind};
use crate::error::Error;
use crate::spatial::{force_cross, motion_cross};
use nalgebra::{Matrix6, Vector3, Vector6};

/// A chain's dynamics.
#[derive(Debug, Clone)]
pub struct Dynamics {
    chain: Chain,
    /// Gravity in the base frame, m/s^2.
    pub gravity: Vector3<f64>,
    /// Each joint's motion subspace in its own frame.
    s: Vec<Vector6<f64>>,
}

/// Gravity on Earth in a base whose z points up.
pub const EARTH: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

impl Dynamics {
    /// The dynamics of `chain` under `gravity` (base frame). Refused for a chain with
    /// mimic joints (a closed linkage in disguise) and for a joint that carries no
    /// inertia about its own axis (its acceleration would be unbounded).
    pub fn new(chain: &Chain, gravity: Vector3<f64>) -> Result<Dynamics, Error> {
        if chain.has_mimic() {
            return Err(Error::Dynamics(
                "the chain has mimic joints: its dynamics are a closed linkage's".into(),
            ));
        }
        effort_limits(chain)?;
        let s: Vec<Vector6<f64>> = chain.joints.iter().map(subspace).collect();
        // A joint with nothing of mass from it to the tip has no articulated inertia
        // about its axis: its acceleration would be unbounded.
        let mut massless = true;
        for j in chain.joints.iter().rev() {
            massless &= j.body.norm() == 0.0;
            if massless {
                return Err(Error::Dynamics(format!(
                    "joint `{}` moves nothing with mass: the links from it to the tip need <inertial>",
                    j.name
                )));
            }
        }
        Ok(Dynamics {
            chain: chain.clone(),
            gravity,
            s,
        })
    }

    /// The chain.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    fn check(&self, what: &'static str, v: &[f64]) -> Result<(), Error> {
        self.chain.check_len(what, v)
    }

    /// Each body's transform from its parent's coordinates, at `q`, into `x`.
    fn transforms(&self, q: &[f64], x: &mut Vec<Matrix6<f64>>) {
        x.clear();
        x.extend(
            self.chain
                .joints
                .iter()
                .map(|j| j.frame(q[j.dof]).motion_to_child()),
        );
    }

    /// The base's acceleration that stands for gravity.
    fn a0(&self) -> Vector6<f64> {
        let g = -self.gravity;
        Vector6::new(g.x, g.y, g.z, 0.0, 0.0, 0.0)
    }

    /// Joint efforts that give accelerations `qdd` at `q`, `qd`: `M qdd + C qd + g`.
    pub fn rnea(&self, q: &[f64], qd: &[f64], qdd: &[f64]) -> Result<Vec<f64>, Error> {
        let mut tau = vec![0.0; qdd.len()];
        self.rnea_into(&mut Workspace::new(&self.chain), q, qd, qdd, &mut tau)?;
        Ok(tau)
    }

    /// [`Dynamics::rnea`] into `tau`, its scratch in `ws`: no allocation once `ws` has
    /// grown to the chain (as it is made by [`Workspace::new`]).
    pub fn rnea_into(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        tau: &mut [f64],
    ) -> Result<(), Error> {
        self.check("q", q)?;
        self.check("qd", qd)?;
        self.check("qdd", qdd)?;
        self.check("tau", tau)?;
        self.transforms(q, &mut ws.x);
        let (x, f) = (&ws.x, &mut ws.pa);
        let n = x.len();
        let (mut v, mut a) = (Vector6::zeros(), self.a0());
        f.clear();
        for i in 0..n {
            let s = &self.s[i];
            let vj = s * qd[i];
            v = x[i] * v + vj;
            a = x[i] * a + s * qdd[i] + motion_cross(&v) * vj;
            let body = &self.chain.joints[i].body;
            f.push(body * a + force_cross(&v, &(body * v)));
        }
        for i in (0..n).rev() {
            tau[i] = self.s[i].dot(&f[i]);
            if i > 0 {
                let up = x[i].transpose() * f[i];
                f[i - 1] += up;
            }
        }
        Ok(())
    }

    /// The efforts that hold the arm still at `q` against gravity.
    pub fn gravity_torques(&self, q: &[f64]) -> Result<Vec<f64>, Error> {
        let mut tau = vec![0.0; q.len()];
        self.gravity_torques_into(&mut Workspace::new(&self.chain), q, &mut tau)?;
        Ok(tau)
    }

    /// [`Dynamics::gravity_torques`] into `tau`, its scratch in `ws`.
    pub fn gravity_torques_into(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        tau: &mut [f64],
    ) -> Result<(), Error> {
        // Taken out of `ws` for the call (an empty `Vec` allocates nothing) and put back.
        let mut z = std::mem::take(&mut ws.zeros);
        z.clear();
        z.resize(q.len(), 0.0);
        let r = self.rnea_into(ws, q, &z, &z, tau);
        ws.zeros = z;
        r
    }

    /// Joint accelerations under efforts `tau` at `q`, `qd`.
    pub fn aba(&self, q: &[f64], qd: &[f64], tau: &[f64]) -> Result<Vec<f64>, Error> {
        let mut qdd = vec![0.0; tau.len()];
        self.aba_into(&mut Workspace::new(&self.chain), q, qd, tau, &mut qdd)?;
        Ok(qdd)
    }

    /// [`Dynamics::aba`] into `qdd`, its scratch in `ws`: no allocation once `ws` has
    /// grown to the chain (as it is made by [`Workspace::new`]).
    pub fn aba_into(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), Error> {
        self.check("q", q)?;
        self.check("qd", qd)?;
        self.check("tau", tau)?;
        self.check("qdd", qdd)?;
        self.transforms(q, &mut ws.x);
        self.aba_outward(ws, qd);
        self.aba_inward(ws, tau)?;
        let Workspace { x, c, u, d, uu, .. } = ws;
        let mut a = self.a0();
        for i in 0..x.len() {
            let ap = x[i] * a + c[i];
            qdd[i] = (uu[i] - u[i].dot(&ap)) / d[i];
            a = ap + self.s[i] * qdd[i];
        }
        Ok(())
    }

    /// The ABA's first pass, base to tip: velocities' bias accelerations `c`, each
    /// body's own inertia `ia` and bias force `pa`.
    fn aba_outward(&self, ws: &mut Workspace, qd: &[f64]) {
        let Workspace { x, c, ia, pa, .. } = ws;
        c.clear();
        ia.clear();
        pa.clear();
        let mut v = Vector6::zeros();
        for i in 0..x.len() {
            let vj = self.s[i] * qd[i];
            v = x[i] * v + vj;
            c.push(motion_cross(&v) * vj);
            let body = self.chain.joints[i].body;
            ia.push(body);
            pa.push(force_cross(&v, &(body * v)));
        }
    }

    /// The ABA's second pass, tip to base: articulated inertias and bias forces
    /// folded into each parent, and each joint's `u`, `d`, `uu`.
    fn aba_inward(&self, ws: &mut Workspace, tau: &[f64]) -> Result<(), Error> {
        let Workspace {
            x,
            c,
            ia,
            pa,
            u,
            d,
            uu,
            ..
        } = ws;
        let n = x.len();
        for v in [&mut *d, &mut *uu] {
            v.clear();
            v.resize(n, 0.0);
        }
        u.clear();
        u.resize(n, Vector6::zeros());
        for i in (0..n).rev() {
            let s = &self.s[i];
            u[i] = ia[i] * s;
            d[i] = s.dot(&u[i]);
            if d[i].is_nan() || d[i] <= 1e-12 {
                let name = &self.chain.joints[i].name;
                return Err(Error::Dynamics(format!(
                    "joint `{name}` has no inertia about its axis at this configuration"
                )));
            }
            uu[i] = tau[i] - s.dot(&pa[i]);
            if i > 0 {
                let iai = ia[i] - u[i] * u[i].transpose() / d[i];
                let pai = pa[i] + iai * c[i] + u[i] * (uu[i] / d[i]);
                ia[i - 1] += x[i].transpose() * iai * x[i];
                pa[i - 1] += x[i].transpose() * pai;
            }
        }
        Ok(())
    }
}

/// The dynamics' scratch memory (Pinocchio's `Data` beside its `Model`, which
/// [`Dynamics`] is): made once for a chain, it lets [`Dynamics::aba_into`] and
/// [`Dynamics::rnea_into`] run in a simulation's inner loop without allocating.
/// Any workspace serves any chain; one made for another grows on its first use.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    /// Each body's motion transform from its parent.
    x: Vec<Matrix6<f64>>,
    /// Velocity-product accelerations (ABA).
    c: Vec<Vector6<f64>>,
    /// Articulated inertias (ABA).
    ia: Vec<Matrix6<f64>>,
    /// Bias forces (ABA); the bodies' forces (RNEA).
    pa: Vec<Vector6<f64>>,
    /// `IA s`, `s^T IA s` and `tau - s^T pA` per joint (ABA).
    u: Vec<Vector6<f64>>,
    d: Vec<f64>,
    uu: Vec<f64>,
    /// Zero velocities and accelerations (gravity torques).
    zeros: Vec<f64>,
}

impl Workspace {
    /// A workspace sized for `chain`: its first use allocates nothing either.
    pub fn new(chain: &Chain) -> Workspace {
        let n = chain.joints.len();
        Workspace {
            x: Vec::with_capacity(n),
            c: Vec::with_capacity(n),
            ia: Vec::with_capacity(n),
            pa: Vec::with_capacity(n),
            u: Vec::with_capacity(n),
            d: Vec::with_capacity(n),
            uu: Vec::with_capacity(n),
            zeros: Vec::with_capacity(chain.dof()),
        }
    }
}

/// Every degree of freedom has a positive, finite effort limit: a simulated servo's
/// torques are clamped to it, and without one (a continuous joint without `<limit>`,
/// or `effort="0"`, which URDF files write for "unknown") nothing bounds them, or
/// nothing can drive the joint.
fn effort_limits(chain: &Chain) -> Result<(), Error> {
    for d in &chain.dofs {
        if !(d.effort.is_finite() && d.effort > 0.0) {
            let unit = match chain
                .joints
                .iter()
                .find(|j| j.name == d.name)
                .map(|j| j.kind)
            {
                Some(Kind::Prismatic) => "N",
                _ => "N m",
            };
            let given = match d.effort.is_finite() {
                true => format!("effort {}", d.effort),
                false => "no <limit effort>".to_string(),
            };
            return Err(Error::Dynamics(format!(
                "joint `{}` has {given}: its motor's torque is unbounded or nothing; write its largest effort, <limit effort=\"...\"> in {unit}, greater than zero",
                d.name
            )));
        }
    }
    Ok(())
}

/// A joint's motion subspace `[linear; angular]` in its own frame.
fn subspace(j: &crate::chain::Joint) -> Vector6<f64> {
    let a = j.axis.into_inner();
    match j.kind {
        Kind::Revolute => Vector6::new(0.0, 0.0, 0.0, a.x, a.y, a.z),
        Kind::Prismatic => Vector6::new(a.x, a.y, a.z, 0.0, 0.0, 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_joint(kind: &str, limit: &str) -> Chain {
        let xml = format!(
            r#"<robot name="r"><link name="base"/>
            <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial></link>
            <joint name="j1" type="{kind}"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>{limit}</joint></robot>"#
        );
        Chain::from_urdf(&xml, "base", "a").expect("chain")
    }

    /// Issue 51: `effort="0"` (or a continuous joint without `<limit>`) left the
    /// simulated servo's torques unbounded.
    #[test]
    fn a_joint_without_a_positive_effort_limit_is_refused_and_named() {
        let zero = r#"<limit lower="-1" upper="1" effort="0" velocity="1"/>"#;
        for (kind, limit, want) in [
            ("revolute", zero, "joint `j1` has effort 0"),
            ("prismatic", zero, "in N, greater than zero"),
            ("continuous", "", "joint `j1` has no <limit effort>"),
        ] {
            let e = Dynamics::new(&one_joint(kind, limit), EARTH)
                .expect_err(want)
                .to_string();
            assert!(
                e.contains(want) && e.contains("<limit effort=\"...\">"),
                "{e}"
            );
        }
        let ok = r#"<limit lower="-1" upper="1" effort="5" velocity="1"/>"#;
        Dynamics::new(&one_joint("revolute", ok), EARTH).expect("a motor of 5 N m");
    }

    /// Issue 52: the workspace versions give the allocating ones' numbers bit for bit,
    /// from a workspace that served another chain (its stale contents unused).
    #[test]
    fn the_workspace_versions_give_the_same_bits_from_a_used_workspace() {
        let xml = include_str!("../../../deploy/robots/panda.urdf");
        let panda = Chain::from_urdf(xml, "panda_link0", "panda_hand").expect("panda");
        let dynamics = Dynamics::new(&panda, EARTH).expect("dynamics");
        let ok = r#"<limit lower="-1" upper="1" effort="5" velocity="1"/>"#;
        let one = Dynamics::new(&one_joint("revolute", ok), EARTH).expect("one joint");
        let mut ws = Workspace::new(&panda);
        let q = [0.3, -0.7, 0.2, -2.1, 0.4, 1.6, 0.9];
        let qd = [0.5, -0.4, 0.3, 0.2, -0.6, 0.7, -0.1];
        let tau = [1.0, -2.0, 3.0, -4.0, 0.5, -0.5, 0.25];
        let mut out = [0.0; 7];
        for _ in 0..2 {
            dynamics
                .aba_into(&mut ws, &q, &qd, &tau, &mut out)
                .expect("aba");
            assert_eq!(out.to_vec(), dynamics.aba(&q, &qd, &tau).expect("aba"));
            dynamics
                .rnea_into(&mut ws, &q, &qd, &tau, &mut out)
                .expect("rnea");
            assert_eq!(out.to_vec(), dynamics.rnea(&q, &qd, &tau).expect("rnea"));
            dynamics
                .gravity_torques_into(&mut ws, &q, &mut out)
                .expect("g");
            assert_eq!(out.to_vec(), dynamics.gravity_torques(&q).expect("g"));
            // A bigger chain's leftovers, then the Panda again.
            let mut small = [0.0];
            one.aba_into(&mut ws, &[0.1], &[0.2], &[0.3], &mut small)
                .expect("aba");
        }
        let e = dynamics.aba_into(&mut ws, &q, &qd, &tau, &mut [0.0; 6]);
        assert!(e.expect_err("six outputs").to_string().contains("qdd"));
    }
}
