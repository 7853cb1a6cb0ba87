//! A block with a blind round hole in its top: the peg-in-hole scene's fixture,
//! written by [`Mesh::block_with_hole`] so the shipped file is what the code makes.

use super::Mesh;
use std::f64::consts::TAU;

/// The triangles so far, each turned to face `out` (the solid's outside there).
struct Faces {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Faces {
    fn at(&mut self, p: [f64; 3]) -> u32 {
        self.vertices.push(p);
        (self.vertices.len() - 1) as u32
    }

    /// Adds triangle `t`, its corners reordered if its normal points against `out`.
    fn push(&mut self, t: [u32; 3], out: [f64; 3]) {
        let [a, b, c] = t.map(|i| self.vertices[i as usize]);
        let (u, v) = (
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let facing = n[0] * out[0] + n[1] * out[1] + n[2] * out[2];
        self.triangles
            .push(if facing >= 0.0 { t } else { [t[0], t[2], t[1]] });
    }
}

/// Where the ray from the centre at angle `a` leaves the rectangle of half sizes
/// `hx`, `hy`.
fn on_rectangle(a: f64, hx: f64, hy: f64) -> [f64; 2] {
    let (c, s) = (a.cos(), a.sin());
    let t = (hx / c.abs().max(1e-300)).min(hy / s.abs().max(1e-300));
    [t * c, t * s]
}

impl Mesh {
    /// A block of a square top, `half_width` from its axis to each side and
    /// `half_height` up and down, centred on the origin, with a round hole of `sides`
    /// faces down its z axis from the top face, `depth` deep; the polygon's inscribed
    /// radius is `radius` (so a cylinder of that radius just fits). `sides` is rounded
    /// down to a multiple of 8, so the square's corners are among the rays the top
    /// face is cut along (a rectangle's would not be). Closed and outward.
    pub fn block_with_hole(
        half_width: f64,
        half_height: f64,
        sides: u32,
        radius: f64,
        depth: f64,
    ) -> Mesh {
        let h = [half_width, half_width, half_height];
        let n = (sides.max(8) / 8) * 8;
        let circum = radius / (std::f64::consts::PI / f64::from(n)).cos();
        let (top, floor) = (h[2], h[2] - depth);
        let mut f = Faces {
            vertices: Vec::with_capacity(4 * n as usize + 5),
            triangles: Vec::with_capacity(6 * n as usize + 6),
        };
        let angle = |k: u32| TAU * f64::from(k % n) / f64::from(n);
        let ring = |z: f64, r: f64, f: &mut Faces| -> Vec<u32> {
            (0..n)
                .map(|k| f.at([r * angle(k).cos(), r * angle(k).sin(), z]))
                .collect()
        };
        let mouth = ring(top, circum, &mut f);
        let bottom = ring(floor, circum, &mut f);
        let rim: Vec<u32> = (0..n)
            .map(|k| {
                let [x, y] = on_rectangle(angle(k), h[0], h[1]);
                f.at([x, y, top])
            })
            .collect();
        let centre = f.at([0.0, 0.0, floor]);
        let corners: Vec<u32> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
            .iter()
            .map(|s| f.at([s[0] * h[0], s[1] * h[1], -h[2]]))
            .collect();
        for k in 0..n as usize {
            let j = (k + 1) % n as usize;
            let mid = angle(k as u32) + std::f64::consts::PI / f64::from(n);
            let axis = [-mid.cos(), -mid.sin(), 0.0];
            f.push([mouth[k], rim[k], rim[j]], [0.0, 0.0, 1.0]);
            f.push([mouth[k], rim[j], mouth[j]], [0.0, 0.0, 1.0]);
            f.push([bottom[k], mouth[j], bottom[j]], axis);
            f.push([bottom[k], mouth[k], mouth[j]], axis);
            f.push([centre, bottom[k], bottom[j]], [0.0, 0.0, 1.0]);
            // The side under this piece of the rim: a fan from the bottom corner
            // below its side (the rim's corners are at k = n/8, 3n/8, ...).
            let side = ((8 * k as u32 + n) / (2 * n)) % 4;
            let out = match side {
                0 => [1.0, 0.0, 0.0],
                1 => [0.0, 1.0, 0.0],
                2 => [-1.0, 0.0, 0.0],
                _ => [0.0, -1.0, 0.0],
            };
            f.push([corners[(side as usize + 1) % 4], rim[k], rim[j]], out);
        }
        // Each side's triangle between its two bottom corners and its last rim point.
        for side in 0..4u32 {
            let out = match side {
                0 => [1.0, 0.0, 0.0],
                1 => [0.0, 1.0, 0.0],
                2 => [-1.0, 0.0, 0.0],
                _ => [0.0, -1.0, 0.0],
            };
            let corner = rim[((2 * side + 1) * n / 8 % n) as usize];
            let (a, b) = (
                corners[(side as usize + 1) % 4],
                corners[(side as usize + 2) % 4],
            );
            f.push([a, b, corner], out);
        }
        f.push([corners[0], corners[1], corners[2]], [0.0, 0.0, -1.0]);
        f.push([corners[0], corners[2], corners[3]], [0.0, 0.0, -1.0]);
        Mesh {
            vertices: f.vertices,
            triangles: f.triangles,
        }
    }
}
