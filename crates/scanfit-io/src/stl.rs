//! STL reader (binary and ascii) as a point cloud: the triangles' corners,
//! welded where they are bit-identical (STL repeats a shared corner in every
//! triangle), with area-weighted vertex normals from the triangles
//! (`mesh.rs`; the stored facet normals are often zero or stale, the winding
//! is what every STL writer gets right).
//!
//! Binary: an 80-byte header, a little-endian `u32` triangle count, then 50
//! bytes per triangle (normal, three corners as `f32`, a `u16`). The count is
//! checked against the file's size before anything is allocated. A file that
//! starts with `solid` is ascii unless its size is exactly that of a binary
//! file with its count (binary writers put `solid` in the header too).
//!
//! Ascii: `solid`, then `facet normal .. / outer loop / vertex x y z (3 or
//! more) / endloop / endfacet`, `endsolid`; errors name the line.

use std::collections::HashMap;
use std::path::Path;

use scanfit::Point3;

use crate::mesh::{attach_normals, fan, Triangle};
use crate::table::{split_lines, Format, Origin, PointTable, ReadOptions};
use crate::{Error, Result};

const HEADER: usize = 84;
const RECORD: usize = 50;

/// Whether `bytes` look like an STL file: a binary file whose size matches
/// its triangle count, or ascii starting with `solid` with a `facet` soon
/// after.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    binary_size_matches(bytes) || ascii_magic(bytes)
}

fn ascii_magic(bytes: &[u8]) -> bool {
    let head = bytes.get(..bytes.len().min(1024)).unwrap_or_default();
    let text = String::from_utf8_lossy(head);
    text.trim_start().starts_with("solid") && (text.contains("facet") || text.contains("endsolid"))
}

fn binary_size_matches(bytes: &[u8]) -> bool {
    count(bytes)
        .is_some_and(|n| (n as u128) * (RECORD as u128) + HEADER as u128 == bytes.len() as u128)
}

fn count(bytes: &[u8]) -> Option<u32> {
    let b: [u8; 4] = bytes.get(80..84)?.try_into().ok()?;
    Some(u32::from_le_bytes(b))
}

/// Reads an STL file's bytes (`path` is for messages).
pub(crate) fn parse(path: &Path, bytes: &[u8], options: &ReadOptions) -> Result<PointTable> {
    // ascii: `solid` and a facet (or `endsolid`) in the first kilobyte,
    // unless the size is exactly that of a binary file with its count
    let mut table = if ascii_magic(bytes) && !binary_size_matches(bytes) {
        parse_ascii(path, bytes)?
    } else {
        parse_binary(path, bytes)?
    };
    table.0.warnings.extend(table.2);
    attach_normals(&mut table.0, &table.1);
    table.0.finish(options.non_finite)
}

/// Welds corners by their exact value (`-0.0` and `0.0` alike).
#[derive(Default)]
struct Welder {
    index: HashMap<[u64; 3], u32>,
    points: Vec<Point3>,
}

impl Welder {
    /// The index of `p`, and whether it is new.
    fn add(&mut self, p: Point3) -> (u32, bool) {
        let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
        let next = self.points.len() as u32;
        let i = *self.index.entry(key).or_insert(next);
        let new = i == next;
        if new {
            self.points.push(p);
        }
        (i, new)
    }
}

fn table(path: &Path, points: Vec<Point3>, origin: Origin) -> PointTable {
    PointTable {
        path: path.to_path_buf(),
        format: Format::Stl,
        points,
        columns: vec!["x".into(), "y".into(), "z".into()],
        extra: Vec::new(),
        origin,
        file_index: None,
        dropped_non_finite: 0,
        warnings: Vec::new(),
    }
}

type Parsed = (PointTable, Vec<Triangle>, Vec<String>);

fn parse_binary(path: &Path, bytes: &[u8]) -> Result<Parsed> {
    let Some(n) = count(bytes) else {
        return Err(Error::Binary {
            path: path.to_path_buf(),
            offset: bytes.len() as u64,
            message: format!(
                "the file has {} bytes, fewer than the 84 of a binary STL header (80 bytes, then the triangle count); it is truncated or not an STL file",
                bytes.len()
            ),
        });
    };
    let body = bytes.len() - HEADER;
    let need = n as u128 * RECORD as u128;
    if need > body as u128 {
        return Err(Error::Binary {
            path: path.to_path_buf(),
            offset: 80,
            message: format!(
                "the header declares {n} triangles ({need} bytes), but only {body} bytes follow: {} complete triangles; the file is truncated or its count is wrong",
                body / RECORD
            ),
        });
    }
    let mut warnings = Vec::new();
    let spare = body - need as usize;
    if spare > 0 {
        warnings.push(format!(
            "{}: {spare} bytes follow the {n} triangles the header declares; they were not read",
            path.display()
        ));
    }
    let mut weld = Welder::default();
    let mut offsets = Vec::new();
    let mut triangles = Vec::with_capacity(n as usize);
    for t in 0..n as usize {
        let rec = HEADER + t * RECORD;
        let mut tri = [0u32; 3];
        for (k, slot) in tri.iter_mut().enumerate() {
            let at = rec + 12 + 12 * k;
            let f = |o: usize| {
                bytes
                    .get(at + o..at + o + 4)
                    .and_then(|b| b.try_into().ok())
                    .map_or(f64::NAN, |b: [u8; 4]| f64::from(f32::from_le_bytes(b)))
            };
            let (i, new) = weld.add(Point3::new(f(0), f(4), f(8)));
            if new {
                offsets.push(at as u64);
            }
            *slot = i;
        }
        triangles.push(tri);
    }
    Ok((
        table(path, weld.points, Origin::Offsets(offsets)),
        triangles,
        warnings,
    ))
}

fn parse_ascii(path: &Path, bytes: &[u8]) -> Result<Parsed> {
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes
            .get(..e.valid_up_to())
            .unwrap_or_default()
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        perr(line, "not UTF-8 text in an ascii STL file (it starts with 'solid'); is it a binary STL whose size disagrees with its triangle count?".into())
    })?;
    let mut weld = Welder::default();
    let mut lines = Vec::new();
    let mut triangles = Vec::new();
    // the corners of the loop being read, and the line its facet began on
    let mut ring: Vec<u32> = Vec::new();
    let mut in_loop: Option<usize> = None;
    for (no, line) in split_lines(text) {
        let mut tok = line.split_ascii_whitespace();
        let Some(word) = tok.next() else { continue };
        match word {
            "solid" | "endsolid" | "facet" | "endfacet" => {}
            "outer" => {
                if let Some(open) = in_loop {
                    return Err(perr(no, format!("'outer loop' inside the loop opened on line {open}; close it with 'endloop' first")));
                }
                in_loop = Some(no);
                ring.clear();
            }
            "vertex" => {
                if in_loop.is_none() {
                    return Err(perr(
                        no,
                        "'vertex' outside an 'outer loop ... endloop' block".into(),
                    ));
                }
                let mut xyz = [0.0; 3];
                for (k, v) in xyz.iter_mut().enumerate() {
                    let t = tok.next().ok_or_else(|| {
                        perr(
                            no,
                            format!(
                                "'vertex' needs three numbers x y z; {} missing",
                                ["x", "y", "z"][k]
                            ),
                        )
                    })?;
                    *v = t
                        .parse()
                        .map_err(|_| perr(no, format!("'{t}' is not a number")))?;
                }
                if tok.next().is_some() {
                    return Err(perr(no, "'vertex' has more than three numbers".into()));
                }
                let (i, new) = weld.add(Point3::from(xyz));
                if new {
                    lines.push(no);
                }
                ring.push(i);
            }
            "endloop" => {
                let Some(open) = in_loop.take() else {
                    return Err(perr(no, "'endloop' without an 'outer loop'".into()));
                };
                if ring.len() < 3 {
                    return Err(perr(
                        no,
                        format!("the loop opened on line {open} has {} vertices; a facet needs at least 3", ring.len()),
                    ));
                }
                fan(&ring, &mut triangles);
            }
            other => {
                let shown: String = other.chars().take(32).collect();
                return Err(perr(no, format!("unknown keyword '{shown}'; an ascii STL has solid, facet, outer loop, vertex, endloop, endfacet and endsolid lines")));
            }
        }
    }
    if let Some(open) = in_loop {
        return Err(perr(
            open,
            "the file ends inside this 'outer loop' (no 'endloop'); it is truncated".into(),
        ));
    }
    Ok((
        table(path, weld.points, Origin::Lines(lines)),
        triangles,
        Vec::new(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use scanfit::Vector3;

    /// A unit tetrahedron with outward winding, as binary STL.
    pub(crate) fn tetra_binary() -> Vec<u8> {
        let v = [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
        let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let mut b = vec![b' '; 80];
        b[..5].copy_from_slice(b"solid");
        b.extend_from_slice(&4u32.to_le_bytes());
        for f in faces {
            b.extend_from_slice(&[0u8; 12]);
            for i in f {
                for c in v[i] {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    fn read(name: &str, bytes: &[u8]) -> Result<PointTable> {
        parse(Path::new(name), bytes, &ReadOptions::default())
    }

    #[test]
    fn binary_tetrahedron_welds_and_points_out() {
        let b = tetra_binary();
        assert!(sniff(&b));
        let t = read("t.stl", &b).unwrap();
        assert_eq!(t.points.len(), 4);
        assert_eq!(t.columns, ["x", "y", "z", "nx", "ny", "nz"]);
        let c = t.clone().into_cloud().unwrap();
        let centre = Point3::new(0.25, 0.25, 0.25);
        for (p, n) in c.points().iter().zip(c.normals().unwrap()) {
            assert!(n.dot(&(p - centre)) > 0.0, "{p} {n}");
        }
        // the apex (0,0,1): faces 1 and 2 (normals -y, -x, area 1/2) and the
        // slanted one ((1,1,1), area sqrt(3)/2): (1,1,1) + (0,-1,0) + (-1,0,0)
        let apex = c.points().iter().position(|p| p.z == 1.0).unwrap();
        assert!((c.normals().unwrap()[apex] - Vector3::z()).norm() < 1e-15);
        // record offsets locate the first use of each vertex
        assert_eq!(t.byte_offset(0), Some(84 + 12));
        // truncated and lying counts
        let e = read("t.stl", &b[..b.len() - 1]).unwrap_err().to_string();
        assert!(e.starts_with("t.stl: byte offset 80: the header declares 4 triangles (200 bytes), but only 199 bytes follow: 3 complete"), "{e}");
        let e = read("t.stl", &b[..50]).unwrap_err().to_string();
        assert!(e.contains("fewer than the 84"), "{e}");
        let mut more = b.clone();
        more.extend_from_slice(&[0; 7]);
        let t = read("t.stl", &more).unwrap();
        assert!(
            t.warnings[0].contains("7 bytes follow the 4 triangles"),
            "{:?}",
            t.warnings
        );
        let mut huge = b.clone();
        huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(read("t.stl", &huge)
            .unwrap_err()
            .to_string()
            .contains("4294967295 triangles"));
    }

    #[test]
    fn ascii_with_a_quad_and_errors_with_lines() {
        let s = "solid x\n facet normal 0 0 0\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n";
        assert!(sniff(s.as_bytes()));
        let t = read("q.stl", s.as_bytes()).unwrap();
        assert_eq!(t.points.len(), 4);
        assert_eq!(t.column("nz").unwrap(), &[1.0; 4]);
        assert_eq!(t.locate(3), "q.stl:7");
        for (bad, want) in [
            (
                s.replace("vertex 1 1 0", "vertex 1 1"),
                "q.stl:6: 'vertex' needs three numbers x y z; z missing",
            ),
            (
                s.replace("vertex 1 1 0", "vertex 1 a 0"),
                "q.stl:6: 'a' is not a number",
            ),
            (
                s.replace("endloop", "endloops"),
                "q.stl:8: unknown keyword 'endloops'",
            ),
            (
                s.replace("  endloop\n", ""),
                "q.stl:3: the file ends inside",
            ),
            (
                s.replace("   vertex 1 1 0\n   vertex 0 1 0\n", ""),
                "q.stl:6: the loop opened on line 3 has 2 vertices",
            ),
            ("solid\nendsolid\n".to_string(), "q.stl: no points found"),
        ] {
            let e = read("q.stl", bad.as_bytes()).unwrap_err().to_string();
            assert!(e.starts_with(want), "{e}");
        }
        // a NaN corner: rejected by default with its line, dropped on request
        let nan = s.replace("vertex 1 1 0", "vertex 1 nan 0");
        let e = read("q.stl", nan.as_bytes()).unwrap_err().to_string();
        assert!(e.starts_with("q.stl:6: y is NaN"), "{e}");
    }
}
