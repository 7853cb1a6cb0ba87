//! Writers of the three formats: the seeds of the mesh readers' fuzz target, the
//! tests' files, and the meshes shipped in deploy/scenarios/meshes/.

use super::Mesh;
use std::fmt::Write as _;

/// The corners of each triangle, in metres as f32 (what an STL holds).
fn corners(m: &Mesh) -> impl Iterator<Item = [[f64; 3]; 3]> + '_ {
    m.triangles
        .iter()
        .map(|t| t.map(|i| m.vertices.get(i as usize).copied().unwrap_or_default()))
}

fn normal(c: &[[f64; 3]; 3]) -> [f64; 3] {
    let u: [f64; 3] = std::array::from_fn(|i| c[1][i] - c[0][i]);
    let v: [f64; 3] = std::array::from_fn(|i| c[2][i] - c[0][i]);
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let l = n.iter().map(|x| x * x).sum::<f64>().sqrt();
    if l > 0.0 {
        n.map(|x| x / l)
    } else {
        n
    }
}

/// A binary STL.
pub fn to_stl_binary(m: &Mesh) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b[..12].copy_from_slice(b"tactile mesh");
    b.extend_from_slice(&(m.triangles.len() as u32).to_le_bytes());
    for c in corners(m) {
        for v in std::iter::once(normal(&c)).chain(c) {
            for x in v {
                b.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

/// An ASCII STL.
pub fn to_stl_ascii(m: &Mesh, name: &str) -> String {
    let mut s = format!("solid {name}\n");
    for c in corners(m) {
        let n = normal(&c);
        let _ = writeln!(
            s,
            "  facet normal {} {} {}\n    outer loop",
            n[0], n[1], n[2]
        );
        for v in c {
            let _ = writeln!(s, "      vertex {} {} {}", v[0], v[1], v[2]);
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    let _ = writeln!(s, "endsolid {name}");
    s
}

/// An OBJ.
pub fn to_obj(m: &Mesh) -> String {
    let mut s = String::new();
    for v in &m.vertices {
        let _ = writeln!(s, "v {} {} {}", v[0], v[1], v[2]);
    }
    for t in &m.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}
