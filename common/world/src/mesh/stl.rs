//! STL, binary and ASCII. A binary file is an 80-byte header, a little-endian u32
//! triangle count and 50 bytes per triangle (a normal, three corners, two attribute
//! bytes); an ASCII one is `solid ... facet normal ... outer loop vertex x y z (x3)
//! endloop endfacet ... endsolid`. Binary files may also begin with `solid` (some
//! exporters write it into the header), so a file whose length is exactly what its
//! count says is binary whatever its first bytes.

use super::{vertex, weld, Mesh, MeshError, MAX_TRIANGLES};

const HEADER: usize = 84;
const PER_TRIANGLE: usize = 50;

/// Parses an STL file, binary or ASCII.
pub fn parse_stl(bytes: &[u8]) -> Result<Mesh, MeshError> {
    if bytes.is_empty() {
        return Err(MeshError::Empty);
    }
    let count = bytes
        .get(80..84)
        .map(|c| u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
    let binary_len = count.map(|n| HEADER as u64 + n * PER_TRIANGLE as u64);
    if binary_len == Some(bytes.len() as u64) || !bytes.trim_ascii_start().starts_with(b"solid") {
        return binary(bytes, count);
    }
    ascii(bytes)
}

fn binary(bytes: &[u8], count: Option<u64>) -> Result<Mesh, MeshError> {
    let Some(count) = count else {
        return Err(MeshError::Syntax {
            format: "binary STL",
            problem: format!("{} bytes, shorter than its 84-byte header", bytes.len()),
        });
    };
    if count as usize > MAX_TRIANGLES {
        return Err(MeshError::TooManyTriangles(count));
    }
    let expected = HEADER as u64 + count * PER_TRIANGLE as u64;
    let len = bytes.len() as u64;
    if len < expected {
        return Err(MeshError::Truncated {
            count,
            expected,
            len,
        });
    }
    if len > expected {
        return Err(MeshError::Syntax {
            format: "binary STL",
            problem: format!(
                "{} bytes after its {count} triangles: not a binary STL (nor an ASCII one: it does not begin with `solid`)",
                len - expected
            ),
        });
    }
    if count == 0 {
        return Err(MeshError::Empty);
    }
    let mut corners = Vec::with_capacity(count as usize * 3);
    for t in bytes[HEADER..].chunks_exact(PER_TRIANGLE) {
        for k in 0..3 {
            let at = 12 + 12 * k;
            let f = |i: usize| {
                let b = &t[at + 4 * i..at + 4 * i + 4];
                f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            };
            corners.push(vertex([f(0), f(1), f(2)], corners.len())?);
        }
    }
    Ok(weld(&corners))
}

fn syntax(line: usize, problem: impl std::fmt::Display) -> MeshError {
    MeshError::Syntax {
        format: "ASCII STL",
        problem: format!("line {line}: {problem}"),
    }
}

fn ascii(bytes: &[u8]) -> Result<Mesh, MeshError> {
    let text = std::str::from_utf8(bytes).map_err(|e| MeshError::Syntax {
        format: "ASCII STL",
        problem: format!("not text (byte {} is not UTF-8)", e.valid_up_to()),
    })?;
    let mut corners: Vec<[f64; 3]> = Vec::new();
    let mut in_loop = 0usize; // corners in the current loop, plus one while open
    for (n, line) in text.lines().enumerate() {
        let mut w = line.split_ascii_whitespace();
        match w.next() {
            Some("vertex") => {
                if in_loop == 0 {
                    return Err(syntax(n + 1, "a vertex outside `outer loop`"));
                }
                let mut v = [0.0; 3];
                for x in &mut v {
                    *x = w
                        .next()
                        .and_then(|s| s.parse::<f64>().ok())
                        .ok_or_else(|| syntax(n + 1, "a vertex needs three numbers"))?;
                }
                if in_loop > 3 {
                    return Err(syntax(n + 1, "a facet with more than three vertices"));
                }
                corners.push(vertex(v, corners.len())?);
                in_loop += 1;
                if corners.len() / 3 > MAX_TRIANGLES {
                    return Err(MeshError::TooManyTriangles(corners.len() as u64 / 3));
                }
            }
            Some("outer") => {
                if in_loop != 0 {
                    return Err(syntax(n + 1, "`outer loop` inside a loop"));
                }
                in_loop = 1;
            }
            Some("endloop") => {
                if in_loop != 4 {
                    return Err(syntax(
                        n + 1,
                        format!(
                            "a facet with {} vertices (it takes 3)",
                            in_loop.saturating_sub(1)
                        ),
                    ));
                }
                in_loop = 0;
            }
            Some("solid" | "facet" | "endfacet" | "endsolid") | None => {}
            Some(other) => {
                let shown: String = other.chars().take(20).collect();
                return Err(syntax(n + 1, format!("`{shown}` is not an STL keyword")));
            }
        }
    }
    if in_loop != 0 {
        return Err(syntax(
            text.lines().count(),
            "the file ends inside a facet (truncated)",
        ));
    }
    if corners.is_empty() {
        return Err(MeshError::Empty);
    }
    Ok(weld(&corners))
}
