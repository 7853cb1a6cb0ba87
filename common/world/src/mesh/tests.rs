use super::*;

fn cube() -> Mesh {
    Mesh::cuboid([0.5, 1.0, 2.0])
}

#[test]
fn a_cube_reads_back_from_each_format_closed() {
    let m = cube();
    m.check_closed().expect("the generator's cube is closed");
    let name = "c";
    for (what, got) in [
        ("binary", parse_stl(&to_stl_binary(&m))),
        ("ascii", parse_stl(to_stl_ascii(&m, name).as_bytes())),
        ("obj", parse_obj(to_obj(&m).as_bytes())),
    ] {
        let got = got.unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(got.vertices.len(), 8, "{what}");
        assert_eq!(got.triangles.len(), 12, "{what}");
        got.check_closed().unwrap_or_else(|e| panic!("{what}: {e}"));
    }
}

#[test]
fn a_binary_stl_whose_header_says_solid_is_read_as_binary() {
    let mut b = to_stl_binary(&cube());
    b[..6].copy_from_slice(b"solid ");
    assert_eq!(parse_stl(&b).expect("binary").triangles.len(), 12);
}

#[test]
fn empty_truncated_and_oversized_files_are_refused() {
    assert_eq!(parse_stl(b""), Err(MeshError::Empty));
    assert_eq!(parse_obj(b""), Err(MeshError::Empty));
    assert_eq!(parse_obj(b"# nothing\nv 0 0 0\n"), Err(MeshError::Empty));
    let b = to_stl_binary(&cube());
    let cut = &b[..b.len() - 7];
    assert!(
        matches!(parse_stl(cut), Err(MeshError::Truncated { count: 12, .. })),
        "{:?}",
        parse_stl(cut)
    );
    let ascii = to_stl_ascii(&cube(), "c");
    let cut = &ascii[..ascii.len() / 2];
    assert!(matches!(
        parse_stl(cut.as_bytes()),
        Err(MeshError::Syntax { .. })
    ));
    // 10^7 triangles claimed: refused from the header, nothing allocated for them.
    let mut huge = vec![0u8; 84];
    huge[80..84].copy_from_slice(&10_000_000u32.to_le_bytes());
    assert_eq!(
        parse_stl(&huge),
        Err(MeshError::TooManyTriangles(10_000_000))
    );
}

#[test]
fn binary_garbage_is_refused() {
    // A fixed pseudo-random sequence (an LCG): no STL count matches its length.
    let mut x = 12345u64;
    let junk: Vec<u8> = (0..4000)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 56) as u8
        })
        .collect();
    assert!(parse_stl(&junk).is_err());
    assert!(matches!(parse_obj(&junk), Err(MeshError::Syntax { .. })));
}

#[test]
fn nan_and_huge_vertices_are_refused() {
    for bad in ["nan", "1e300", "inf"] {
        let obj = format!("v 0 0 0\nv 1 0 0\nv 0 {bad} 0\nf 1 2 3\n");
        assert!(
            matches!(
                parse_obj(obj.as_bytes()),
                Err(MeshError::BadVertex { index: 2, .. })
            ),
            "{bad}: {:?}",
            parse_obj(obj.as_bytes())
        );
        let stl = format!("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 {bad} 0\nendloop\nendfacet\nendsolid x\n");
        assert!(
            matches!(
                parse_stl(stl.as_bytes()),
                Err(MeshError::BadVertex { index: 2, .. })
            ),
            "{bad}"
        );
    }
    let mut b = to_stl_binary(&cube());
    b[84 + 12..84 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(matches!(
        parse_stl(&b),
        Err(MeshError::BadVertex { index: 0, .. })
    ));
}

#[test]
fn an_open_or_inconsistent_surface_is_not_closed() {
    let mut m = cube();
    m.triangles.pop();
    assert!(
        matches!(m.check_closed(), Err(MeshError::NotClosed { open: 3, .. })),
        "{:?}",
        m.check_closed()
    );
    let mut m = cube();
    m.triangles[0].swap(1, 2);
    assert!(matches!(m.check_closed(), Err(MeshError::NotClosed { .. })));
    let mut m = cube();
    let t = m.triangles[0];
    m.triangles.push(t);
    assert!(matches!(m.check_closed(), Err(MeshError::NotClosed { .. })));
}

#[test]
fn obj_faces_are_fanned_and_indices_checked() {
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1/1 2//2 3 -1\n";
    assert_eq!(
        parse_obj(quad.as_bytes()).expect("quad").triangles,
        [[0, 1, 2], [0, 2, 3]]
    );
    for bad in ["f 1 2 9", "f 0 1 2", "f 1 2", "f a b c", "vertex 1 2 3"] {
        let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{bad}\n");
        assert!(
            matches!(parse_obj(text.as_bytes()), Err(MeshError::Syntax { .. })),
            "{bad}"
        );
    }
}

#[test]
fn files_are_read_by_extension_with_a_size_cap() {
    let d = tempfile::tempdir().expect("temp dir");
    let p = d.path().join("c.STL");
    std::fs::write(&p, to_stl_binary(&cube())).expect("write");
    assert_eq!(read(&p).expect("read").triangles.len(), 12);
    let p = d.path().join("c.ply");
    std::fs::write(&p, b"ply").expect("write");
    assert!(matches!(read(&p), Err(MeshError::UnknownFormat { .. })));
    let big = d.path().join("big.obj");
    std::fs::File::create(&big)
        .and_then(|f| f.set_len(MAX_MESH_BYTES + 1))
        .expect("sparse");
    assert!(matches!(read(&big), Err(MeshError::TooLarge { .. })));
    assert!(matches!(
        read(&d.path().join("none.obj")),
        Err(MeshError::Io { .. })
    ));
}

#[test]
fn a_prism_is_closed() {
    let m = Mesh::prism(8, 0.005, 0.02);
    assert_eq!(m.triangles.len(), 32);
    m.check_closed().expect("closed");
}

/// deploy/scenarios/meshes/ holds what the writers make (`TACTILE_WRITE_MESHES=1`
/// writes them anew).
#[test]
fn the_shipped_meshes_are_the_writers_and_closed() {
    let dir =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../deploy/scenarios/meshes");
    let files: [(&str, Vec<u8>); 3] = [
        (
            "block.stl",
            to_stl_binary(&Mesh::cuboid([0.02, 0.02, 0.02])),
        ),
        (
            "peg.obj",
            to_obj(&Mesh::prism(16, 0.005, 0.03)).into_bytes(),
        ),
        (
            "hole-block.stl",
            to_stl_binary(&Mesh::block_with_hole(0.03, 0.02, 32, 0.0055, 0.03)),
        ),
    ];
    for (name, bytes) in &files {
        let p = dir.join(name);
        if std::env::var("TACTILE_WRITE_MESHES").is_ok_and(|v| v == "1") {
            std::fs::create_dir_all(&dir).expect("folder");
            std::fs::write(&p, bytes).expect("write");
        }
        assert_eq!(&std::fs::read(&p).expect("a shipped mesh"), bytes, "{name}");
        read(&p).expect("reads").check_closed().expect("closed");
    }
}

/// The block with a hole is closed, faces outward (its signed volume is the box's
/// less the hole's, which only an outward surface gives), and its hole's walls are
/// at the inscribed radius asked for.
#[test]
fn a_block_with_a_hole_is_closed_and_holds_the_volume_it_should() {
    let (h, n, r, d) = ([0.03, 0.03, 0.015], 32u32, 0.0055, 0.02);
    let m = Mesh::block_with_hole(h[0], h[2], n, r, d);
    m.check_closed().expect("closed");
    let v = &m.vertices;
    let volume: f64 = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v[i as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum();
    let angle = std::f64::consts::PI / f64::from(n);
    // A regular n-gon of inscribed radius r has area n r^2 tan(pi / n).
    let hole = f64::from(n) * r * r * angle.tan() * d;
    let want = 8.0 * h[0] * h[1] * h[2] - hole;
    assert!((volume - want).abs() < 1e-12, "{volume} m^3, want {want}");
    // Every wall's midpoint at the top is r from the axis.
    let top: Vec<&[f64; 3]> = v
        .iter()
        .filter(|p| p[2] == h[2] && (p[0].hypot(p[1]) - r / angle.cos()).abs() < 1e-12)
        .collect();
    assert_eq!(top.len(), n as usize);
    let (a, b) = (top[0], top[1]);
    let mid = ((a[0] + b[0]) / 2.0).hypot((a[1] + b[1]) / 2.0);
    assert!((mid - r).abs() < 1e-12, "{mid}");
}
