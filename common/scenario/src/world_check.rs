//! The checks of the physics world's keys that need no file: every number finite and
//! in range, names unique and known, limits in order. Each error names the field
//! (`environment.bodies[2].mass`) and says what is wrong with the value.

use crate::shown::Num;
use crate::world::{BodyConfig, BodyKind, Engine, JointConfig, JointKind, Shape, ToolConfig};
use crate::{finite3, invalid, Environment, ScenarioError, TaskConfig, TOOL_BODY};

/// Most bodies and most joints a world holds: a bound on what a scenario can make the
/// slave allocate (a body costs a few kB in rapier).
pub const MAX_BODIES: usize = 1000;
/// Most points of a `convex_hull` written in the scenario.
pub const MAX_HULL_POINTS: usize = 10_000;
/// Largest size of a shape and farthest position, m.
pub const MAX_SIZE_M: f64 = 100.0;

/// A finite value in `[lo, hi]` (`lo` itself allowed only with `lo_ok`).
fn within(v: f64, field: &str, lo: f64, hi: f64, lo_ok: bool) -> Result<(), ScenarioError> {
    let low = if lo_ok { v >= lo } else { v > lo };
    if !v.is_finite() || !low || v > hi {
        let from = if lo_ok { "from" } else { "above" };
        return Err(invalid(
            field,
            format!("{} must be {from} {} up to {}", Num(v), Num(lo), Num(hi)),
        ));
    }
    Ok(())
}

/// A count of steps or iterations: 1 to 64.
fn count(n: u32, field: &str) -> Result<(), ScenarioError> {
    if !(1..=64).contains(&n) {
        return Err(invalid(field, format!("{n} is outside 1 to 64")));
    }
    Ok(())
}

/// A length: positive, finite, at most [`MAX_SIZE_M`].
fn length(v: f64, field: &str) -> Result<(), ScenarioError> {
    within(v, field, 0.0, MAX_SIZE_M, false)
}

/// A quaternion `[x, y, z, w]` that can be normalised.
pub(crate) fn quaternion(q: &[f64; 4], field: &str) -> Result<(), ScenarioError> {
    if let Some(i) = q.iter().position(|v| !v.is_finite() || v.abs() > 1e6) {
        return Err(invalid(
            format!("{field}[{i}]"),
            format!("{} is not a finite quaternion component", Num(q[i])),
        ));
    }
    if q.iter().map(|v| v * v).sum::<f64>() < 1e-12 {
        return Err(invalid(
            field,
            "is zero: not a rotation ([0, 0, 0, 1] is none)",
        ));
    }
    Ok(())
}

/// A direction that can be normalised.
pub(crate) fn direction(v: &[f64; 3], field: &str) -> Result<(), ScenarioError> {
    finite3(v, field)?;
    let big = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(1e-9..=1e6).contains(&big) {
        return Err(invalid(
            field,
            "must be a direction: not zero, components at most 1e6",
        ));
    }
    Ok(())
}

fn position(p: &[f64; 3], field: &str) -> Result<(), ScenarioError> {
    finite3(p, field)?;
    for (i, x) in p.iter().enumerate() {
        if x.abs() > MAX_SIZE_M {
            return Err(invalid(
                format!("{field}[{i}]"),
                format!("{} m is beyond {MAX_SIZE_M} m", Num(*x)),
            ));
        }
    }
    Ok(())
}

fn shape(s: &Shape, f: &str) -> Result<(), ScenarioError> {
    match s {
        Shape::Box { half_extents } => {
            for (i, h) in half_extents.iter().enumerate() {
                length(*h, &format!("{f}.half_extents[{i}]"))?;
            }
        }
        Shape::Sphere { radius } => length(*radius, &format!("{f}.radius"))?,
        Shape::Capsule {
            half_height,
            radius,
        }
        | Shape::Cylinder {
            half_height,
            radius,
        } => {
            length(*half_height, &format!("{f}.half_height"))?;
            length(*radius, &format!("{f}.radius"))?;
        }
        Shape::ConvexHull {
            points,
            file,
            scale,
        } => {
            within(*scale, &format!("{f}.scale"), 0.0, 1e3, false)?;
            match (points, file) {
                (Some(p), None) => hull_points(p, &format!("{f}.points"))?,
                (None, Some(file)) => path(file, &format!("{f}.file"))?,
                _ => {
                    return Err(invalid(
                        f,
                        "a convex_hull takes `points` or `file`, one of them",
                    ))
                }
            }
        }
        Shape::Mesh { file, scale } => {
            path(file, &format!("{f}.file"))?;
            within(*scale, &format!("{f}.scale"), 0.0, 1e3, false)?;
        }
    }
    Ok(())
}

fn path(p: &str, field: &str) -> Result<(), ScenarioError> {
    if p.trim().is_empty() {
        return Err(invalid(field, "is empty: name an STL or OBJ file"));
    }
    Ok(())
}

fn hull_points(p: &[[f64; 3]], field: &str) -> Result<(), ScenarioError> {
    if p.len() < 4 || p.len() > MAX_HULL_POINTS {
        return Err(invalid(
            field,
            format!(
                "has {} points; a hull takes 4 to {MAX_HULL_POINTS}",
                p.len()
            ),
        ));
    }
    for (k, x) in p.iter().enumerate() {
        position(x, &format!("{field}[{k}]"))?;
    }
    Ok(())
}

fn name(n: &str, field: &str, taken: &[&str]) -> Result<(), ScenarioError> {
    if n.is_empty() || n.len() > 64 || n.chars().any(char::is_control) {
        return Err(invalid(
            field,
            "a name is 1 to 64 characters, none a control character",
        ));
    }
    if taken.contains(&n) {
        return Err(invalid(
            field,
            format!("`{n}` is used twice: names are unique"),
        ));
    }
    Ok(())
}

fn body(b: &BodyConfig, f: &str, taken: &[&str]) -> Result<(), ScenarioError> {
    name(&b.name, &format!("{f}.name"), taken)?;
    if b.name == TOOL_BODY {
        return Err(invalid(
            format!("{f}.name"),
            format!("`{TOOL_BODY}` is the tool's name ([environment.tool])"),
        ));
    }
    shape(&b.shape, &format!("{f}.shape"))?;
    position(&b.position, &format!("{f}.position"))?;
    quaternion(&b.rotation, &format!("{f}.rotation"))?;
    let moves = b.kind == BodyKind::Dynamic;
    for (key, v, max) in [("mass", b.mass, 1e4), ("density", b.density, 1e5)] {
        let Some(v) = v else { continue };
        if !moves {
            return Err(invalid(
                format!("{f}.{key}"),
                "only a dynamic body has a mass: this one does not move under forces",
            ));
        }
        within(v, &format!("{f}.{key}"), 0.0, max, false)?;
    }
    if b.mass.is_some() && b.density.is_some() {
        return Err(invalid(
            format!("{f}.density"),
            "give a mass or a density, not both",
        ));
    }
    within(b.friction, &format!("{f}.friction"), 0.0, 10.0, false)?;
    within(b.restitution, &format!("{f}.restitution"), 0.0, 1.0, true)?;
    within(
        b.contact_skin,
        &format!("{f}.contact_skin"),
        0.0,
        0.01,
        true,
    )
}

fn joint(
    j: &JointConfig,
    f: &str,
    taken: &[&str],
    bodies: &[BodyConfig],
) -> Result<(), ScenarioError> {
    name(&j.name, &format!("{f}.name"), taken)?;
    let find = |n: &str, key: &str| {
        bodies.iter().find(|b| b.name == n).ok_or_else(|| {
            invalid(
                format!("{f}.{key}"),
                format!(
                    "`{n}` is not a body: the bodies are {}",
                    crate::shown::listed(bodies.iter().map(|b| b.name.as_str()))
                ),
            )
        })
    };
    let b2 = find(&j.body2, "body2")?;
    let b1 = j.body1.as_deref().map(|n| find(n, "body1")).transpose()?;
    if j.body1.as_deref() == Some(j.body2.as_str()) {
        return Err(invalid(format!("{f}.body1"), "joins a body to itself"));
    }
    if b2.kind != BodyKind::Dynamic && b1.is_none_or(|b| b.kind != BodyKind::Dynamic) {
        return Err(invalid(
            format!("{f}.body2"),
            "neither body is dynamic: the joint could never move",
        ));
    }
    position(&j.anchor, &format!("{f}.anchor"))?;
    direction(&j.axis, &format!("{f}.axis"))?;
    if j.kind == JointKind::Fixed {
        let moves = [
            ("limits", j.limits.is_some()),
            ("damping", j.damping != 0.0),
            ("friction", j.friction != 0.0),
        ];
        if let Some((key, _)) = moves.iter().find(|(_, set)| *set) {
            return Err(invalid(
                format!("{f}.{key}"),
                "a fixed joint does not move: its limits, damping and friction would do nothing",
            ));
        }
    }
    if let Some([lo, hi]) = j.limits {
        for (i, v) in [lo, hi].iter().enumerate() {
            within(*v, &format!("{f}.limits[{i}]"), -1e3, 1e3, true)?;
        }
        if lo >= hi {
            return Err(invalid(
                format!("{f}.limits"),
                format!(
                    "lower {} is not below upper {}: the limits are reversed or empty",
                    Num(lo),
                    Num(hi)
                ),
            ));
        }
        if lo > 0.0 || hi < 0.0 {
            return Err(invalid(
                format!("{f}.limits"),
                "exclude 0, the joint's position at the start",
            ));
        }
    }
    within(j.damping, &format!("{f}.damping"), 0.0, 1e4, true)?;
    within(j.friction, &format!("{f}.friction"), 0.0, 1e4, true)
}

fn tool(t: &ToolConfig) -> Result<(), ScenarioError> {
    let f = "environment.tool";
    shape(&t.shape, &format!("{f}.shape"))?;
    within(t.mass, &format!("{f}.mass"), 0.0, 100.0, false)?;
    within(t.friction, &format!("{f}.friction"), 0.0, 10.0, false)?;
    within(t.restitution, &format!("{f}.restitution"), 0.0, 1.0, true)?;
    within(t.stiffness, &format!("{f}.stiffness"), 0.0, 1e6, false)?;
    within(t.damping, &format!("{f}.damping"), 0.0, 1e5, true)?;
    within(
        t.angular_stiffness,
        &format!("{f}.angular_stiffness"),
        0.0,
        1e5,
        false,
    )?;
    within(
        t.angular_damping,
        &format!("{f}.angular_damping"),
        0.0,
        1e4,
        true,
    )
}

impl Environment {
    /// The physics world's keys: refused beside the analytic engine, checked with it.
    pub(crate) fn validate_physics(&self, task: Option<&TaskConfig>) -> Result<(), ScenarioError> {
        if self.engine == Engine::Analytic {
            let physics_only = [
                ("environment.bodies", !self.bodies.is_empty()),
                ("environment.joints", !self.joints.is_empty()),
                ("task", task.is_some()),
            ];
            if let Some((field, _)) = physics_only.iter().find(|(_, set)| *set) {
                return Err(invalid(
                    *field,
                    "belongs to a physics world: set [environment] engine = \"physics\"",
                ));
            }
            return Ok(());
        }
        if !self.objects.is_empty() || !self.changes.is_empty() {
            return Err(invalid(
                "environment.objects",
                "analytic objects and changes are not part of a physics world: write them as [[environment.bodies]]",
            ));
        }
        finite3(&self.gravity, "environment.gravity")?;
        if self.gravity.iter().any(|g| g.abs() > 100.0) {
            return Err(invalid(
                "environment.gravity",
                "is beyond 100 m/s^2 on an axis",
            ));
        }
        count(self.substeps, "environment.substeps")?;
        let b = &self.bounds;
        position(&b.min, "environment.bounds.min")?;
        position(&b.max, "environment.bounds.max")?;
        if let Some(i) = (0..3).find(|&i| b.min[i] >= b.max[i]) {
            return Err(invalid(
                format!("environment.bounds.max[{i}]"),
                "must be above min: the world would be empty",
            ));
        }
        let s = &self.solver;
        count(s.iterations, "environment.solver.iterations")?;
        within(
            s.contact_frequency_hz,
            "environment.solver.contact_frequency_hz",
            0.0,
            1e4,
            false,
        )?;
        within(
            s.contact_damping_ratio,
            "environment.solver.contact_damping_ratio",
            0.0,
            1e3,
            false,
        )?;
        within(
            s.allowed_penetration,
            "environment.solver.allowed_penetration",
            0.0,
            0.01,
            true,
        )?;
        within(
            s.prediction_distance,
            "environment.solver.prediction_distance",
            0.0,
            0.1,
            true,
        )?;
        for (key, n) in [("bodies", self.bodies.len()), ("joints", self.joints.len())] {
            if n > MAX_BODIES {
                return Err(invalid(
                    format!("environment.{key}"),
                    format!("has {n}; a world holds at most {MAX_BODIES}"),
                ));
            }
        }
        let mut names: Vec<&str> = Vec::new();
        for (k, bc) in self.bodies.iter().enumerate() {
            body(bc, &format!("environment.bodies[{k}]"), &names)?;
            names.push(&bc.name);
        }
        let mut joints: Vec<&str> = Vec::new();
        for (k, j) in self.joints.iter().enumerate() {
            joint(
                j,
                &format!("environment.joints[{k}]"),
                &joints,
                &self.bodies,
            )?;
            joints.push(&j.name);
        }
        tool(&self.tool)?;
        match task {
            Some(t) => t.validate(&names, &joints),
            None => Ok(()),
        }
    }
}
