//! Triangle meshes from STL (binary and ASCII) and OBJ files: read with a size cap, a
//! triangle cap and every vertex checked, so no file can make the slave hold more than
//! [`MAX_MESH_BYTES`] of text or [`MAX_TRIANGLES`] triangles, or put a NaN into the
//! world. The readers are pure functions of the bytes ([`parse`]); [`read`] is the one
//! place that touches the file system.

mod hole;
mod obj;
mod stl;
mod write;

pub use obj::parse_obj;
pub use stl::parse_stl;
pub use write::{to_obj, to_stl_ascii, to_stl_binary};

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest mesh file read, bytes: a binary STL of [`MAX_TRIANGLES`] is 50 MB.
pub const MAX_MESH_BYTES: u64 = 64 << 20;
/// Most triangles a mesh may have (10^6: a 10,000-triangle table top is 1 % of it).
pub const MAX_TRIANGLES: usize = 1_000_000;
/// Largest magnitude of a coordinate in the file's own units: past this a value is
/// garbage, whatever the scale (1e300 would overflow every product the engine forms).
pub const MAX_COORDINATE: f64 = 1e9;

/// A triangle mesh: vertices shared between triangles (an STL's repeated corners
/// welded where they are bit-identical), triangles as indices, counter-clockwise
/// seen from outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// The vertices, in the file's units.
    pub vertices: Vec<[f64; 3]>,
    /// The triangles, indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// A mesh that cannot be read or used; the message says where and why.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MeshError {
    /// The file could not be read.
    #[error("cannot read {}: {problem}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        problem: String,
    },
    /// Larger than [`MAX_MESH_BYTES`].
    #[error("{} is {len} bytes, more than the {MAX_MESH_BYTES} a mesh file may have", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size.
        len: u64,
    },
    /// Neither `.stl` nor `.obj`.
    #[error("{} is not an .stl or .obj file", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// No triangle at all.
    #[error("holds no triangle")]
    Empty,
    /// A binary STL shorter than its triangle count says.
    #[error(
        "is truncated: its header counts {count} triangles ({expected} bytes), the file has {len}"
    )]
    Truncated {
        /// Triangles the header counts.
        count: u64,
        /// Bytes that makes.
        expected: u64,
        /// Bytes there are.
        len: u64,
    },
    /// More than [`MAX_TRIANGLES`].
    #[error("has {0} triangles, more than the {MAX_TRIANGLES} a mesh may have")]
    TooManyTriangles(u64),
    /// Not a mesh of this format: the line (OBJ, ASCII STL) and what is wrong.
    #[error("is not a valid {format}: {problem}")]
    Syntax {
        /// `OBJ`, `ASCII STL`, `binary STL`.
        format: &'static str,
        /// Where and what.
        problem: String,
    },
    /// A vertex that is not finite or beyond [`MAX_COORDINATE`].
    #[error("vertex {index} has {value}, not a finite coordinate within {MAX_COORDINATE:e}")]
    BadVertex {
        /// Which vertex (in file order).
        index: usize,
        /// The value.
        value: String,
    },
    /// Edges used by one triangle only, or by more than two: not the surface of a solid.
    #[error("is not closed: {open} of its {edges} edges are not shared by exactly two triangles turning opposite ways (a solid needs a closed, consistently oriented surface)")]
    NotClosed {
        /// Edges not shared properly.
        open: usize,
        /// All edges.
        edges: usize,
    },
}

/// Which reader a file takes, by its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// STL, binary or ASCII (told apart by the bytes).
    Stl,
    /// Wavefront OBJ.
    Obj,
}

impl Format {
    /// The format of `path` by its extension (any case).
    pub fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(Format::Stl),
            "obj" => Some(Format::Obj),
            _ => None,
        }
    }
}

/// Parses `bytes` as `format`.
pub fn parse(bytes: &[u8], format: Format) -> Result<Mesh, MeshError> {
    match format {
        Format::Stl => parse_stl(bytes),
        Format::Obj => parse_obj(bytes),
    }
}

/// Reads the mesh at `path` (a regular file of at most [`MAX_MESH_BYTES`], read with
/// that bound so a file growing meanwhile cannot exhaust memory), by its extension.
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    let format = Format::of(path).ok_or_else(|| MeshError::UnknownFormat {
        path: path.to_path_buf(),
    })?;
    let io = |e: std::io::Error| MeshError::Io {
        path: path.to_path_buf(),
        problem: e.to_string(),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(MeshError::Io {
            path: path.to_path_buf(),
            problem: "not a regular file".into(),
        });
    }
    let too_large = |len| MeshError::TooLarge {
        path: path.to_path_buf(),
        len,
    };
    if meta.len() > MAX_MESH_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_MESH_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_MESH_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    parse(&bytes, format)
}

/// A vertex checked: finite, within [`MAX_COORDINATE`].
pub(crate) fn vertex(v: [f64; 3], index: usize) -> Result<[f64; 3], MeshError> {
    match v
        .iter()
        .find(|x| !x.is_finite() || x.abs() > MAX_COORDINATE)
    {
        None => Ok(v),
        Some(x) => Err(MeshError::BadVertex {
            index,
            value: format!("{x:e}"),
        }),
    }
}

/// Builds an indexed mesh from triangles given by their corners, welding corners
/// that are bit-identical (STL repeats every shared corner).
pub(crate) fn weld(corners: &[[f64; 3]]) -> Mesh {
    let mut index: HashMap<[u64; 3], u32> = HashMap::with_capacity(corners.len() / 2);
    let mut vertices = Vec::with_capacity(corners.len() / 2);
    let mut ids = Vec::with_capacity(corners.len());
    for c in corners {
        // -0.0 and 0.0 are one point.
        let key = c.map(|x| (x + 0.0).to_bits());
        let id = *index.entry(key).or_insert_with(|| {
            vertices.push(*c);
            (vertices.len() - 1) as u32
        });
        ids.push(id);
    }
    let triangles = ids.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    Mesh {
        vertices,
        triangles,
    }
}

impl Mesh {
    /// Whether the surface is closed and consistently oriented: every edge is walked
    /// once each way, by exactly two triangles. A degenerate triangle (two corners the
    /// same vertex) counts as an open edge.
    pub fn check_closed(&self) -> Result<(), MeshError> {
        let mut directed: HashMap<(u32, u32), u32> =
            HashMap::with_capacity(self.triangles.len() * 3);
        let mut degenerate = 0usize;
        for t in &self.triangles {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                degenerate += 1;
                continue;
            }
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        let mut open = degenerate;
        let mut edges = degenerate;
        for (&(a, b), &n) in &directed {
            if a < b || !directed.contains_key(&(b, a)) {
                edges += 1;
            }
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            if (n != 1 || back != 1) && (a < b || back == 0) {
                open += 1;
            }
        }
        if open > 0 || self.triangles.is_empty() {
            return Err(MeshError::NotClosed { open, edges });
        }
        Ok(())
    }

    /// The vertices scaled (file units to metres).
    pub fn scaled(&self, scale: f64) -> Vec<[f64; 3]> {
        self.vertices.iter().map(|v| v.map(|x| x * scale)).collect()
    }

    /// A prism of `sides` faces around z (a polygon of circumradius `radius`), centred
    /// on the origin, `2 half_height` long: a peg; closed and outward.
    pub fn prism(sides: u32, radius: f64, half_height: f64) -> Mesh {
        let n = sides.max(3);
        let mut vertices = Vec::with_capacity(2 * n as usize + 2);
        for z in [-half_height, half_height] {
            for k in 0..n {
                let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
                vertices.push([radius * a.cos(), radius * a.sin(), z]);
            }
        }
        vertices.push([0.0, 0.0, -half_height]);
        vertices.push([0.0, 0.0, half_height]);
        let (bottom, top) = (2 * n, 2 * n + 1);
        let mut triangles = Vec::with_capacity(4 * n as usize);
        for k in 0..n {
            let j = (k + 1) % n;
            triangles.push([k, j, n + j]);
            triangles.push([k, n + j, n + k]);
            triangles.push([bottom, j, k]);
            triangles.push([top, n + k, n + j]);
        }
        Mesh {
            vertices,
            triangles,
        }
    }

    /// A box centred on the origin, 12 triangles, closed and outward (the tests' and
    /// the fuzz seeds' mesh).
    pub fn cuboid(h: [f64; 3]) -> Mesh {
        let vertices = (0..8)
            .map(|i| {
                let s = |b: usize| if i & b == 0 { -1.0 } else { 1.0 };
                [s(1) * h[0], s(2) * h[1], s(4) * h[2]]
            })
            .collect();
        // Faces as quads (outward, counter-clockwise), split in two.
        let quads = [
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Mesh {
            vertices,
            triangles,
        }
    }
}

#[cfg(test)]
mod tests;
