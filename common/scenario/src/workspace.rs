//! The map from the master's workspace to the arm's, as every established teleoperation
//! stack draws it (dVRK's `mtsTeleOperationPSM`, ICube's cartesian_vic_teleop): a fixed
//! rotation between the two base frames, a position scale (one number or one per axis of
//! the arm's base), the box the arm's tool may be sent into, and the force scale on the
//! way back (through the same rotation). The clutch's offsets, captured at each engage,
//! live with the arm (`tactile-slave`): they are state, this is configuration.
//!
//! Pure arithmetic on arrays, so the scenario crate needs no linear-algebra crate; the
//! loop's values pass through exactly (a product with 1 and sums with 0), so the
//! defaults leave every run's bytes as they were.

use crate::shown::Num;
use crate::{invalid, ScenarioError};
use serde::{Deserialize, Serialize};

/// A 3x3 rotation matrix, rows.
pub type Matrix = [[f64; 3]; 3];

/// The range of a position or force scale: from a micromanipulator's 1:1000 to a
/// macro arm's 100:1. Outside it the map turns a millimetre of the robot into
/// kilometres of the master's workspace (`slave.arm.scale = 1e-300` made the slave's
/// force 8e301 N) or the operator's hand into nothing.
pub const SCALE_RANGE: (f64, f64) = (1e-3, 100.0);

fn in_scale_range(s: f64) -> bool {
    s.is_finite() && (SCALE_RANGE.0..=SCALE_RANGE.1).contains(&s)
}

/// Why a scale is refused: the value (in its shortest form, so 1e-300 is not 300
/// digits and 100.1 is not `1.001e2`) and the range.
fn out_of_range(s: f64) -> String {
    let (lo, hi) = SCALE_RANGE;
    format!("{} is outside [{lo}, {hi}]", Num(s))
}

/// How far from one a configured quaternion's norm may be before it is refused (four
/// or five decimals of a half-angle's sine are what people copy).
const UNIT_TOLERANCE: f64 = 1e-3;

/// Metres the arm's tool moves per metre of the master's hand: one number, or one per
/// axis of the arm's base frame (applied after the rotation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    /// The same on every axis.
    Uniform(f64),
    /// x, y, z of the arm's base frame.
    PerAxis([f64; 3]),
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

impl Scale {
    /// The three factors.
    pub fn axes(&self) -> [f64; 3] {
        match *self {
            Scale::Uniform(s) => [s; 3],
            Scale::PerAxis(s) => s,
        }
    }

    fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        for (i, s) in self.axes().iter().enumerate() {
            if !in_scale_range(*s) {
                let f = match self {
                    Scale::Uniform(_) => field.to_string(),
                    Scale::PerAxis(_) => format!("{field}[{i}]"),
                };
                return Err(invalid(f, out_of_range(*s)));
            }
        }
        Ok(())
    }
}

/// The master's base frame in the arm's: `R` takes a vector in the master's axes to the
/// arm's. Written as roll, pitch and yaw in degrees about the fixed x, y, z axes (as
/// URDF's `rpy` and `static_transform_publisher` take them), or as a unit quaternion
/// `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum FrameRotation {
    /// Roll about x, then pitch about y, then yaw about z (fixed axes), degrees.
    RpyDeg([f64; 3]),
    /// A unit quaternion `[x, y, z, w]` (normalized when read).
    Quaternion([f64; 4]),
}

impl Default for FrameRotation {
    fn default() -> Self {
        FrameRotation::Quaternion([0.0, 0.0, 0.0, 1.0])
    }
}

impl FrameRotation {
    /// True for no rotation.
    pub fn is_identity(&self) -> bool {
        match *self {
            FrameRotation::RpyDeg(a) => a == [0.0; 3],
            FrameRotation::Quaternion(q) => q == [0.0, 0.0, 0.0, 1.0],
        }
    }

    /// The rotation matrix.
    pub fn matrix(&self) -> Matrix {
        match *self {
            FrameRotation::RpyDeg(a) => rpy_matrix(a.map(f64::to_radians)),
            FrameRotation::Quaternion(q) => quaternion_matrix(q),
        }
    }

    /// The rotation as a unit quaternion `[x, y, z, w]`, w >= 0.
    pub fn quaternion(&self) -> [f64; 4] {
        let q = match *self {
            FrameRotation::Quaternion(q) => normalized(q),
            FrameRotation::RpyDeg(a) => {
                let [r, p, y] = a.map(|v| v.to_radians() / 2.0);
                let (sr, cr, sp, cp, sy, cy) =
                    (r.sin(), r.cos(), p.sin(), p.cos(), y.sin(), y.cos());
                [
                    sr * cp * cy - cr * sp * sy,
                    cr * sp * cy + sr * cp * sy,
                    cr * cp * sy - sr * sp * cy,
                    cr * cp * cy + sr * sp * sy,
                ]
            }
        };
        if q[3] < 0.0 {
            q.map(|v| -v)
        } else {
            q
        }
    }

    fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        match *self {
            FrameRotation::RpyDeg(a) => {
                for (i, v) in a.iter().enumerate() {
                    if !(v.is_finite() && v.abs() <= 360.0) {
                        return Err(invalid(
                            format!("{field}.rpy_deg[{i}]"),
                            format!("{} is not an angle within 360 degrees", Num(*v)),
                        ));
                    }
                }
            }
            FrameRotation::Quaternion(q) => {
                let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
                if !(n.is_finite() && (n - 1.0).abs() <= UNIT_TOLERANCE) {
                    return Err(invalid(
                        format!("{field}.quaternion"),
                        format!("{q:?} has norm {}, not 1", Num(n)),
                    ));
                }
            }
        }
        Ok(())
    }
}

fn normalized(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

/// `Rz(y) Ry(p) Rx(r)`: URDF's convention.
fn rpy_matrix([r, p, y]: [f64; 3]) -> Matrix {
    let (sr, cr, sp, cp, sy, cy) = (r.sin(), r.cos(), p.sin(), p.cos(), y.sin(), y.cos());
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// The matrix of a quaternion `[x, y, z, w]` (normalized first).
pub fn quaternion_matrix(q: [f64; 4]) -> Matrix {
    let [x, y, z, w] = normalized(q);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// `m v`.
pub fn apply(m: &Matrix, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// `m^T v`.
pub fn apply_transpose(m: &Matrix, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2])
}

/// The box of the arm's base frame its tool may be sent into, m: a target outside is
/// clamped onto it and counted (a table, a wall, a cell's fence the robot must not
/// reach for whatever the operator does).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Workspace {
    /// The smallest x, y, z.
    pub min: [f64; 3],
    /// The largest x, y, z.
    pub max: [f64; 3],
}

impl Workspace {
    /// `p` clamped into the box, and whether it had to be.
    pub fn clamp(&self, p: [f64; 3]) -> ([f64; 3], bool) {
        let c = [0, 1, 2].map(|k| p[k].clamp(self.min[k], self.max[k]));
        (c, c != p)
    }

    fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        for k in 0..3 {
            let (lo, hi) = (self.min[k], self.max[k]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(invalid(
                    format!("{field}.min[{k}]"),
                    format!(
                        "{} m is not a finite number below max[{k}] = {} m",
                        Num(lo),
                        Num(hi)
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A rotation's configuration, checked; errors name `field`.
pub(crate) fn validate_rotation(r: &FrameRotation, field: &str) -> Result<(), ScenarioError> {
    r.validate(field)
}

/// The map's configuration, checked.
pub(crate) fn validate(
    scale: &Scale,
    rotation: &FrameRotation,
    workspace: Option<&Workspace>,
    force_scale: f64,
) -> Result<(), ScenarioError> {
    scale.validate("slave.arm.scale")?;
    rotation.validate("slave.arm.rotation")?;
    if let Some(w) = workspace {
        w.validate("slave.arm.workspace")?;
    }
    if !in_scale_range(force_scale) {
        return Err(invalid("slave.arm.force_scale", out_of_range(force_scale)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scale just past its bound reads as written: `{:e}` showed 100.1 as `1.001e2`.
    #[test]
    fn a_scale_out_of_range_reads_as_written() {
        assert_eq!(out_of_range(100.1), "100.1 is outside [0.001, 100]");
        assert_eq!(out_of_range(-1e308), "-1e308 is outside [0.001, 100]");
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12)
    }

    #[test]
    fn rpy_and_its_quaternion_are_the_same_rotation() {
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 360.0 - 180.0
        };
        for _ in 0..200 {
            let rpy = FrameRotation::RpyDeg([next(), next() / 2.0, next()]);
            let q = FrameRotation::Quaternion(rpy.quaternion());
            let (a, b) = (rpy.matrix(), q.matrix());
            for v in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.3, -2.0, 0.7]] {
                assert!(close(apply(&a, v), apply(&b, v)), "{rpy:?}");
                assert!(
                    close(apply_transpose(&a, apply(&a, v)), v),
                    "not orthonormal"
                );
            }
        }
    }

    #[test]
    fn a_touch_base_turns_into_a_robot_base() {
        // A Touch's base has y up and z towards the operator; a robot's z is up.
        let r = FrameRotation::RpyDeg([90.0, 0.0, 0.0]).matrix();
        assert!(close(apply(&r, [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]));
        assert!(close(apply(&r, [0.0, 0.0, 1.0]), [0.0, -1.0, 0.0]));
    }

    /// Roll, pitch and yaw compose about the fixed axes, yaw last (URDF's order): a desk
    /// device facing a robot, rpy (90, 0, -90), takes the device's right to the robot's
    /// -y, its up to z, towards the operator to -x; and a general one equals the
    /// product of the three turns written out.
    #[test]
    fn rpy_composes_about_fixed_axes_yaw_last() {
        let m = FrameRotation::RpyDeg([90.0, 0.0, -90.0]).matrix();
        assert!(close(apply(&m, [1.0, 0.0, 0.0]), [0.0, -1.0, 0.0]));
        assert!(close(apply(&m, [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]));
        assert!(close(apply(&m, [0.0, 0.0, 1.0]), [-1.0, 0.0, 0.0]));
        let (r, p, y) = (0.3f64, -0.4f64, 1.1f64);
        let rx = [
            [1.0, 0.0, 0.0],
            [0.0, r.cos(), -r.sin()],
            [0.0, r.sin(), r.cos()],
        ];
        let ry = [
            [p.cos(), 0.0, p.sin()],
            [0.0, 1.0, 0.0],
            [-p.sin(), 0.0, p.cos()],
        ];
        let rz = [
            [y.cos(), -y.sin(), 0.0],
            [y.sin(), y.cos(), 0.0],
            [0.0, 0.0, 1.0],
        ];
        let m = FrameRotation::RpyDeg([r, p, y].map(f64::to_degrees)).matrix();
        let v = [0.2, -0.7, 0.5];
        let want = apply(&rz, apply(&ry, apply(&rx, v)));
        assert!(close(apply(&m, v), want), "{:?} {want:?}", apply(&m, v));
    }

    #[test]
    fn the_identity_passes_values_through_exactly() {
        let m = FrameRotation::default().matrix();
        for v in [[0.1, -0.2, 0.3], [1e-300, -0.0, 7.5]] {
            assert_eq!(apply(&m, v), v);
            assert_eq!(apply_transpose(&m, v), v);
        }
    }

    #[test]
    fn bad_values_name_their_field() {
        let e = validate(
            &Scale::PerAxis([1.0, 0.0, 1.0]),
            &FrameRotation::default(),
            None,
            1.0,
        );
        assert!(e
            .expect_err("refused")
            .to_string()
            .contains("slave.arm.scale[1]"));
        let e = validate(
            &Scale::Uniform(1.0),
            &FrameRotation::Quaternion([0.0, 0.0, 0.5, 0.5]),
            None,
            1.0,
        );
        assert!(e
            .expect_err("refused")
            .to_string()
            .contains("slave.arm.rotation.quaternion"));
        let w = Workspace {
            min: [0.0, 0.5, 0.0],
            max: [1.0, 0.5, 1.0],
        };
        let e = validate(
            &Scale::Uniform(1.0),
            &FrameRotation::default(),
            Some(&w),
            1.0,
        );
        assert!(e
            .expect_err("refused")
            .to_string()
            .contains("slave.arm.workspace.min[1]"));
        let e = validate(
            &Scale::Uniform(1.0),
            &FrameRotation::default(),
            None,
            f64::NAN,
        );
        assert!(e
            .expect_err("refused")
            .to_string()
            .contains("slave.arm.force_scale"));
    }

    /// Issue 51: `scale = 1e-300` was taken, and the slave sent 8e301 N.
    #[test]
    fn scales_outside_their_range_are_refused() {
        let map = |scale, force| validate(&scale, &FrameRotation::default(), None, force);
        for s in [1e-300, 9.9e-4, 100.1, f64::INFINITY, 0.0, -1.0] {
            let e = map(Scale::Uniform(s), 1.0).expect_err("scale").to_string();
            assert!(
                e.contains("slave.arm.scale") && e.contains("outside [0.001, 100]"),
                "{e}"
            );
            let e = map(Scale::Uniform(1.0), s)
                .expect_err("force scale")
                .to_string();
            assert!(e.contains("slave.arm.force_scale"), "{e}");
        }
        let e = map(Scale::Uniform(1e-300), 1.0)
            .expect_err("tiny")
            .to_string();
        assert!(e.contains("1e-300 is outside"), "{e}");
        for s in [1e-3, 0.01, 1.0, 100.0] {
            map(Scale::Uniform(s), s).expect("in range");
        }
    }

    #[test]
    fn a_point_outside_the_box_is_clamped_onto_it() {
        let w = Workspace {
            min: [-1.0; 3],
            max: [1.0; 3],
        };
        assert_eq!(w.clamp([0.5, 0.0, -0.5]), ([0.5, 0.0, -0.5], false));
        assert_eq!(w.clamp([2.0, 0.0, -3.0]), ([1.0, 0.0, -1.0], true));
    }
}
