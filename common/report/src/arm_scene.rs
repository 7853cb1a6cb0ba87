//! A URDF slave arm as a recording draws it (`[slave.arm]`): one `/robot_description`
//! holding the master (the paper's arm) and the robot's own links and joints as its
//! file writes them, the robot standing upright where the paper's slave stands, every
//! joint on `/tf` or `/tf_static` as `robot_state_publisher` would put it, and the
//! loop's positions (tool, environment) taken into the robot's base frame by the
//! loop's own map ([`tactile_scenario::ArmConfig::to_robot`]), so a viewer shows the
//! arm touching what it touched.

use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use tactile_chain::{urdf, Chain, Frame, Robot, Tree};
use tactile_math::arith::StdTrig;
use tactile_math::geometry::Geometry;
use tactile_math::kernels;
use tactile_ros::arm::{self, Link, WORLD};
use tactile_scenario::{ArmConfig, Object, Scenario};

/// The joint that stands the robot in the world.
pub const MOUNT: &str = "slave_mount";

/// Why the scenario's arm cannot be drawn: its file, its geometry, or the robot in it.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The URDF file could not be read or parsed.
    #[error("slave.arm: {0}")]
    Read(#[from] tactile_chain::file::ReadError),
    /// The master's geometry (the device) is not one the scenario can have.
    #[error(transparent)]
    Geometry(#[from] tactile_scenario::ScenarioError),
    /// The file was read, but its robot cannot be drawn.
    #[error("slave.arm: {}: {source}", path.display())]
    Robot {
        /// The URDF file.
        path: std::path::PathBuf,
        /// Why its robot cannot be drawn.
        source: RobotError,
    },
}

/// Why a robot (a URDF's text and model) cannot be drawn beside the master.
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// The URDF, the chain asked for or its tree is wrong.
    #[error(transparent)]
    Urdf(#[from] tactile_chain::Error),
    /// The robot names a link or joint the master's drawing names too.
    #[error("the URDF names `{0}`, as the master's drawing does: rename it")]
    Clash(String),
}

/// A URDF arm, for drawing.
#[derive(Debug, Clone)]
pub struct ArmScene {
    description: String,
    tree: Tree,
    /// The chain's joint names, in the order of the recorded joint values.
    pub names: Vec<String>,
    /// The base link: the frame of the tool, the force and the environment.
    pub base: String,
    cfg: ArmConfig,
    home_tool: [f64; 3],
    master_home: [f64; 3],
    /// The robot's root in the world (None when the URDF's root is the world itself).
    mount: Option<Frame>,
}

impl ArmScene {
    /// The scenario's arm, its URDF read; None for the paper's arm.
    pub fn of_scenario(scenario: &Scenario) -> Result<Option<ArmScene>, SceneError> {
        let Some(cfg) = &scenario.slave.arm else {
            return Ok(None);
        };
        // The nodes' one reader of a URDF: the same cap and messages.
        let urdf = tactile_chain::file::read(std::path::Path::new(&cfg.urdf))?;
        let g = scenario.device.geometry()?;
        ArmScene::of_robot(cfg, &urdf.text, &urdf.robot, &g)
            .map(Some)
            .map_err(|source| SceneError::Robot {
                path: urdf.path,
                source,
            })
    }

    /// The arm of `cfg` from its URDF text `xml`, beside the master of geometry `g`.
    pub fn new(cfg: &ArmConfig, xml: &str, g: &Geometry) -> Result<ArmScene, RobotError> {
        let robot = Robot::parse(xml)?;
        ArmScene::of_robot(cfg, xml, &robot, g)
    }

    /// The arm of `cfg` from its URDF's text `xml` and its model `robot` (parsed
    /// once), beside the master of geometry `g`.
    pub fn of_robot(
        cfg: &ArmConfig,
        xml: &str,
        robot: &Robot,
        g: &Geometry,
    ) -> Result<ArmScene, RobotError> {
        let chain = Chain::new(robot, &cfg.base, &cfg.tip)?;
        let tree = Tree::new(robot)?;
        let names: Vec<String> = chain.dofs.iter().map(|d| d.name.clone()).collect();
        let home_tool = chain.fk(&cfg.home).p.into();
        let master_home = kernels::fk(&g.lengths(), &StdTrig, [0.0; 3]);
        let mut description = tactile_ros::urdf::urdf_open(g, &["master"]);
        let ours = names_in(&robot_of(&description)?);
        let theirs = names_in(robot);
        if let Some(clash) = theirs.iter().find(|n| *n != WORLD && ours.contains(n)) {
            return Err(RobotError::Clash(clash.clone()));
        }
        for e in urdf::elements(xml, &["material", "link", "joint"])? {
            if tree.root == WORLD && e.starts_with("<link") && names_in_element(e) == WORLD {
                continue; // the robot's world is the drawing's
            }
            description.push_str("  ");
            description.push_str(e);
            description.push('\n');
        }
        let mount = (tree.root != WORLD).then(|| mount(g, &tree, &chain, cfg));
        if let Some(m) = &mount {
            let (xyz, rpy) = xyz_rpy(m);
            description.push_str(&format!(
                "  <joint name=\"{MOUNT}\" type=\"fixed\">\n    <parent link=\"{WORLD}\"/>\n    \
                 <child link=\"{}\"/>\n    <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>\n  </joint>\n",
                tree.root, xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]
            ));
        }
        description.push_str("</robot>\n");
        Ok(ArmScene {
            description,
            tree,
            names,
            base: cfg.base.clone(),
            cfg: cfg.clone(),
            home_tool,
            master_home,
            mount,
        })
    }

    /// `/robot_description`: the master and the robot.
    pub fn description(&self) -> &str {
        &self.description
    }

    /// `/tf_static`: the robot in the world, its fixed joints.
    pub fn fixed(&self) -> Vec<Link> {
        let mut v: Vec<Link> = self
            .mount
            .iter()
            .map(|m| link(WORLD, &self.tree.root, m))
            .collect();
        v.extend(self.tree.fixed().map(|(p, c, f)| link(p, c, &f)));
        v
    }

    /// `/tf`: every moving joint at the chain's values `q` (the others at rest).
    pub fn links(&self, q: &[f64]) -> Vec<Link> {
        let value = |name: &str| self.names.iter().position(|n| n == name).map(|k| q[k]);
        self.tree
            .moving(&value)
            .map(|(p, c, f)| link(p, c, &f))
            .collect()
    }

    /// A point of the loop (the master's frame) in the robot's base frame.
    pub fn to_robot(&self, p: [f64; 3]) -> [f64; 3] {
        self.cfg.to_robot(self.home_tool, self.master_home, p)
    }

    /// An environment object of the loop as the robot meets it: placed by the map,
    /// sized by its scale. A box is drawn as the box of the base's axes around its map (the map itself,
    /// for rotations by quarter turns), a sphere with the scales' geometric mean.
    pub fn object(&self, o: &Object) -> Object {
        let scale = self.cfg.scale.axes();
        let s = scale.iter().product::<f64>().cbrt();
        let s = match self.cfg.scale {
            tactile_scenario::Scale::Uniform(u) => u,
            tactile_scenario::Scale::PerAxis(_) => s,
        };
        let r = self.cfg.rotation.matrix();
        match o.clone() {
            Object::Sphere {
                center,
                radius,
                stiffness,
            } => Object::Sphere {
                center: self.to_robot(center),
                radius: radius * s,
                stiffness,
            },
            Object::Box {
                center,
                half_extents,
                stiffness,
            } => Object::Box {
                center: self.to_robot(center),
                half_extents: [0, 1, 2].map(|k| {
                    (0..3).map(|j| r[k][j].abs() * half_extents[j]).sum::<f64>() * scale[k]
                }),
                stiffness,
            },
            Object::Plane {
                point,
                normal,
                stiffness,
            } => Object::Plane {
                point: self.to_robot(point),
                normal: self.normal(normal),
                stiffness,
            },
        }
    }

    /// A plane's normal as the map carries it: `S^-1 R n`, normalized (untouched by the
    /// identity and a uniform scale).
    fn normal(&self, n: [f64; 3]) -> [f64; 3] {
        if self.cfg.rotation.is_identity()
            && matches!(self.cfg.scale, tactile_scenario::Scale::Uniform(_))
        {
            return n;
        }
        let s = self.cfg.scale.axes();
        let m = tactile_scenario::workspace::apply(&self.cfg.rotation.matrix(), n);
        let v = [0, 1, 2].map(|k| m[k] / s[k]);
        let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v.map(|x| x / len)
    }
}

fn robot_of(open: &str) -> Result<Robot, tactile_chain::Error> {
    Robot::parse(&format!("{open}</robot>"))
}

/// Every link and joint name of `robot`.
fn names_in(robot: &Robot) -> Vec<String> {
    let links = robot.links.iter().map(|l| l.name.clone());
    links
        .chain(robot.joints.iter().map(|j| j.name.clone()))
        .collect()
}

/// The `name` attribute of an element's text.
fn names_in_element(e: &str) -> &str {
    e.split("name=\"")
        .nth(1)
        .and_then(|r| r.split('"').next())
        .unwrap_or_default()
}

/// The robot's root in the world: upright (its base's axes the world's), its base
/// where the paper's slave base stands.
fn mount(g: &Geometry, tree: &Tree, chain: &Chain, cfg: &ArmConfig) -> Frame {
    let home = |name: &str| {
        chain
            .dofs
            .iter()
            .position(|d| d.name == name)
            .map(|k| cfg.home[k])
    };
    let base_in_root = tree.pose(&cfg.base, &home).unwrap_or(Frame::IDENTITY);
    let (_, _, at, _) = arm::base_in_world(g, "slave");
    Frame::translation(Vector3::from(at)).then(&base_in_root.inverse())
}

fn quaternion(f: &Frame) -> [f64; 4] {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(f.r));
    [q.i, q.j, q.k, q.w]
}

fn xyz_rpy(f: &Frame) -> ([f64; 3], [f64; 3]) {
    let (r, p, y) = Rotation3::from_matrix_unchecked(f.r).euler_angles();
    (f.p.into(), [r, p, y])
}

fn link(parent: &str, child: &str, f: &Frame) -> Link {
    (
        parent.to_string(),
        child.to_string(),
        f.p.into(),
        quaternion(f),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const PANDA: &str = include_str!("../../../deploy/robots/panda.urdf");

    /// The shipped Panda scenario's arm, at `scale`.
    fn cfg(scale: f64) -> ArmConfig {
        let text = include_str!("../../../deploy/scenarios/panda.toml");
        let s = Scenario::from_toml_str(text).expect("the shipped scenario");
        ArmConfig {
            scale: tactile_scenario::Scale::Uniform(scale),
            ..s.slave.arm.expect("an arm")
        }
    }

    #[test]
    fn the_robot_stands_upright_where_the_papers_slave_stands() {
        let g = Geometry::PAPER;
        let s = ArmScene::new(&cfg(1.0), PANDA, &g).expect("scene");
        let fixed = s.fixed();
        let (parent, child, at, rotation) = &fixed[0];
        assert_eq!((parent.as_str(), child.as_str()), (WORLD, "panda_link0"));
        assert_eq!(*at, arm::base_in_world(&g, "slave").2);
        assert_eq!(*rotation, [0.0, 0.0, 0.0, 1.0]);
        assert!(s
            .description()
            .contains("<joint name=\"slave_mount\" type=\"fixed\">"));
        assert!(s.description().contains("<link name=\"master_tool\">"));
        assert!(!s.description().contains("slave_tool"));
        // Every moving joint of the Panda, fingers too, is on /tf.
        assert_eq!(s.links(&cfg(1.0).home).len(), 9);
    }

    #[test]
    fn the_environment_meets_the_robot_where_the_loop_puts_it() {
        let g = Geometry::PAPER;
        let s = ArmScene::new(&cfg(2.0), PANDA, &g).expect("scene");
        let master_home = kernels::fk(&g.lengths(), &StdTrig, [0.0; 3]);
        let ball = Object::Sphere {
            center: [master_home[0], master_home[1], master_home[2] - 0.01],
            radius: 0.02,
            stiffness: [500.0; 3],
        };
        let Object::Sphere { center, radius, .. } = s.object(&ball) else {
            panic!("a sphere stays a sphere");
        };
        // Twice the displacement and the size: the tool meets it where the loop's does.
        let tool = s.to_robot(master_home);
        assert!((center[2] - (tool[2] - 0.02)).abs() < 1e-12);
        assert_eq!(radius, 0.04);
    }

    #[test]
    fn a_urdf_naming_a_master_link_is_refused() {
        let clash = PANDA.replace("panda_link3", "master_base");
        let e = ArmScene::new(&cfg(1.0), &clash, &Geometry::PAPER).expect_err("clash");
        assert!(e.to_string().contains("`master_base`"), "{e}");
    }

    #[test]
    fn a_scene_error_keeps_the_urdf_fault_as_its_source() {
        use std::error::Error as _;
        let broken = &PANDA[..PANDA.len() / 2];
        let e = ArmScene::new(&cfg(1.0), broken, &Geometry::PAPER).expect_err("bad XML");
        assert!(
            matches!(e, RobotError::Urdf(tactile_chain::Error::Xml(_))),
            "{e:?}"
        );
        let e = SceneError::Robot {
            path: "panda.urdf".into(),
            source: e,
        };
        let cause = e.source().expect("the robot's fault");
        assert!(cause.downcast_ref::<RobotError>().is_some(), "{cause:?}");
        assert_eq!(e.to_string(), format!("slave.arm: panda.urdf: {cause}"));
    }

    #[test]
    fn a_missing_urdf_is_named_with_its_read_error_as_source() {
        use std::error::Error as _;
        let text = include_str!("../../../deploy/scenarios/panda.toml");
        let mut s = Scenario::from_toml_str(text).expect("the shipped scenario");
        if let Some(arm) = s.slave.arm.as_mut() {
            arm.urdf = "/nonexistent/robot.urdf".into();
        }
        let e = ArmScene::of_scenario(&s).expect_err("no file");
        assert!(
            e.to_string().starts_with("slave.arm: cannot read URDF"),
            "{e}"
        );
        let cause = e.source().expect("the read error");
        assert!(cause
            .downcast_ref::<tactile_chain::file::ReadError>()
            .is_some());
        assert!(cause.source().is_some(), "the I/O error under it");
    }

    #[test]
    fn a_robot_rooted_in_the_world_keeps_its_own_placement() {
        let xml = PANDA.replacen(
            "<link name=\"panda_link0\"",
            "<link name=\"world\"/>\n  <joint name=\"fix\" type=\"fixed\"><parent link=\"world\"/><child link=\"panda_link0\"/><origin xyz=\"1 2 0\"/></joint>\n  <link name=\"panda_link0\"",
            1,
        );
        let s = ArmScene::new(&cfg(1.0), &xml, &Geometry::PAPER).expect("scene");
        assert!(!s.description().contains(MOUNT));
        assert_eq!(s.description().matches("<link name=\"world\"").count(), 1);
        let fixed = s.fixed();
        assert!(fixed
            .iter()
            .any(|(p, c, at, _)| p == WORLD && c == "panda_link0" && *at == [1.0, 2.0, 0.0]));
    }
}
