//! Forward kinematics and the geometric Jacobian of a chain, in its base frame.

use crate::chain::{Chain, Kind};
use crate::spatial::Frame;
use nalgebra::{Matrix6xX, Vector3};

impl Chain {
    /// Each moving joint's frame in the base, and the tip's, at joint values `q`.
    pub fn frames(&self, q: &[f64]) -> (Vec<Frame>, Frame) {
        let mut out = Vec::with_capacity(self.joints.len());
        let tip = self.frames_into(q, &mut out);
        (out, tip)
    }

    /// [`Chain::frames`] into `out` (cleared first): no allocation once it has room.
    pub fn frames_into(&self, q: &[f64], out: &mut Vec<Frame>) -> Frame {
        out.clear();
        self.walk(q, |f| out.push(f))
    }

    /// The tip's pose in the base at joint values `q` (allocates nothing).
    pub fn fk(&self, q: &[f64]) -> Frame {
        self.walk(q, |_| {})
    }

    /// Each moving joint's frame in the base to `each`, base to tip; the tip's back.
    fn walk(&self, q: &[f64], mut each: impl FnMut(Frame)) -> Frame {
        let mut f = Frame::IDENTITY;
        for j in &self.joints {
            f = f.then(&j.frame(j.position(q)));
            each(f);
        }
        f.then(&self.tip_frame)
    }

    /// The tip's pose and its geometric Jacobian: column `k` is the tip's velocity
    /// `[linear; angular]` in the base frame, at the tip's origin, per unit speed of
    /// degree of freedom `k` (Pinocchio's `LOCAL_WORLD_ALIGNED` of the tip frame, for a
    /// base at the world's origin). A mimic joint adds its multiple to its leader's.
    pub fn jacobian(&self, q: &[f64], jac: &mut Matrix6xX<f64>) -> Frame {
        self.jacobian_with(q, jac, &mut Vec::with_capacity(self.joints.len()))
    }

    /// [`Chain::jacobian`] with the joints' frames kept in `frames`: no allocation
    /// once it has room for them.
    pub fn jacobian_with(
        &self,
        q: &[f64],
        jac: &mut Matrix6xX<f64>,
        frames: &mut Vec<Frame>,
    ) -> Frame {
        let tip = self.frames_into(q, frames);
        jac.fill(0.0);
        for (j, f) in self.joints.iter().zip(frames.iter()) {
            let z: Vector3<f64> = f.r * j.axis.into_inner();
            let (lin, ang) = match j.kind {
                Kind::Revolute => (z.cross(&(tip.p - f.p)), z),
                Kind::Prismatic => (z, Vector3::zeros()),
            };
            let mut col = jac.column_mut(j.dof);
            for i in 0..3 {
                col[i] += j.multiplier * lin[i];
                col[i + 3] += j.multiplier * ang[i];
            }
        }
        tip
    }
}

#[cfg(test)]
mod tests {
    use crate::Chain;
    use nalgebra::Matrix6xX;
    use proptest::prelude::*;
    use tactile_math::arith::StdTrig;
    use tactile_math::geometry::Geometry;
    use tactile_math::kernels::fk;

    fn paper_slave() -> Chain {
        let xml = tactile_ros::urdf::urdf(&Geometry::PAPER);
        Chain::from_urdf(&xml, "slave_base", "slave_tool").expect("the paper's arm is a chain")
    }

    #[test]
    fn the_papers_arm_is_a_chain_of_three_joints_and_a_mimic() {
        let c = paper_slave();
        let names: Vec<&str> = c.dofs.iter().map(|d| d.name.as_str()).collect();
        assert_eq!(names, ["slave_joint1", "slave_joint2", "slave_joint3"]);
        assert_eq!(c.joints.len(), 4);
        assert!(c.has_mimic());
    }

    proptest! {
        /// The chain read from the paper arm's URDF puts the tool where the paper's
        /// closed-form FK does.
        #[test]
        fn the_chain_fk_is_the_papers_fk(t1 in -1.5f64..1.5, t2 in -0.5f64..1.2, t3 in -0.8f64..1.0) {
            let g = Geometry::PAPER.lengths::<f64>();
            let k = fk(&g, &StdTrig, [t1, t2, t3]);
            let p = paper_slave().fk(&[t1, t2, t3]).p;
            for i in 0..3 {
                prop_assert!((p[i] - k[i]).abs() < 1e-12, "{p:?} vs {k:?}");
            }
        }

        /// Each Jacobian column is the derivative of the FK (central differences).
        #[test]
        fn the_jacobian_is_the_derivative_of_the_fk(t1 in -1.5f64..1.5, t2 in -0.5f64..1.2, t3 in -0.8f64..1.0) {
            let c = paper_slave();
            let q = [t1, t2, t3];
            let mut jac = Matrix6xX::zeros(3);
            c.jacobian(&q, &mut jac);
            let h = 1e-6;
            for k in 0..3 {
                let (mut a, mut b) = (q, q);
                a[k] += h;
                b[k] -= h;
                let d = (c.fk(&a).p - c.fk(&b).p) / (2.0 * h);
                for i in 0..3 {
                    prop_assert!((d[i] - jac[(i, k)]).abs() < 1e-7);
                }
            }
        }
    }
}
