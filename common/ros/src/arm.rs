//! The arms as frames: the paper's kinematics written once as a chain of joints
//! ([`chain`]), from which the URDF ([`crate::urdf`]), the recordings' `/tf` and the
//! live view place the links where the kernels' FK puts the tool.
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

/// How a joint of the chain moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// It does not; the child frame is turned by `angle` about axis `about` (0 x, 1 y,
    /// 2 z) of the parent's.
    Fixed {
        /// The axis, 0 to 2.
        about: usize,
        /// The turn, rad.
        angle: f64,
    },
    /// It turns about `axis` (a unit axis of the parent frame: one of +-x, +-y, +-z)
    /// by `multiplier` times the paper's angle `theta[joint]`, after its origin turned
    /// `at_zero` about the same axis line (the URDF's origin rpy).
    Turns {
        /// The axis.
        axis: [f64; 3],
        /// Which of the paper's three angles drives it.
        joint: usize,
        /// 1, or -1 for a joint that undoes another (a URDF mimic).
        multiplier: f64,
        /// The origin's turn about the axis' own line (positive sense), rad.
        at_zero: f64,
    },
}

/// What a link looks like in a viewer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Visual {
    /// Its shape.
    pub shape: Shape,
    /// Its centre in the link's frame, m.
    pub at: [f64; 3],
    /// Drawn in the tool's colour rather than the arm's.
    pub tool: bool,
}

/// A link's shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A box of these sides, m.
    Box([f64; 3]),
    /// A cylinder along z: radius and length, m.
    Cylinder(f64, f64),
    /// A sphere of this radius, m.
    Sphere(f64),
}

/// One joint of an arm's chain and the link it carries.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Its name, without the arm's prefix.
    pub name: &'static str,
    /// The parent link, without the arm's prefix ([`WORLD`] for the base).
    pub parent: &'static str,
    /// The child link, without the arm's prefix.
    pub child: &'static str,
    /// The child frame's origin in the parent's, m.
    pub origin: [f64; 3],
    /// How it moves.
    pub motion: Motion,
    /// What the child link looks like, if anything.
    pub visual: Option<Visual>,
}

fn joint(
    name: &'static str,
    (parent, child): (&'static str, &'static str),
    origin: [f64; 3],
    motion: Motion,
    visual: Option<Visual>,
) -> Joint {
    Joint {
        name,
        parent,
        child,
        origin,
        motion,
        visual,
    }
}

fn looks(shape: Shape, at: [f64; 3]) -> Option<Visual> {
    Some(Visual {
        shape,
        at,
        tool: false,
    })
}

/// A joint turning about -x by the paper's angle `joint` times `multiplier`.
fn about_minus_x(joint: usize, multiplier: f64, at_zero: f64) -> Motion {
    Motion::Turns {
        axis: [-1.0, 0.0, 0.0],
        joint,
        multiplier,
        at_zero,
    }
}

/// The chain of `arm` in the paper's dimensions: its base in the world (side by
/// side, 0.4 m apart, 0.2 m up, turned so the device's y, up, is the world's z), the
/// three joints and the elbow that mimics joint 2, the tool on the forearm. The URDF,
/// the recordings' `/tf` and the live view's frames all come from this.
pub fn chain(g: &Geometry, arm: &str) -> [Joint; 6] {
    use std::f64::consts::FRAC_PI_2;
    let x = if arm == ARMS[0] { -0.2 } else { 0.2 };
    let rod = |len: f64| Shape::Cylinder(0.005, len);
    let turntable = Motion::Turns {
        axis: [0.0, -1.0, 0.0],
        joint: 0,
        multiplier: 1.0,
        at_zero: 0.0,
    };
    let tool = Some(Visual {
        shape: Shape::Sphere(0.006),
        at: [0.0; 3],
        tool: true,
    });
    [
        joint(
            "base_joint",
            (WORLD, "base"),
            [x, 0.0, 0.2],
            Motion::Fixed {
                about: 0,
                angle: FRAC_PI_2,
            },
            looks(Shape::Box([0.06, 0.01, 0.06]), [0.0, -0.005, 0.0]),
        ),
        joint(
            "joint1",
            ("base", "link1"),
            [0.0, g.l3, -(g.l1 + g.a)],
            turntable,
            looks(Shape::Cylinder(0.012, 0.02), [0.0; 3]),
        ),
        joint(
            "joint2",
            ("link1", "upper_arm"),
            [0.0; 3],
            about_minus_x(1, 1.0, 0.0),
            looks(rod(g.l1), [0.0, 0.0, g.l1 / 2.0]),
        ),
        joint(
            "elbow_joint",
            ("upper_arm", "elbow"),
            [0.0, 0.0, g.l1],
            about_minus_x(1, -1.0, 0.0),
            None,
        ),
        joint(
            "joint3",
            ("elbow", "forearm"),
            [0.0; 3],
            about_minus_x(2, 1.0, FRAC_PI_2),
            looks(rod(g.l2), [0.0, 0.0, g.l2 / 2.0]),
        ),
        joint(
            "tool_joint",
            ("forearm", "tool"),
            [0.0, 0.0, g.l2],
            Motion::Fixed {
                about: 0,
                angle: 0.0,
            },
            tool,
        ),
    ]
}

/// The rotation by `angle` about axis `k` (0 x, 1 y, 2 z), `[x, y, z, w]`.
pub fn about(k: usize, angle: f64) -> [f64; 4] {
    let mut q = [0.0, 0.0, 0.0, (angle / 2.0).cos()];
    q[k % 3] = (angle / 2.0).sin();
    q
}

/// The axis index and sense of a unit axis (components 0 or +-1).
pub fn axis_index(axis: [f64; 3]) -> (usize, f64) {
    let k = (0..3).find(|&k| axis[k] != 0.0).unwrap_or(0);
    (k, axis[k].signum())
}

impl Joint {
    /// The child frame in the parent's at the paper's angles `theta`. A turn is one
    /// rotation about its axis line, the origin's turn and the joint's added (so the
    /// angle is the paper's own expression, exactly: pi/2 - theta3 for joint 3).
    pub fn transform(&self, arm: &str, theta: [f64; 3]) -> Link {
        let rotation = match self.motion {
            Motion::Fixed { angle: 0.0, .. } => [0.0, 0.0, 0.0, 1.0],
            Motion::Fixed { about: k, angle } => about(k, angle),
            Motion::Turns {
                axis,
                joint,
                multiplier,
                at_zero,
            } => {
                let (k, sense) = axis_index(axis);
                let turn = (sense * multiplier) * theta[joint];
                about(k, if at_zero == 0.0 { turn } else { at_zero + turn })
            }
        };
        let parent = if self.parent == WORLD {
            WORLD.to_string()
        } else {
            name(arm, self.parent)
        };
        (parent, name(arm, self.child), self.origin, rotation)
    }
}

/// Where `arm`'s base stands in the world.
pub fn base_in_world(g: &Geometry, arm: &str) -> Link {
    chain(g, arm)[0].transform(arm, [0.0; 3])
}

/// The transforms that never move: the bases in the world and each tool on its
/// forearm.
pub fn fixed(g: &Geometry) -> Vec<Link> {
    fixed_of(g, &ARMS)
}

/// The transforms that never move of the arms `arms` (of [`ARMS`]).
pub fn fixed_of(g: &Geometry, arms: &[&str]) -> Vec<Link> {
    let mut v: Vec<Link> = arms.iter().map(|a| base_in_world(g, a)).collect();
    for a in arms {
        v.push(chain(g, a)[5].transform(a, [0.0; 3]));
    }
    v
}

/// The four moving transforms of `arm` at the paper's joint angles `theta`.
pub fn links(g: &Geometry, arm: &str, theta: [f64; 3]) -> [Link; 4] {
    let c = chain(g, arm);
    [1, 2, 3, 4].map(|k| c[k].transform(arm, theta))
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
