//! Meshes read as clouds: the seed meshes of the fuzz corpora (a unit
//! tetrahedron as binary and ascii STL, OBJ with `vn`, binary and ascii PLY
//! with faces, and a square pyramid OBJ with a quad) give their vertices
//! with outward unit normals; PLY faces that name a missing vertex or end
//! early are a warning and no normals; format detection by content.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use scanfit::{Point3, Vector3};
use scanfit_io::{parse_cloud, read_cloud, Format, ReadOptions};

fn seed(dir: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus")
        .join(dir)
        .join(name)
}

/// The normals of `path` read as a cloud, checked outward from `centre`.
fn outward(path: &Path, points: usize, centre: Point3) -> Vec<Vector3> {
    let t = read_cloud(path, &ReadOptions::default()).unwrap();
    assert!(t.warnings.is_empty(), "{:?}", t.warnings);
    let c = t.into_cloud().unwrap();
    assert_eq!(c.len(), points, "{}", path.display());
    let n = c.normals().expect("normals from the faces");
    for (p, n) in c.points().iter().zip(&n) {
        assert!((n.norm() - 1.0).abs() < 1e-12);
        assert!(n.dot(&(p - centre)) > 0.0, "{}: {p} {n}", path.display());
    }
    n
}

#[test]
fn seed_meshes_give_their_vertices_with_outward_normals() {
    let centre = Point3::new(0.25, 0.25, 0.25);
    let want = outward(&seed("stl", "tetra_binary.stl"), 4, centre);
    // the same tetrahedron in every format gives the same area-weighted normals
    for (dir, name) in [
        ("stl", "tetra_ascii.stl"),
        ("ply", "tetra_faces_le.ply"),
        ("ply", "tetra_faces_ascii.ply"),
    ] {
        let got = outward(&seed(dir, name), 4, centre);
        // (binary STL welds in first-use order: compare as sets)
        for g in &got {
            assert!(want.iter().any(|w| (w - g).norm() < 1e-7), "{name}: {g}");
        }
    }
    // vn given: the origin's normal is the mean of -z, -y, -x
    let n = outward(&seed("obj", "tetra_vn.obj"), 4, centre);
    assert!((n[0] + Vector3::new(1.0, 1.0, 1.0).normalize()).norm() < 1e-12);
    // a quad base and four sides: the base corners lean down and out
    let n = outward(
        &seed("obj", "pyramid_quad.obj"),
        5,
        Point3::new(0.5, 0.5, 0.3),
    );
    assert_eq!(n[4], Vector3::z());
}

#[test]
fn bad_faces_are_a_warning_and_detection_is_by_content() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    let t = parse_cloud(
        Path::new("m.ply"),
        format!("{head}3 0 1 7\n").as_bytes(),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(t.columns.len(), 3);
    assert!(
        t.warnings[0]
            .starts_with("m.ply:13: face 0 names vertex 7, but the file has 3 vertices (0 to 2)"),
        "{:?}",
        t.warnings
    );
    let t = parse_cloud(
        Path::new("m.ply"),
        format!("{head}3 0 1 2\n").as_bytes(),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(t.column("nz").unwrap(), &[1.0, 1.0, 1.0]);
    // binary, faces before the vertices, truncated inside the face list
    let mut b = b"ply\nformat binary_big_endian 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
    b.push(3);
    for i in [0i32, 2, 1] {
        b.extend_from_slice(&i.to_be_bytes());
    }
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        for c in p {
            b.extend_from_slice(&c.to_be_bytes());
        }
    }
    let t = parse_cloud(Path::new("b.ply"), &b, &ReadOptions::default()).unwrap();
    assert_eq!(t.column("nz").unwrap(), &[-1.0, -1.0, -1.0]);
    // no extension: STL and OBJ by their first bytes
    let stl = std::fs::read(seed("stl", "tetra_ascii.stl")).unwrap();
    let obj = std::fs::read(seed("obj", "tetra_vn.obj")).unwrap();
    let bin = std::fs::read(seed("stl", "tetra_binary.stl")).unwrap();
    for (bytes, want) in [
        (&stl, Format::Stl),
        (&obj, Format::Obj),
        (&bin, Format::Stl),
    ] {
        assert_eq!(Format::sniff(bytes), want);
        let t = parse_cloud(Path::new("mesh"), bytes, &ReadOptions::default()).unwrap();
        assert_eq!((t.format, t.points.len()), (want, 4));
    }
    // an STL named .xyz: by its magic, with a warning
    let t = parse_cloud(Path::new("m.xyz"), &stl, &ReadOptions::default()).unwrap();
    assert_eq!(t.format, Format::Stl);
    assert!(
        t.warnings[0].contains("the content is STL (by its first bytes)"),
        "{:?}",
        t.warnings
    ); // every magic-detectable format named .xyz (or .csv, .txt) is read as what
       // it is: a PLY, a binary STL, an OBJ (by its first statement)
    let ply = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 2 3\n".to_vec();
    for (name, bytes, want, n) in [
        ("p.xyz", &ply, Format::Ply, 2),
        ("b.csv", &bin, Format::Stl, 4),
        ("o.txt", &obj, Format::Obj, 4),
    ] {
        let t = parse_cloud(Path::new(name), bytes, &ReadOptions::default()).unwrap();
        assert_eq!((t.format, t.points.len()), (want, n), "{name}");
        assert!(
            t.warnings[0].contains(&format!("the content is {}", want.name())),
            "{:?}",
            t.warnings
        );
    }
    // a real text file stays text, with no warning
    let t = parse_cloud(
        Path::new("t.xyz"),
        b"x y z\n0 0 0\n1 1 1\n",
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(
        (t.format, t.points.len(), t.warnings.len()),
        (Format::Text, 2, 0)
    );
}

/// A small mutation campaign on stable (the cargo-fuzz targets `stl` and
/// `obj` do this coverage-guided): 3000 deterministic mutants of each mesh
/// seed (bytes overwritten with boundary values, runs deleted, duplicated,
/// truncated; counts in binary headers set to extremes), each read as STL,
/// OBJ and PLY without a panic. Returns nothing: Ok and Err are both fine.
#[test]
fn mutated_meshes_never_panic() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n.max(1) as u64) as usize
    };
    let seeds = [
        ("stl", "tetra_binary.stl"),
        ("stl", "tetra_ascii.stl"),
        ("obj", "tetra_vn.obj"),
        ("obj", "pyramid_quad.obj"),
        ("ply", "tetra_faces_le.ply"),
        ("ply", "tetra_faces_ascii.ply"),
    ];
    let specials: [&[u8]; 8] = [
        b"\xff\xff\xff\xff",
        b"\x00\x00\x00\x80",
        b"-0",
        b"nan",
        b"1e309",
        b"-99999999999",
        b"/",
        b"\r",
    ];
    let mut accepted = 0;
    for (dir, name) in seeds {
        let base = std::fs::read(seed(dir, name)).unwrap();
        for _ in 0..3000 {
            let mut m = base.clone();
            for _ in 0..1 + rnd(4) {
                let at = rnd(m.len() + 1);
                match rnd(5) {
                    0 => m.truncate(at),
                    1 => {
                        let s = specials[rnd(specials.len())];
                        let end = (at + s.len()).min(m.len());
                        m.splice(at..end, s.iter().copied());
                    }
                    2 => {
                        let end = (at + 1 + rnd(16)).min(m.len());
                        m.drain(at..end);
                    }
                    3 => {
                        let end = (at + 1 + rnd(64)).min(m.len());
                        let run = m[at..end].to_vec();
                        m.splice(at..at, run);
                    }
                    _ => {
                        if let Some(b) = m.get_mut(at) {
                            *b = rnd(256) as u8;
                        }
                    }
                }
            }
            for as_name in ["f.stl", "f.obj", "f.ply"] {
                let read = scanfit_io::fuzz::point_file(as_name, &m);
                accepted += usize::from(read.unwrap_or_else(|e| panic!("{as_name}: {e}")));
            }
        }
    }
    eprintln!("{accepted} of {} mutant reads accepted", 6 * 3000 * 3);
}
