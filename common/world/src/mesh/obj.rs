//! Wavefront OBJ: `v x y z [w]` vertices and `f` faces (`i`, `i/t`, `i//n`, `i/t/n`,
//! negative indices counted back from the last vertex), polygons split into a fan of
//! triangles. Normals, texture coordinates, groups, objects, smoothing, materials and
//! lines are skipped; any other keyword is refused (binary garbage is not an OBJ).

use super::{vertex, Mesh, MeshError, MAX_TRIANGLES};

/// Most corners of one face: a bound on what one line can add.
const MAX_FACE_CORNERS: usize = 256;

fn syntax(line: usize, problem: impl std::fmt::Display) -> MeshError {
    MeshError::Syntax {
        format: "OBJ",
        problem: format!("line {line}: {problem}"),
    }
}

/// Parses an OBJ file.
pub fn parse_obj(bytes: &[u8]) -> Result<Mesh, MeshError> {
    if bytes.is_empty() {
        return Err(MeshError::Empty);
    }
    let text = std::str::from_utf8(bytes).map_err(|e| MeshError::Syntax {
        format: "OBJ",
        problem: format!("not text (byte {} is not UTF-8)", e.valid_up_to()),
    })?;
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut face: Vec<u32> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        let mut w = line.split_ascii_whitespace();
        match w.next() {
            Some("v") => {
                let mut v = [0.0; 3];
                for x in &mut v {
                    *x = w
                        .next()
                        .and_then(|s| s.parse::<f64>().ok())
                        .ok_or_else(|| syntax(n + 1, "a vertex needs three numbers"))?;
                }
                if vertices.len() >= 3 * MAX_TRIANGLES {
                    return Err(syntax(
                        n + 1,
                        format!("more than {} vertices", 3 * MAX_TRIANGLES),
                    ));
                }
                vertices.push(vertex(v, vertices.len())?);
            }
            Some("f") => {
                face.clear();
                for c in w {
                    if face.len() == MAX_FACE_CORNERS {
                        return Err(syntax(
                            n + 1,
                            format!("a face of more than {MAX_FACE_CORNERS} corners"),
                        ));
                    }
                    face.push(corner(c, vertices.len()).map_err(|p| syntax(n + 1, p))?);
                }
                if face.len() < 3 {
                    return Err(syntax(
                        n + 1,
                        format!("a face of {} corners (at least 3)", face.len()),
                    ));
                }
                for k in 1..face.len() - 1 {
                    triangles.push([face[0], face[k], face[k + 1]]);
                }
                if triangles.len() > MAX_TRIANGLES {
                    return Err(MeshError::TooManyTriangles(triangles.len() as u64));
                }
            }
            Some("vn" | "vt" | "vp" | "g" | "o" | "s" | "usemtl" | "mtllib" | "l") | None => {}
            Some(other) => {
                let shown: String = other.chars().take(20).collect();
                return Err(syntax(n + 1, format!("`{shown}` is not an OBJ keyword")));
            }
        }
    }
    if triangles.is_empty() {
        return Err(MeshError::Empty);
    }
    Ok(Mesh {
        vertices,
        triangles,
    })
}

/// A face's corner `i[/t[/n]]` as a 0-based vertex index among `count` so far.
fn corner(c: &str, count: usize) -> Result<u32, String> {
    let first = c.split('/').next().unwrap_or("");
    let i: i64 = first.parse().map_err(|_| {
        format!(
            "`{}` is not a vertex index",
            first.chars().take(20).collect::<String>()
        )
    })?;
    let at = match i {
        1.. => i - 1,
        0 => return Err("vertex index 0 (OBJ counts from 1)".into()),
        _ => count as i64 + i,
    };
    if at < 0 || at >= count as i64 {
        return Err(format!(
            "vertex {i} is not among the {count} given before it"
        ));
    }
    Ok(at as u32)
}
