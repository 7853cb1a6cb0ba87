//! The arms as frames: the paper's kinematics written as a chain of link transforms,
//! so that the URDF ([`crate::urdf`]), the recordings' `/tf` and the live view place
//! the links where the kernels' FK puts the tool.
//!
//! The paper's FK (`tactile_math::kernels::fk`) in the device frame (y up):
//! shoulder at `(0, L3, -L4)`; the turntable turns about -y by theta1; the upper arm,
//! `L1` long, leaves the shoulder at theta2 above the horizontal (about -x); the
//! forearm, `L2` long, hangs at theta3 from the vertical, measured from the ground
//! (the Omni's parallel linkage), not from the upper arm. A serial chain gets that with
//! an elbow joint that mimics joint 2 with multiplier -1 (undoing the upper arm's
//! turn) before joint 3, whose origin turns by pi/2. Joint values are then the paper's
//! angles: theta1, theta2, theta3.

use tactile_math::geometry::Geometry;

/// A transform: `(parent, child, translation m, rotation [x, y, z, w])`.
pub type Link = (String, String, [f64; 3], [f64; 4]);

/// The two arms, by the prefix of their frames, joints and topics.
pub const ARMS: [&str; 2] = ["master", "slave"];

/// The world frame both arms stand in (z up, as REP 103 asks).
pub const WORLD: &str = "world";

/// `{arm}_{name}`: a frame or joint of one arm.
pub fn name(arm: &str, part: &str) -> String {
    format!("{arm}_{part}")
}

/// The arm's joint names, `{arm}_joint1..3`, as JointState and the URDF name them.
pub fn joint_names(arm: &str) -> Vec<String> {
    ["joint1", "joint2", "joint3"]
        .map(|j| name(arm, j))
        .to_vec()
}

/// Rotation by `a` about x.
pub fn rot_x(a: f64) -> [f64; 4] {
    [(a / 2.0).sin(), 0.0, 0.0, (a / 2.0).cos()]
}

/// Rotation by `a` about y.
pub fn rot_y(a: f64) -> [f64; 4] {
    [0.0, (a / 2.0).sin(), 0.0, (a / 2.0).cos()]
}

/// Where each arm's base stands in the world: side by side, 0.4 m apart, 0.2 m up,
/// turned so the device's y (up) is the world's z.
pub fn base_in_world(arm: &str) -> Link {
    let x = if arm == ARMS[0] { -0.2 } else { 0.2 };
    (
        WORLD.to_string(),
        name(arm, "base"),
        [x, 0.0, 0.2],
        rot_x(std::f64::consts::FRAC_PI_2),
    )
}

/// The transforms that never move: the bases in the world and each tool on its
/// forearm (`L2` along the forearm's z).
pub fn fixed(g: &Geometry) -> Vec<Link> {
    let mut v: Vec<Link> = ARMS.iter().map(|a| base_in_world(a)).collect();
    for a in ARMS {
        v.push((
            name(a, "forearm"),
            name(a, "tool"),
            [0.0, 0.0, g.l2],
            [0.0, 0.0, 0.0, 1.0],
        ));
    }
    v
}

/// The four moving transforms of `arm` at the paper's joint angles `theta`.
pub fn links(g: &Geometry, arm: &str, theta: [f64; 3]) -> [Link; 4] {
    let l4 = g.l1 + g.a;
    let f = |p: &str, c: &str, t: [f64; 3], r: [f64; 4]| (name(arm, p), name(arm, c), t, r);
    [
        f("base", "link1", [0.0, g.l3, -l4], rot_y(-theta[0])),
        f("link1", "upper_arm", [0.0; 3], rot_x(-theta[1])),
        f("upper_arm", "elbow", [0.0, 0.0, g.l1], rot_x(theta[1])),
        f(
            "elbow",
            "forearm",
            [0.0; 3],
            rot_x(std::f64::consts::FRAC_PI_2 - theta[2]),
        ),
    ]
}

/// `q` applied to `v`.
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [x, y, z, w] = q;
    // v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    let c1 = [
        y * v[2] - z * v[1],
        z * v[0] - x * v[2],
        x * v[1] - y * v[0],
    ];
    let c2 = [
        y * c1[2] - z * c1[1],
        z * c1[0] - x * c1[2],
        x * c1[1] - y * c1[0],
    ];
    [0, 1, 2].map(|i| v[i] + 2.0 * (w * c1[i] + c2[i]))
}

/// Quaternion product `a b` (first b, then a).
pub fn compose(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// The tool's position in the arm's base frame, through the chain of transforms.
pub fn tool_in_base(g: &Geometry, theta: [f64; 3]) -> [f64; 3] {
    let (mut p, mut q) = ([0.0; 3], [0.0, 0.0, 0.0, 1.0]);
    let tool = [0.0, 0.0, g.l2];
    for (_, _, t, r) in links(g, "a", theta).iter().chain([&(
        String::new(),
        String::new(),
        tool,
        [0.0, 0.0, 0.0, 1.0],
    )]) {
        let d = rotate(q, *t);
        p = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
        q = compose(q, *r);
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactile_math::arith::StdTrig;
    use tactile_math::kernels::fk;

    #[test]
    fn the_chain_puts_the_tool_where_the_kernels_fk_does() {
        let g = Geometry::PAPER;
        let lengths = g.lengths::<f64>();
        for theta in [
            [0.0, 0.0, 0.0],
            [0.3, -0.2, 0.9],
            [-1.1, 0.7, 0.2],
            [2.5, 1.2, -0.4],
        ] {
            let chain = tool_in_base(&g, theta);
            let kernel = fk(&lengths, &StdTrig, theta);
            for k in 0..3 {
                assert!(
                    (chain[k] - kernel[k]).abs() < 1e-12,
                    "{theta:?}: {chain:?} vs {kernel:?}"
                );
            }
        }
    }
}
