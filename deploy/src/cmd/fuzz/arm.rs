//! The targets of a URDF arm: the URDF itself (parsed, its tree, its chains, and the
//! slave's arm made from it and driven a few samples) and the map of `[slave.arm]`
//! from the master's workspace to the arm's (parsed inside a scenario, checked, then
//! applied to poses and forces). Their property is more than "no panic": whatever
//! they accept must be usable, so every value an accepted input yields is checked
//! (finite, a rotation that is one, a map that can be undone) and a value that is not
//! panics here, which the campaign counts and keeps like any other panic.

use super::targets::{outcome, Target};
use tactile_chain::{Chain, Frame, Robot, Tree};
use tactile_scenario::{ArmConfig, Scenario};
use tactile_slave::environment::Scene;
use tactile_slave::urdf_arm::UrdfArm;

const PANDA: &str = include_str!("../../../robots/panda.urdf");
const UR5: &str = include_str!("../../../robots/ur5_robot.urdf");
const OMNI: &str = include_str!("../../../devices/phantom_omni.urdf");

/// The chains the seeds have, base to tip: a mutated file that keeps the names is
/// made into the same chain.
const CHAINS: [(&str, &str); 3] = [
    ("panda_link0", "panda_hand"),
    ("base_link", "tool0"),
    ("base", "stylus"),
];

/// The master's home the arms map from (the paper device's tool at zero angles).
const MASTER_HOME: [f64; 3] = [0.0, -0.107, -0.035];

/// Panics unless every value is finite: an accepted input's value must be usable.
pub fn finite(what: &str, v: impl IntoIterator<Item = f64>) {
    let v: Vec<f64> = v.into_iter().collect();
    assert!(
        v.iter().all(|x| x.is_finite()),
        "{what} is not finite: {v:?}"
    );
}

/// Panics unless `f` is a rigid transform: finite, its rotation orthonormal.
fn frame(what: &str, f: &Frame) {
    finite(what, f.r.iter().chain(f.p.iter()).copied());
    let rtr = f.r.transpose() * f.r;
    for i in 0..3 {
        for j in 0..3 {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!(
                (rtr[(i, j)] - want).abs() < 1e-6,
                "{what}: the rotation is not one: {:?}",
                f.r
            );
        }
    }
}

/// The URDF of an arm: every file Tactile ships as its seeds.
pub fn urdf() -> Target {
    Target {
        name: "urdf",
        seeds: [PANDA, UR5, OMNI]
            .iter()
            .map(|s| s.as_bytes().to_vec())
            .collect(),
        dict: &[
            "1e308",
            "-1e308",
            "1e200",
            "1e-300",
            "0",
            "-0",
            "-1",
            "nan",
            "inf",
            "0 0 0",
            "1e200 0 0",
            "\"fixed\"",
            "\"continuous\"",
            "\"prismatic\"",
            "\"floating\"",
            "\"base\"",
            "\"tool0\"",
            "\"panda_link0\"",
            "<mimic joint=\"waist\"/>",
            "<dynamics damping=\"-5\"/>",
        ],
        run: Box::new(|b| unlisted(&urdf_run(&String::from_utf8_lossy(b)))),
    }
}

/// `text` with what it lists in parentheses left out (the links of a robot with
/// several roots, by name) and each number one `#` (`-1e0` and `0.5e-3` alike):
/// names and values are the input, not a path through the checks.
fn unlisted(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut depth = 0usize;
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        let numeric = c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e');
        // A sign or a point opens a number when a digit follows it (`-1e0`, `.5`).
        let opens = matches!(c, '.' | '-' | '+') && chars.peek().is_some_and(char::is_ascii_digit);
        match c {
            '(' => depth += 1,
            ')' if depth > 0 => depth -= 1,
            _ if depth > 0 => {}
            _ if numeric && (c.is_ascii_digit() || opens || out.ends_with('#')) => {
                if !out.ends_with('#') {
                    out.push('#');
                }
            }
            _ => out.push(c),
        }
    }
    out
}

fn urdf_run(xml: &str) -> String {
    let robot = match Robot::parse(xml) {
        Ok(r) => r,
        Err(e) => return e.to_string(),
    };
    let mut out = vec![outcome(Tree::new(&robot))];
    let mut pairs: Vec<(&str, &str)> = CHAINS.to_vec();
    // A chain between the file's first and last links reaches a mutated file's names.
    if let (Some(a), Some(b)) = (robot.links.first(), robot.links.last()) {
        pairs.push((&a.name, &b.name));
    }
    for (base, tip) in pairs {
        if robot.link(base).is_none() || robot.link(tip).is_none() {
            continue;
        }
        out.push(match Chain::new(&robot, base, tip) {
            Ok(c) => arm(xml, &c),
            Err(e) => e.to_string(),
        });
    }
    out.join(" / ")
}

/// An accepted chain checked, then the slave's arm made from it and driven a few
/// samples towards a moved and turned target.
fn arm(xml: &str, chain: &Chain) -> String {
    chain_values(chain);
    let home: Vec<f64> = chain
        .dofs
        .iter()
        .map(|d| 0f64.clamp(d.lower, d.upper))
        .collect();
    frame("the tool at home", &chain.fk(&home));
    let n = home.len();
    let cfg = ArmConfig {
        urdf: "fuzz.urdf".into(),
        base: chain.base.clone(),
        tip: chain.tip.clone(),
        home,
        kp: vec![100.0; n],
        kd: vec![10.0; n],
        scale: Default::default(),
        rotation: Default::default(),
        workspace: None,
        force_scale: 1.0,
        step_s: 2.5e-4,
        gravity: [0.0, 0.0, -9.81],
        ik: Default::default(),
        servo: Default::default(),
        cartesian: Default::default(),
    };
    let mut a = match UrdfArm::new(&cfg, xml, MASTER_HOME) {
        Ok(a) => a,
        Err(e) => return e,
    };
    for d in &a.chain().dofs {
        let e = d.effort;
        assert!(
            e > 0.0 && e.is_finite(),
            "an arm simulated with joint {}'s effort {e}",
            d.name
        );
    }
    let scene = Scene::new(&[]);
    let turn = [0.0, 0.0, 0.1f64.sin(), 0.1f64.cos()];
    for k in 0..3 {
        let p = [0, 1, 2].map(|i| MASTER_HOME[i] + 0.002 * f64::from(k + i as i32));
        let f = a.follow(p, Some(turn), 1e-3);
        a.advance(1e-3, tactile_slave::world::Touch::Scene(&scene));
        let s = a.state();
        finite(
            "the arm's state",
            s.q.iter().chain(&s.qd).chain(&s.tau).copied(),
        );
        finite("the tool", a.tool());
        if f.refused {
            return "ik refused".into();
        }
    }
    "arm ok".into()
}

/// What the chain holds is what the dynamics and the IK take as given.
fn chain_values(c: &Chain) {
    for j in &c.joints {
        frame(&format!("joint {}'s origin", j.name), &j.origin);
        finite(&format!("joint {}'s axis", j.name), j.axis.iter().copied());
        assert!(
            (j.axis.norm() - 1.0).abs() < 1e-9,
            "joint {}'s axis is not a unit vector: {:?}",
            j.name,
            j.axis
        );
        finite(
            &format!("joint {}'s mimic", j.name),
            [j.multiplier, j.offset],
        );
        finite(&format!("joint {}'s body", j.name), j.body.iter().copied());
    }
    for d in &c.dofs {
        assert!(
            d.lower <= d.upper,
            "joint {}: limits {} > {}",
            d.name,
            d.lower,
            d.upper
        );
        assert!(
            d.velocity > 0.0,
            "joint {}: velocity {}",
            d.name,
            d.velocity
        );
        // Zero or none is the URDF's "not given": a chain takes it (a passive
        // gimbal's), the dynamics do not (checked once the arm is made).
        assert!(d.effort >= 0.0, "joint {}: effort {}", d.name, d.effort);
        assert!(
            d.damping.is_finite() && d.damping >= 0.0,
            "joint {}: damping {}",
            d.name,
            d.damping
        );
    }
    frame("the tip's frame", &c.tip_frame);
}

/// A shipped scenario cut around its `[slave.arm]` table: the text before, the table
/// (up to the next table that is not one of its own), the text after.
fn split_arm(text: &str) -> Option<(&str, &str, &str)> {
    let start = text.find("\n[slave.arm]")? + 1;
    let rest = &text[start..];
    let end = rest
        .match_indices("\n[")
        .map(|(k, _)| k + 1)
        .find(|&k| !rest[k..].starts_with("[slave.arm."))
        .unwrap_or(rest.len());
    Some((&text[..start], &rest[..end], &rest[end..]))
}

/// The map of `[slave.arm]`: the table fuzzed inside the Panda's 6-DoF scenario,
/// seeded with the tables of every shipped arm scenario and two that use the forms
/// they do not (a quaternion, a scale per axis).
pub fn map() -> Result<Target, String> {
    let reach = include_str!("../../../scenarios/panda-reach.toml");
    let (before, _, after) = split_arm(reach).ok_or("panda-reach.toml has no [slave.arm]")?;
    let mut seeds: Vec<Vec<u8>> = [
        reach,
        include_str!("../../../scenarios/panda.toml"),
        include_str!("../../../scenarios/panda-pose.toml"),
        include_str!("../../../scenarios/ur5.toml"),
    ]
    .iter()
    .filter_map(|s| split_arm(s))
    .map(|(_, t, _)| t.as_bytes().to_vec())
    .collect();
    let first = String::from_utf8_lossy(&seeds[0]).into_owned();
    seeds.push(
        first
            .replace(
                "{ rpy_deg = [90.0, 0.0, -90.0] }",
                "{ quaternion = [0.5, -0.5, -0.5, 0.5] }",
            )
            .replace("scale = 1.5", "scale = [1.5, 2.0, 0.5]")
            .into_bytes(),
    );
    let (before, after) = (before.to_string(), after.to_string());
    Ok(Target {
        name: "map",
        seeds,
        dict: &[
            "1e308",
            "-1e308",
            "1e-300",
            "5e-324",
            "0.0",
            "-0.0",
            "100.0",
            "100.000001",
            "360.0",
            "-360.0",
            "nan",
            "inf",
            "[1e-300, 1.0, 1.0]",
            "[0.0, 0.0, 0.0, 1.0]",
            "[0.0, 0.0, 0.0, 1.0005]",
            "{ rpy_deg = [360.0, -360.0, 180.0] }",
        ],
        run: Box::new(move |b| {
            let text = format!("{before}{}\n{after}", String::from_utf8_lossy(b));
            match Scenario::from_toml_str(&text) {
                Ok(sc) => sc.slave.arm.as_ref().map_or("no arm".into(), map_applied),
                Err(e) => e.to_string(),
            }
        }),
    })
}

/// An accepted map applied to the poses and forces of a run: every value finite, the
/// map undone to the master's precision, a force's size kept (then scaled), the
/// rotation a rotation; then the Panda's or UR5's arm made with it, its targets too.
fn map_applied(cfg: &ArmConfig) -> String {
    let tool = [0.3, -0.1, 0.5];
    let r = cfg.rotation.quaternion();
    let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!((norm - 1.0).abs() < 1e-9, "the rotation's quaternion {r:?}");
    frame(
        "the map's rotation",
        &Frame {
            r: tactile_slave::urdf_arm::rotation_matrix(r),
            p: Default::default(),
        },
    );
    for d in [[0.0; 3], [0.08, -0.06, 0.035], [-0.2, 0.2, -0.2]] {
        let p = [0, 1, 2].map(|k| MASTER_HOME[k] + d[k]);
        let to = cfg.to_robot(tool, MASTER_HOME, p);
        finite("a target", to);
        finite("a target in the box", cfg.clamp(to).0);
        let back = cfg.to_master(tool, MASTER_HOME, to);
        let err = (0..3).map(|k| (back[k] - p[k]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-6, "{p:?} mapped to {to:?} and back to {back:?}");
        let f = [d[0] * 1e3, d[1] * 1e3, d[2] * 1e3];
        let felt = cfg.force_to_master(f);
        let size = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let want = cfg.force_scale * size(f);
        assert!(
            (size(felt) - want).abs() <= 1e-9 * (1.0 + want),
            "force {f:?} felt as {felt:?}"
        );
        assert!((size(cfg.force_to_robot(f)) - size(f)).abs() <= 1e-9 * (1.0 + size(f)));
    }
    let xml = match cfg.urdf.rsplit('/').next() {
        Some("panda.urdf") => PANDA,
        Some("ur5_robot.urdf") => UR5,
        _ => return "map ok".into(),
    };
    let a = match UrdfArm::new(cfg, xml, MASTER_HOME) {
        Ok(a) => a,
        Err(e) => return e,
    };
    let turn = [0.0, 0.2f64.sin(), 0.0, 0.2f64.cos()];
    for d in [0.0, 0.05, -0.3] {
        let (t, _) = a.target(
            [MASTER_HOME[0] + d, MASTER_HOME[1], MASTER_HOME[2] - d],
            Some(turn),
        );
        frame("an arm's target", &t);
        if let Some(w) = &cfg.workspace {
            assert!(
                !w.clamp(t.p.into()).1,
                "a target outside the box: {:?}",
                t.p
            );
        }
    }
    finite("a force felt", a.felt([10.0, -5.0, 1.0]));
    "arm ok".into()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_arm_table_is_cut_out_with_its_own_tables() {
        let text =
            "a = 1\n[slave.arm]\nx = 1\n[slave.arm.ik]\ny = 2\n[[environment.objects]]\nz = 3\n";
        let (b, t, a) = split_arm(text).expect("has one");
        assert_eq!(b, "a = 1\n");
        assert_eq!(t, "[slave.arm]\nx = 1\n[slave.arm.ik]\ny = 2\n");
        assert_eq!(a, "[[environment.objects]]\nz = 3\n");
    }

    #[test]
    fn listed_names_are_left_out() {
        assert_eq!(
            unlisted("robot `r`: 2 links are no joint's child (a, b(c)): a robot has one root"),
            "robot `r`: # links are no joint's child : a robot has one root"
        );
        assert_eq!(
            unlisted("moments -1e0, 0.5e-3 kg"),
            unlisted("moments 2, 3 kg")
        );
    }

    /// The checks are not vacuous: a value that is not usable panics.
    #[test]
    fn unusable_values_panic() {
        let caught = |f: fn()| std::panic::catch_unwind(f).is_err();
        assert!(caught(|| finite("x", [1.0, f64::NAN])));
        assert!(caught(|| frame(
            "f",
            &Frame {
                r: Frame::IDENTITY.r * 2.0,
                p: Default::default()
            }
        )));
        assert!(!caught(|| frame("f", &Frame::IDENTITY)));
    }
}
