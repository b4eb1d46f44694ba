//! Wavefront OBJ reader as a point cloud: the `v` vertices, with per-vertex
//! normals from the file's `vn` (when every face corner names one: the
//! normalised sum of the normals a vertex is given) or else area-weighted
//! from the `f` faces (`mesh.rs`). Every other statement (`vt`, `o`, `g`,
//! `s`, `usemtl`, `mtllib`, `l`, ...) is ignored.
//!
//! Face corners are `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based, negative
//! for "counted back from the last one defined"; a corner must name a
//! vertex defined before its line. Errors name the line.

use std::path::Path;

use scanfit::{Point3, Vector3};

use crate::mesh::{attach_normals, fan, Triangle};
use crate::table::{split_lines, Format, Origin, PointTable, ReadOptions};
use crate::{Error, Result};

/// Whether `bytes` look like an OBJ file: its first statement (after
/// comments and blank lines) is `v`, `vn`, `vt`, `o`, `g`, `mtllib` or
/// `usemtl`.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(bytes.get(..bytes.len().min(4096)).unwrap_or_default());
    head.lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
        .and_then(|l| l.split_ascii_whitespace().next())
        .is_some_and(|w| ["v", "vn", "vt", "o", "g", "mtllib", "usemtl"].contains(&w))
}

/// The parts of an OBJ file that make the cloud.
#[derive(Default)]
struct Obj {
    points: Vec<Point3>,
    lines: Vec<usize>,
    normals: Vec<Vector3>,
    triangles: Vec<Triangle>,
    /// per vertex, the sum of the `vn` its face corners name
    given: Vec<Vector3>,
    /// whether every face corner names a `vn`
    all_given: bool,
}

/// Reads an OBJ file's bytes (`path` is for messages).
pub(crate) fn parse(path: &Path, bytes: &[u8], options: &ReadOptions) -> Result<PointTable> {
    let text = String::from_utf8_lossy(bytes);
    let obj = read(path, &text)?;
    let mut table = PointTable {
        path: path.to_path_buf(),
        format: Format::Obj,
        points: obj.points,
        columns: vec!["x".into(), "y".into(), "z".into()],
        extra: Vec::new(),
        origin: Origin::Lines(obj.lines),
        file_index: None,
        dropped_non_finite: 0,
        warnings: Vec::new(),
    };
    if obj.all_given && !obj.triangles.is_empty() {
        let used = used_vertices(table.points.len(), &obj.triangles);
        let ok = obj
            .given
            .iter()
            .zip(&used)
            .all(|(n, &u)| u && n.norm() > 0.0 && n.iter().all(|c| c.is_finite()));
        if ok {
            let unit: Vec<Vector3> = obj.given.iter().map(|n| n.normalize()).collect();
            for (c, name) in ["nx", "ny", "nz"].into_iter().enumerate() {
                table.columns.push(name.into());
                table.extra.push(unit.iter().map(|n| n[c]).collect());
            }
        }
    }
    attach_normals(&mut table, &obj.triangles);
    table.finish(options.non_finite)
}

fn used_vertices(n: usize, triangles: &[Triangle]) -> Vec<bool> {
    let mut used = vec![false; n];
    for t in triangles {
        for &v in t {
            if let Some(u) = used.get_mut(v as usize) {
                *u = true;
            }
        }
    }
    used
}

/// A 1-based or negative OBJ index into `count` defined items, as 0-based.
fn resolve(token: &str, count: usize, what: &str) -> std::result::Result<usize, String> {
    let i: i64 = token
        .parse()
        .map_err(|_| format!("{what} index '{token}' is not an integer"))?;
    let k = if i > 0 {
        usize::try_from(i - 1).ok().filter(|&k| k < count)
    } else if i < 0 {
        usize::try_from(i.unsigned_abs())
            .ok()
            .and_then(|b| count.checked_sub(b))
    } else {
        return Err(format!(
            "{what} index 0; OBJ indices start at 1 (or count back from -1)"
        ));
    };
    k.ok_or_else(|| format!("{what} index {i}, but only {count} defined before this line"))
}

fn read(path: &Path, text: &str) -> Result<Obj> {
    let perr = |line: usize, message: String| Error::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut obj = Obj {
        all_given: true,
        ..Obj::default()
    };
    let mut ring: Vec<u32> = Vec::new();
    for (no, line) in split_lines(text) {
        let mut tok = line.split_ascii_whitespace();
        match tok.next() {
            Some("v") | Some("vn") => {
                let is_v =
                    line.trim_start().starts_with("v ") || line.trim_start().starts_with("v\t");
                let mut xyz = [0.0; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let t = tok.next().ok_or_else(|| {
                        perr(
                            no,
                            format!(
                                "'{}' needs three numbers x y z; {} missing",
                                if is_v { "v" } else { "vn" },
                                ["x", "y", "z"][k]
                            ),
                        )
                    })?;
                    *c = t
                        .parse()
                        .map_err(|_| perr(no, format!("'{t}' is not a number")))?;
                }
                // (a `v` may go on with w or a colour: ignored)
                if is_v {
                    obj.points.push(Point3::from(xyz));
                    obj.lines.push(no);
                    obj.given.push(Vector3::zeros());
                } else {
                    obj.normals.push(Vector3::from(xyz));
                }
            }
            Some("f") => {
                ring.clear();
                let mut given = Vec::new();
                for corner in tok {
                    let mut parts = corner.split('/');
                    let v = parts.next().unwrap_or_default();
                    let v = resolve(v, obj.points.len(), "vertex").map_err(|m| perr(no, m))?;
                    let _texture = parts.next();
                    match parts.next().filter(|s| !s.is_empty()) {
                        Some(n) => {
                            let n =
                                resolve(n, obj.normals.len(), "normal").map_err(|m| perr(no, m))?;
                            given.push((v, n));
                        }
                        None => obj.all_given = false,
                    }
                    ring.push(v as u32);
                }
                if ring.len() < 3 {
                    return Err(perr(
                        no,
                        format!(
                            "a face needs at least 3 vertices; this one has {}",
                            ring.len()
                        ),
                    ));
                }
                for (v, n) in given {
                    if let (Some(s), Some(n)) = (obj.given.get_mut(v), obj.normals.get(n)) {
                        *s += n;
                    }
                }
                fan(&ring, &mut obj.triangles);
            }
            _ => {}
        }
    }
    Ok(obj)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_obj(s: &str) -> Result<PointTable> {
        parse(Path::new("m.obj"), s.as_bytes(), &ReadOptions::default())
    }

    const CUBE_TOP: &str = "# a square\nmtllib m.mtl\no top\nv 0 0 1\nv 1 0 1\nv 1 1 1 0.5 0.5 0.5\nv 0 1 1\nvt 0 0\nusemtl red\nf 1 2 3\nf -4 -2 -1\n";

    #[test]
    fn faces_give_normals_and_the_rest_is_ignored() {
        assert!(sniff(CUBE_TOP.as_bytes()));
        assert!(!sniff(b"1 2 3\n"));
        let t = read_obj(CUBE_TOP).unwrap();
        assert_eq!(t.points.len(), 4);
        assert_eq!(t.column("nz").unwrap(), &[1.0; 4]);
        assert_eq!(t.locate(2), "m.obj:6");
        // given normals win, averaged per vertex
        let given = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 -1\nvn 0 -1 0\nf 1//1 2//1 3//2\n";
        let t = read_obj(given).unwrap();
        assert_eq!(t.column("nz").unwrap(), &[-1.0, -1.0, 0.0]);
        assert_eq!(t.column("ny").unwrap(), &[0.0, 0.0, -1.0]);
        // a vertex on no face: no normals, a warning
        let t = read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 1 2 3\n").unwrap();
        assert_eq!(t.columns.len(), 3);
        assert!(
            t.warnings[0].contains("1 of 4 vertices lie on no triangle"),
            "{:?}",
            t.warnings
        );
        // points only
        assert_eq!(read_obj("v 1 2 3\n").unwrap().points.len(), 1);
    }

    #[test]
    fn errors_name_the_line() {
        for (bad, want) in [
            (
                "v 0 0\n",
                "m.obj:1: 'v' needs three numbers x y z; z missing",
            ),
            ("v 0 x 0\n", "m.obj:1: 'x' is not a number"),
            (
                "v 0 0 0\nf 1 2 3\n",
                "m.obj:2: vertex index 2, but only 1 defined",
            ),
            (
                "v 0 0 0\nf 1 1 0\n",
                "m.obj:2: vertex index 0; OBJ indices start at 1",
            ),
            (
                "v 0 0 0\nf 1 1 -2\n",
                "m.obj:2: vertex index -2, but only 1",
            ),
            (
                "v 0 0 0\nf 1 1\n",
                "m.obj:2: a face needs at least 3 vertices",
            ),
            (
                "v 0 0 0\nf 1//1 1 1\n",
                "m.obj:2: normal index 1, but only 0",
            ),
            (
                "v 0 0 0\nf 1 1 99999999999999999999\n",
                "m.obj:2: vertex index '99999999999999999999' is not an integer",
            ),
            ("# nothing\n", "m.obj: no points found"),
        ] {
            let e = read_obj(bad).unwrap_err().to_string();
            assert!(e.starts_with(want), "{bad:?}: {e}");
        }
    }
}
