//! Rigid transforms and the spatial algebra of the dynamics, in Pinocchio's order:
//! a motion is `[linear; angular]`, a force `[force; moment]`, so vectors and
//! Jacobians compare with Pinocchio's entry by entry.

use nalgebra::{Matrix3, Matrix6, Quaternion, Rotation3, Unit, UnitQuaternion, Vector3, Vector6};

/// A frame's pose in another: `x_parent = r * x_child + p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Rotation (orthonormal).
    pub r: Matrix3<f64>,
    /// Origin, m.
    pub p: Vector3<f64>,
}

impl Frame {
    /// The identity.
    pub const IDENTITY: Frame = Frame {
        r: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        p: Vector3::new(0.0, 0.0, 0.0),
    };

    /// URDF's `<origin xyz rpy>`: `Rz(yaw) Ry(pitch) Rx(roll)`, then the offset.
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Frame {
        let r = Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]).into_inner();
        Frame {
            r,
            p: Vector3::from(xyz),
        }
    }

    /// A turn by `angle` about the unit `axis` through the origin.
    pub fn rotation(axis: &Unit<Vector3<f64>>, angle: f64) -> Frame {
        Frame {
            r: Rotation3::from_axis_angle(axis, angle).into_inner(),
            p: Vector3::zeros(),
        }
    }

    /// A shift by `d`.
    pub fn translation(d: Vector3<f64>) -> Frame {
        Frame {
            r: Matrix3::identity(),
            p: d,
        }
    }

    /// `self * other`: `other` is given in `self`'s child frame.
    pub fn then(&self, other: &Frame) -> Frame {
        Frame {
            r: self.r * other.r,
            p: self.p + self.r * other.p,
        }
    }

    /// The parent seen from the child.
    pub fn inverse(&self) -> Frame {
        let rt = self.r.transpose();
        Frame {
            r: rt,
            p: -(rt * self.p),
        }
    }

    /// A point of the child frame in the parent's.
    pub fn point(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.r * x + self.p
    }

    /// The motion transform from parent to child coordinates (`v_child = X v_parent`);
    /// its transpose carries forces from child to parent.
    pub fn motion_to_child(&self) -> Matrix6<f64> {
        let rt = self.r.transpose();
        let mut x = Matrix6::zeros();
        x.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
        x.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
        x.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-(rt * self.p.cross_matrix())));
        x
    }
}

/// The motion cross product matrix: `motion_cross(v) * m = v x m`.
pub fn motion_cross(v: &Vector6<f64>) -> Matrix6<f64> {
    let lin = Vector3::new(v[0], v[1], v[2]).cross_matrix();
    let ang = Vector3::new(v[3], v[4], v[5]).cross_matrix();
    let mut x = Matrix6::zeros();
    x.fixed_view_mut::<3, 3>(0, 0).copy_from(&ang);
    x.fixed_view_mut::<3, 3>(3, 3).copy_from(&ang);
    x.fixed_view_mut::<3, 3>(0, 3).copy_from(&lin);
    x
}

/// The force cross product: `v x* f = -motion_cross(v)^T f`.
pub fn force_cross(v: &Vector6<f64>, f: &Vector6<f64>) -> Vector6<f64> {
    -(motion_cross(v).transpose() * f)
}

/// The spatial inertia about a frame's origin of a body of `mass` kg whose centre of
/// mass is at `com` and whose rotational inertia about the centre is `i_com`, all in
/// that frame.
pub fn inertia(mass: f64, com: &Vector3<f64>, i_com: &Matrix3<f64>) -> Matrix6<f64> {
    let c = com.cross_matrix();
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Matrix3::identity() * mass));
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-c * mass));
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(c * mass));
    m.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(i_com - c * c * mass));
    m
}

/// A spatial inertia given in `f`'s child frame, expressed in its parent frame.
pub fn inertia_to_parent(f: &Frame, i: &Matrix6<f64>) -> Matrix6<f64> {
    let x = f.motion_to_child();
    x.transpose() * i * x
}

/// The rotation of a unit quaternion `[x, y, z, w]` (ROS order; normalized here).
pub fn rotation_matrix(q: [f64; 4]) -> Matrix3<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]))
        .to_rotation_matrix()
        .into_inner()
}

/// A rotation matrix as a unit quaternion `[x, y, z, w]` with `w >= 0` (one of the
/// two that are the same rotation, so equal rotations give equal numbers).
pub fn quaternion(r: &Matrix3<f64>) -> [f64; 4] {
    // Closed form (Shepperd's): nalgebra's iterative `from_matrix` loops on a NaN.
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.i, s * q.j, s * q.k, s * q.w]
}

/// The rotation vector (axis times angle, rad) of `r`, its logarithm: finite for any
/// nearly orthonormal matrix, exact near no turn and near half a turn.
pub fn log_rotation(r: &Matrix3<f64>) -> Vector3<f64> {
    // sin(angle) * axis is the skew part, cos(angle) comes from the trace.
    let v = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) / 2.0;
    let (sin, cos) = (v.norm(), ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0));
    let angle = sin.atan2(cos);
    if cos > -0.99 {
        // angle / sin(angle) is 1 + angle^2 / 6 near zero: no division by a small sin.
        let scale = if sin < 1e-9 {
            1.0 + angle * angle / 6.0
        } else {
            angle / sin
        };
        return v * scale;
    }
    // Near half a turn: the axis from the symmetric part, r + r^T = 2 (cos I + (1 - cos) a a^T),
    // its sign from the skew part.
    let sym = (r + r.transpose()) / 2.0 - Matrix3::identity() * cos;
    let k = (0..3)
        .max_by(|&a, &b| sym[(a, a)].total_cmp(&sym[(b, b)]))
        .unwrap_or(0);
    let mut axis = sym.column(k).into_owned() / (sym[(k, k)].max(1e-300)).sqrt();
    axis /= axis.norm().max(1e-300);
    if axis.dot(&v) < 0.0 {
        axis = -axis;
    }
    axis * angle
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternions_of_known_rotations_and_back() {
        let half_x = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0);
        let q = quaternion(&half_x);
        assert!(
            (q[0].abs() - 1.0).abs() < 1e-15 && q[1] == 0.0 && q[2] == 0.0,
            "{q:?}"
        );
        let h = 0.3_f64;
        let about_z = [0.0, 0.0, h.sin(), h.cos()];
        let r = rotation_matrix(about_z);
        assert!((r[(0, 1)] + (2.0 * h).sin()).abs() < 1e-15);
        let back = quaternion(&r);
        assert!(
            back.iter()
                .zip(&about_z)
                .all(|(a, b)| (a - b).abs() < 1e-15),
            "{back:?}"
        );
        // Not a rotation: an answer (NaN), not a hang.
        assert!(quaternion(&Matrix3::from_element(f64::NAN))[3].is_nan());
    }

    #[test]
    fn the_log_of_a_rotation_gives_back_its_axis_and_angle() {
        for angle in [
            0.0,
            1e-12,
            1e-6,
            0.3,
            1.5,
            3.0,
            3.1,
            std::f64::consts::PI - 1e-9,
        ] {
            for axis in [
                Vector3::new(1.0, 2.0, -0.5),
                Vector3::new(0.0, 0.0, 1.0),
                Vector3::new(-0.3, 0.1, 0.2),
            ] {
                let a = Unit::new_normalize(axis);
                let r = Rotation3::from_axis_angle(&a, angle).into_inner();
                let w = log_rotation(&r);
                assert!(
                    (w - a.into_inner() * angle).norm() < 1e-9,
                    "{angle} {axis:?}: {w:?}"
                );
            }
        }
    }

    #[test]
    fn a_frame_and_its_inverse_cancel() {
        let f = Frame::from_xyz_rpy([0.1, -0.2, 0.3], [0.4, -0.5, 0.6]);
        let i = f.then(&f.inverse());
        assert!((i.r - Matrix3::identity()).norm() < 1e-15);
        assert!(i.p.norm() < 1e-15);
    }

    #[test]
    fn rpy_is_fixed_axis_roll_then_pitch_then_yaw() {
        let f = Frame::from_xyz_rpy([0.0; 3], [0.3, 0.0, 0.0]);
        let g = Frame::from_xyz_rpy([0.0; 3], [0.0, 0.0, 0.7]);
        let h = Frame::from_xyz_rpy([0.0; 3], [0.3, 0.0, 0.7]);
        assert!((g.then(&f).r - h.r).norm() < 1e-15);
    }

    #[test]
    fn the_spatial_inertia_gives_momentum_and_angular_momentum() {
        let (m, c) = (2.0, Vector3::new(0.1, 0.2, -0.3));
        let ic = Matrix3::new(0.1, 0.01, 0.0, 0.01, 0.2, 0.02, 0.0, 0.02, 0.3);
        let v = Vector6::new(0.5, -0.4, 0.3, 1.0, 2.0, -1.5);
        let (lin, ang) = (v.fixed_rows::<3>(0), v.fixed_rows::<3>(3));
        let h = (lin + ang.cross(&c)) * m;
        let n = ic * ang + c.cross(&h);
        let f = inertia(m, &c, &ic) * v;
        assert!((f.fixed_rows::<3>(0) - h).norm() < 1e-14);
        assert!((f.fixed_rows::<3>(3) - n).norm() < 1e-14);
    }
}
