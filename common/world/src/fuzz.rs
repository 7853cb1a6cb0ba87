//! The mesh readers as a target of `tactile fuzz`: its seeds (a closed box in each
//! format) and a run over one input, whose outcome in words tells the readers' paths
//! apart. Registered in deploy/src/cmd/fuzz (see docs/16).

use crate::mesh::{self, Mesh};

/// The target's name, as `--target` names it.
pub const NAME: &str = "meshes";

/// Valid inputs to start from: a box as binary STL, ASCII STL and OBJ.
pub fn seeds() -> Vec<Vec<u8>> {
    let m = Mesh::cuboid([0.01, 0.02, 0.03]);
    vec![
        mesh::to_stl_binary(&m),
        mesh::to_stl_ascii(&m, "seed").into_bytes(),
        mesh::to_obj(&m).into_bytes(),
    ]
}

/// Tokens mutations put in place of a number or insert.
pub const DICT: &[&str] = &[
    "nan",
    "1e300",
    "-1e300",
    "inf",
    "0",
    "-1",
    "facet",
    "vertex",
    "endloop",
    "f",
    "v",
    "solid",
    "4294967295",
];

/// Reads `bytes` as STL and as OBJ, and checks each mesh closed; the outcome in words.
pub fn run(bytes: &[u8]) -> String {
    let one = |r: Result<Mesh, mesh::MeshError>| match r {
        Ok(m) => match m.check_closed() {
            Ok(()) => "closed".to_string(),
            Err(e) => e.to_string(),
        },
        Err(e) => e.to_string(),
    };
    format!(
        "{} / {}",
        one(mesh::parse_stl(bytes)),
        one(mesh::parse_obj(bytes))
    )
}
