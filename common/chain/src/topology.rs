//! A URDF robot's links and joints indexed by name once, and checked to form one tree
//! (urdfdom's `initTree` and `initRoot`): every joint joins two declared links, no link
//! is the child of two joints, one link is no joint's child (the root) and every link
//! hangs from it (no cycle). The chain and the tree look links up here, so reading a
//! robot costs one pass over its elements however many links it has.

use crate::error::Error;
use crate::urdf::{Joint, Link, Robot};
use std::collections::{HashMap, HashSet};
use tactile_math::shown::listed;

/// A robot's links and joints by name, checked to be a tree.
#[derive(Debug, Clone)]
pub struct Index<'a> {
    robot: &'a Robot,
    links: HashMap<&'a str, &'a Link>,
    /// Each link's parent joint (the root has none).
    parent: HashMap<&'a str, &'a Joint>,
    /// Each link's child joints, in file order.
    children: HashMap<&'a str, Vec<&'a Joint>>,
    /// The link no joint has as its child.
    root: &'a str,
}

fn tree_error(robot: &Robot, problem: String) -> Error {
    Error::Xml(format!("robot `{}`: {problem}", robot.name))
}

/// The links of the cycle that climbing from `start` goes round, as `a -> b -> a`
/// (empty if the climb reaches a link without a parent).
fn cycle(parent: &HashMap<&str, &Joint>, start: &str) -> String {
    let mut order: HashMap<&str, usize> = HashMap::new();
    let mut path = Vec::new();
    let mut at = start;
    while let Some(j) = parent.get(at) {
        if let Some(&i) = order.get(at) {
            let mut links: Vec<&str> = path[i..].to_vec();
            links.push(at);
            links.reverse();
            return listed(links).replace(", ", " -> ");
        }
        order.insert(at, path.len());
        path.push(at);
        at = &j.parent;
    }
    String::new()
}

impl<'a> Index<'a> {
    /// The index of `robot`, or what keeps it from being one tree, named.
    pub fn new(robot: &'a Robot) -> Result<Index<'a>, Error> {
        let err = |p: String| tree_error(robot, p);
        let mut links = HashMap::with_capacity(robot.links.len());
        for l in &robot.links {
            if links.insert(l.name.as_str(), l).is_some() {
                return Err(err(format!("two links are called `{}`", l.name)));
            }
        }
        let mut names = HashMap::with_capacity(robot.joints.len());
        let mut parent = HashMap::with_capacity(robot.joints.len());
        let mut children: HashMap<&str, Vec<&Joint>> = HashMap::new();
        for j in &robot.joints {
            if names.insert(j.name.as_str(), ()).is_some() {
                return Err(err(format!("two joints are called `{}`", j.name)));
            }
            for (role, l) in [("parent", &j.parent), ("child", &j.child)] {
                if !links.contains_key(l.as_str()) {
                    return Err(err(format!(
                        "joint `{}`: {role} link `{l}` is not a <link> of the robot",
                        j.name
                    )));
                }
            }
            if let Some(first) = parent.insert(j.child.as_str(), j) {
                return Err(err(format!(
                    "link `{}` is the child of two joints (`{}` and `{}`)",
                    j.child, first.name, j.name
                )));
            }
            children.entry(j.parent.as_str()).or_default().push(j);
        }
        let roots: Vec<&str> = robot
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|l| !parent.contains_key(l))
            .collect();
        if roots.is_empty() {
            // Every link has a parent: climbing from any of them goes round a cycle.
            let any = robot.links.first().map_or("", |l| l.name.as_str());
            return Err(err(format!(
                "every link is a joint's child, so none is the root: its joints form a cycle ({})",
                cycle(&parent, any)
            )));
        }
        let [root] = roots[..] else {
            return Err(err(format!(
                "{} links are no joint's child ({}): a robot has one root",
                roots.len(),
                listed(roots.iter().copied())
            )));
        };
        let index = Index {
            robot,
            links,
            parent,
            children,
            root,
        };
        index.check_reachable()?;
        Ok(index)
    }

    /// Every link hangs from the root: one that does not has a parent (only the root
    /// has none), and so has its parent, so climbing from it goes round a cycle.
    fn check_reachable(&self) -> Result<(), Error> {
        let mut reached: HashSet<&str> = HashSet::with_capacity(self.links.len());
        reached.insert(self.root);
        let mut todo = vec![self.root];
        while let Some(l) = todo.pop() {
            for j in self.children_of(l) {
                if reached.insert(&j.child) {
                    todo.push(&j.child);
                }
            }
        }
        match self
            .robot
            .links
            .iter()
            .find(|l| !reached.contains(l.name.as_str()))
        {
            None => Ok(()),
            Some(l) => Err(tree_error(
                self.robot,
                format!(
                    "link `{}` does not hang from the root `{}`: its joints form a cycle ({})",
                    l.name,
                    self.root,
                    cycle(&self.parent, &l.name)
                ),
            )),
        }
    }

    /// The robot.
    pub fn robot(&self) -> &'a Robot {
        self.robot
    }

    /// The root link.
    pub fn root(&self) -> &'a str {
        self.root
    }

    /// The link called `name`.
    pub fn link(&self, name: &str) -> Option<&'a Link> {
        self.links.get(name).copied()
    }

    /// The joint whose child is `link` (none for the root).
    pub fn parent_joint(&self, link: &str) -> Option<&'a Joint> {
        self.parent.get(link).copied()
    }

    /// The joints whose parent is `link`, in file order.
    pub fn children_of(&self, link: &str) -> impl Iterator<Item = &'a Joint> + '_ {
        self.children.get(link).into_iter().flatten().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot(joints: &[(&str, &str, &str)], links: &[&str]) -> String {
        let mut s = String::from("<robot name=\"r\">");
        for l in links {
            s += &format!("<link name=\"{l}\"/>");
        }
        for (j, p, c) in joints {
            s += &format!("<joint name=\"{j}\" type=\"fixed\"><parent link=\"{p}\"/><child link=\"{c}\"/></joint>");
        }
        s + "</robot>"
    }

    fn refused(xml: &str) -> String {
        let r = Robot::parse(xml).expect("parses");
        Index::new(&r).expect_err("refused").to_string()
    }

    #[test]
    fn a_tree_is_indexed_by_name() {
        let xml = robot(
            &[("j1", "a", "b"), ("j2", "b", "c"), ("j3", "b", "d")],
            &["a", "b", "c", "d"],
        );
        let r = Robot::parse(&xml).expect("parses");
        let i = Index::new(&r).expect("a tree");
        assert_eq!(i.root(), "a");
        assert_eq!(i.parent_joint("c").map(|j| j.name.as_str()), Some("j2"));
        let kids: Vec<&str> = i.children_of("b").map(|j| j.name.as_str()).collect();
        assert_eq!(kids, ["j2", "j3"]);
        assert!(i.link("d").is_some() && i.link("e").is_none());
    }

    #[test]
    fn a_cycle_through_the_tool_back_to_the_base_is_refused_and_named() {
        // The tool fixed back to the base: no link is left without a parent.
        let e = refused(&robot(
            &[("j1", "base", "tool"), ("back", "tool", "base")],
            &["base", "tool"],
        ));
        assert!(
            e.contains("none is the root: its joints form a cycle (base -> tool -> base)"),
            "{e}"
        );
        // A root beside a cycle: the cycle's links do not hang from it.
        let e = refused(&robot(
            &[("j1", "root", "x"), ("j2", "a", "b"), ("j3", "b", "a")],
            &["root", "x", "a", "b"],
        ));
        assert!(
            e.contains("link `a` does not hang from the root `root`"),
            "{e}"
        );
        assert!(
            e.contains("a -> b -> a") || e.contains("b -> a -> b"),
            "{e}"
        );
    }

    #[test]
    fn two_parents_two_roots_and_unknown_links_are_named() {
        let e = refused(&robot(
            &[("j1", "a", "c"), ("j2", "b", "c")],
            &["a", "b", "c"],
        ));
        assert!(
            e.contains("link `c` is the child of two joints (`j1` and `j2`)"),
            "{e}"
        );
        let e = refused(&robot(&[("j1", "a", "b")], &["a", "b", "c"]));
        assert!(e.contains("2 links are no joint's child (a, c)"), "{e}");
        let e = refused(&robot(&[("j1", "a", "ghost")], &["a"]));
        assert!(
            e.contains("joint `j1`: child link `ghost` is not a <link>"),
            "{e}"
        );
        let e = refused(&robot(&[], &["a", "a"]));
        assert!(e.contains("two links are called `a`"), "{e}");
        let e = refused(&robot(
            &[("j", "a", "b"), ("j", "b", "c")],
            &["a", "b", "c"],
        ));
        assert!(e.contains("two joints are called `j`"), "{e}");
    }

    #[test]
    fn a_long_list_of_names_is_cut() {
        let links: Vec<String> = (0..20).map(|i| format!("l{i}")).collect();
        let refs: Vec<&str> = links.iter().map(String::as_str).collect();
        let e = refused(&robot(&[], &refs));
        assert!(e.contains("l9, ... and 10 more"), "{e}");
        assert!(!e.contains("l10"), "{e}");
    }

    /// A one-joint arm with `n` fixed links hanging below its tool, each with mass.
    fn tail(n: usize) -> String {
        let mut s = String::from(
            r#"<robot name="tail"><link name="base"/><link name="tool"/>
            <joint name="j" type="revolute"><parent link="base"/><child link="tool"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>"#,
        );
        let mut parent = "tool".to_string();
        for i in 0..n {
            s += &format!(
                r#"<link name="l{i}"><inertial><mass value="0.001"/><inertia ixx="1e-6" iyy="1e-6" izz="1e-6"/></inertial></link>
                <joint name="f{i}" type="fixed"><parent link="{parent}"/><child link="l{i}"/><origin xyz="0 0 0.001"/></joint>"#
            );
            parent = format!("l{i}");
        }
        s + "</robot>"
    }

    /// The fastest of three loads of `xml`, s.
    fn load_s(xml: &str) -> f64 {
        (0..3)
            .map(|_| {
                let t = std::time::Instant::now();
                let c = crate::Chain::from_urdf(xml, "base", "tool").expect("loads");
                assert_eq!(c.dof(), 1);
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Issue 51: 40,000 fixed links below the tool took 19 s, 150,000 took 333 s (each
    /// link's children were found by a scan of every joint). Ten times the links must
    /// cost about ten times the time, not a hundred.
    #[test]
    fn loading_is_linear_in_the_links() {
        let small = load_s(&tail(10_000));
        let large = load_s(&tail(100_000));
        eprintln!("10,000 links: {small:.3} s, 100,000: {large:.3} s");
        assert!(
            large < 30.0 * small,
            "10,000 links: {small} s, 100,000: {large} s"
        );
    }
}
