//! `joints.csv`: a URDF arm's joints and its tool's orientation, one row a sample
//! (`[slave.arm]`), beside `trace.csv` whose columns stay the paper arm's. The
//! columns are described once, in [`header`] and [`row`] side by side.

use std::fmt::Write as _;
use tactile_records::slave::ArmJoints;

/// The header line (without newline) for an arm of `dof` joints: the IK's references,
/// the joints and their efforts per joint, h(n)'s torque about the tool (a real arm's
/// sensor's), then the orientation reference and the tool's orientation relative to
/// the tool's home (`[x, y, z, w]`, about the base's axes), the 6-DoF master's
/// orientation as the arm took it, the clutch's offsets captured at the last engage
/// (position in the base frame, m; orientation), the angle between the reference and
/// the tool, and the clutch.
pub fn header(dof: usize) -> String {
    let mut h = String::from("n");
    for field in ["q_ref", "q", "tau"] {
        for i in 1..=dof {
            let _ = write!(h, ",{field}_{i}");
        }
    }
    h.push_str(",h_torque_1,h_torque_2,h_torque_3");
    for field in ["target_rot", "tool_rot", "master_rot"] {
        for c in ["x", "y", "z", "w"] {
            let _ = write!(h, ",{field}_{c}");
        }
    }
    h.push_str(",offset_1,offset_2,offset_3");
    for c in ["x", "y", "z", "w"] {
        let _ = write!(h, ",offset_rot_{c}");
    }
    h.push_str(",rot_error_deg,released");
    h
}

/// Appends sample `n`'s row (with newline) to `line`.
pub fn row(line: &mut String, n: u64, j: &ArmJoints) {
    let _ = write!(line, "{n}");
    let values = j
        .q_ref
        .iter()
        .chain(j.q.iter())
        .chain(j.tau.iter())
        .chain(&j.torque);
    let turns = j.target_rotation.iter().chain(&j.tool_rotation);
    let map = j
        .master_rotation
        .iter()
        .chain(&j.offset)
        .chain(&j.offset_rotation);
    for x in values.chain(turns).chain(map) {
        let _ = write!(line, ",{x:?}");
    }
    let error = angle_deg(j.target_rotation, j.tool_rotation);
    let _ = writeln!(line, ",{error:?},{}", u8::from(j.released));
}

/// The angle between two orientations given as unit quaternions `[x, y, z, w]`,
/// degrees: `2 acos |a . b|`, computed as `4 atan2(|a - b|, |a + b|)` (with `b` on
/// `a`'s side; the two norms are 2 sin and 2 cos of a quarter of the angle) so it
/// stays exact for small angles.
pub fn angle_deg(a: [f64; 4], b: [f64; 4]) -> f64 {
    let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
    let s = if dot < 0.0 { -1.0 } else { 1.0 };
    let norm = |f: &dyn Fn(f64, f64) -> f64| {
        a.iter()
            .zip(&b)
            .map(|(x, y)| f(*x, *y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let diff = norm(&|x, y| x - s * y);
    let sum = norm(&|x, y| x + s * y);
    (4.0 * diff.atan2(sum)).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_math::joints::Joints;

    #[test]
    fn the_angle_between_orientations_is_the_turn_between_them() {
        let about_z = |deg: f64| {
            let h = deg.to_radians() / 2.0;
            [0.0, 0.0, h.sin(), h.cos()]
        };
        for (a, b) in [(0.0, 0.0), (10.0, 40.0), (-170.0, 170.0), (0.0, 1e-6)] {
            let want = ((b - a + 540.0) % 360.0 - 180.0_f64).abs();
            let got = angle_deg(about_z(a), about_z(b));
            assert!(
                (got - want).abs() < 1e-9 * want.max(1.0),
                "{a} {b}: {got} vs {want}"
            );
            // q and -q are the same orientation.
            let neg = about_z(b).map(|x| -x);
            assert!((angle_deg(about_z(a), neg) - want).abs() < 1e-9 * want.max(1.0));
        }
    }

    #[test]
    fn a_row_has_as_many_cells_as_the_header() {
        let j = ArmJoints {
            q_ref: Joints::from_slice(&[0.1; 7]).expect("seven"),
            q: Joints::from_slice(&[0.2; 7]).expect("seven"),
            tau: Joints::from_slice(&[0.3; 7]).expect("seven"),
            torque: [0.0; 3],
            target_rotation: [0.0, 0.0, 0.0, 1.0],
            tool_rotation: [0.0, 0.0, 0.0, 1.0],
            released: true,
            ..ArmJoints::default()
        };
        let mut line = String::new();
        row(&mut line, 5, &j);
        assert_eq!(
            line.trim_end().split(',').count(),
            header(7).split(',').count()
        );
        assert!(line.ends_with(",0.0,1\n"), "{line}");
    }
}
