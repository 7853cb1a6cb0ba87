//! The slave's environment (ENV): rigid objects and the contact they make with the tool.
//!
//! The environment stands in for the paper's sensors "spread in the ENV": given the
//! tool's true position it reports the nearest surface point s^OBJ(n) of the object
//! the tool penetrates, with that object's stiffness (h_x, h_y, h_z). Pure geometry in
//! f64: this is the physical world, not the HSD's datapath.

use tactile_math::vec3::dot;
use tactile_scenario::{Change, Object};

/// The tool inside an object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Index of the object in the scenario's list.
    pub object: usize,
    /// Nearest point on that object's surface, metres.
    pub surface: [f64; 3],
    /// Stiffness per axis, N/m.
    pub stiffness: [f64; 3],
    /// Penetration depth, metres (> 0).
    pub depth: f64,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The scenario's objects as the contact test takes them: a plane's unit normal is
/// worked out once here rather than at every test (the dynamics test contact at each
/// of a sample's substeps), with the same operations, so contacts are bit for bit as
/// before.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    objects: Vec<(Object, [f64; 3])>,
}

impl Scene {
    /// The objects, each with its unit normal if it is a plane (zero otherwise).
    pub fn new(objects: &[Object]) -> Scene {
        let unit = |o: &Object| match o {
            Object::Plane { normal, .. } => {
                let len = dot(*normal, *normal).sqrt();
                normal.map(|v| v / len)
            }
            _ => [0.0; 3],
        };
        Scene {
            objects: objects.iter().map(|o| (o.clone(), unit(o))).collect(),
        }
    }

    /// Applies a change to its object (a scenario's are checked: an index out of
    /// range changes nothing).
    pub fn apply(&mut self, c: &Change) {
        if let Some((o, _)) = self.objects.get_mut(c.object) {
            *o = o.changed(c);
        }
    }
}

fn contact_with(index: usize, (object, n): &(Object, [f64; 3]), p: [f64; 3]) -> Option<Contact> {
    let (surface, depth) = match object {
        Object::Plane { point, .. } => {
            let n = *n;
            let s = dot(sub(p, *point), n);
            if s >= 0.0 {
                return None;
            }
            ([p[0] - s * n[0], p[1] - s * n[1], p[2] - s * n[2]], -s)
        }
        Object::Sphere { center, radius, .. } => {
            let d = sub(p, *center);
            let dist = dot(d, d).sqrt();
            if dist >= *radius {
                return None;
            }
            // At the very centre every direction is nearest: push out along +y (up).
            let u = if dist > 0.0 {
                d.map(|v| v / dist)
            } else {
                [0.0, 1.0, 0.0]
            };
            (
                [
                    center[0] + radius * u[0],
                    center[1] + radius * u[1],
                    center[2] + radius * u[2],
                ],
                radius - dist,
            )
        }
        Object::Box {
            center,
            half_extents,
            ..
        } => {
            let local = sub(p, *center);
            let mut best: Option<(usize, f64)> = None;
            for k in 0..3 {
                let pen = half_extents[k] - local[k].abs();
                if pen <= 0.0 {
                    return None;
                }
                if best.is_none_or(|(_, b)| pen < b) {
                    best = Some((k, pen));
                }
            }
            let (k, pen) = best?;
            let mut s = p;
            s[k] = center[k] + half_extents[k].copysign(local[k]);
            (s, pen)
        }
    };
    Some(Contact {
        object: index,
        surface,
        stiffness: object.stiffness(),
        depth,
    })
}

/// The deepest contact of the tool at `p` with any object, if it touches one.
pub fn deepest_contact(scene: &Scene, p: [f64; 3]) -> Option<Contact> {
    scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| contact_with(i, o, p))
        .max_by(|a, b| a.depth.total_cmp(&b.depth))
}

#[cfg(test)]
mod tests {
    use super::*;

    const K: [f64; 3] = [100.0, 200.0, 300.0];

    #[test]
    fn plane_contact() {
        let o = [Object::Plane {
            point: [0.0, 0.0, -0.16],
            normal: [0.0, 0.0, 2.0],
            stiffness: K,
        }];
        assert_eq!(deepest_contact(&Scene::new(&o), [0.1, 0.2, -0.15]), None);
        let c = deepest_contact(&Scene::new(&o), [0.1, 0.2, -0.17]).expect("inside");
        assert!((c.depth - 0.01).abs() < 1e-12);
        assert!((c.surface[2] + 0.16).abs() < 1e-12);
        assert_eq!(c.surface[0], 0.1);
        assert_eq!(c.stiffness, K);
    }

    #[test]
    fn a_planes_contact_is_bit_for_bit_the_normal_worked_out_at_each_test() {
        // Normals of awkward lengths and directions, points either side of the plane.
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..200 {
            let (point, normal) = ([next(), next(), next()], [next(), next(), 3.0 * next()]);
            let scene = Scene::new(&[Object::Plane {
                point,
                normal,
                stiffness: K,
            }]);
            let len = dot(normal, normal).sqrt();
            let n = normal.map(|v| v / len);
            for _ in 0..50 {
                let p = [next(), next(), next()];
                let s = dot(sub(p, point), n);
                let want = (s < 0.0).then(|| [p[0] - s * n[0], p[1] - s * n[1], p[2] - s * n[2]]);
                let got = deepest_contact(&scene, p);
                assert_eq!(
                    got.map(|c| (c.surface.map(f64::to_bits), c.depth.to_bits())),
                    want.map(|w| (w.map(f64::to_bits), (-s).to_bits())),
                );
            }
        }
    }

    #[test]
    fn sphere_and_box_contact_pick_the_deepest() {
        let o = [
            Object::Sphere {
                center: [0.0; 3],
                radius: 0.05,
                stiffness: K,
            },
            Object::Box {
                center: [0.0, 0.0, 0.0],
                half_extents: [0.1, 0.02, 0.1],
                stiffness: [1.0; 3],
            },
        ];
        // 1 cm from the centre: sphere depth 4 cm, box depth (y) 1 cm.
        let c = deepest_contact(&Scene::new(&o), [0.0, 0.01, 0.0]).expect("inside");
        assert_eq!(c.object, 0);
        assert!((c.depth - 0.04).abs() < 1e-12);
        assert!((c.surface[1] - 0.05).abs() < 1e-12);
        // Outside the sphere, inside the box: pushed out through the nearest (y) face.
        let c = deepest_contact(&Scene::new(&o), [0.08, -0.015, 0.0]).expect("inside box");
        assert_eq!(c.object, 1);
        assert_eq!(c.surface, [0.08, -0.02, 0.0]);
        assert_eq!(deepest_contact(&Scene::new(&o), [0.2, 0.0, 0.0]), None);
    }
}
