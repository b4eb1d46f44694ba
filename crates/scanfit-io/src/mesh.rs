//! What the mesh readers (STL, OBJ, PLY with faces) share: per-vertex
//! normals from the triangles, area-weighted, stored as the `nx`, `ny`, `nz`
//! columns of the table (the columns the library's normals code reads).
//!
//! The normal of vertex `v` is the normalised sum of `(b - a) x (c - a)`
//! over the triangles `(a, b, c)` that use `v`: each triangle's unit normal
//! weighted by twice its area, so small slivers of a fine tessellation do
//! not tilt the result. Polygons are fanned into triangles from their first
//! vertex; the winding (counter-clockwise seen from outside, as STL, OBJ and
//! PLY agree) gives the sign.

use scanfit::{Point3, Vector3};

use crate::table::PointTable;

/// Triangles as vertex indices into the table's points.
pub(crate) type Triangle = [u32; 3];

/// Appends the triangles of the polygon `ring` (indices of three or more
/// vertices) fanned from its first vertex.
pub(crate) fn fan(ring: &[u32], out: &mut Vec<Triangle>) {
    if let Some((&a, rest)) = ring.split_first() {
        for w in rest.windows(2) {
            out.push([a, w[0], w[1]]);
        }
    }
}

/// The area-weighted vertex normals of `triangles` over `points`, and how
/// many vertices are left without one (used by no triangle of non-zero
/// area). Triangles with a non-finite corner are skipped (the reader's
/// non-finite policy decides about their points afterwards).
pub(crate) fn vertex_normals(points: &[Point3], triangles: &[Triangle]) -> (Vec<Vector3>, usize) {
    let mut sum = vec![Vector3::zeros(); points.len()];
    for t in triangles {
        let corner = |k: usize| points.get(t[k] as usize).copied();
        let (Some(a), Some(b), Some(c)) = (corner(0), corner(1), corner(2)) else {
            continue;
        };
        let n = (b - a).cross(&(c - a));
        if !n.iter().all(|v| v.is_finite()) {
            continue;
        }
        for &v in t {
            if let Some(s) = sum.get_mut(v as usize) {
                *s += n;
            }
        }
    }
    let mut missing = 0;
    for s in &mut sum {
        let len = s.norm();
        if len > 0.0 && len.is_finite() {
            *s /= len;
        } else {
            missing += 1;
        }
    }
    (sum, missing)
}

/// Adds `nx`, `ny`, `nz` columns to `table` from its `triangles` when every
/// vertex gets a normal; otherwise (vertices on no triangle, or only on
/// degenerate ones) adds none and says so in a warning, so that no command
/// works with made-up normals. Does nothing without triangles or when the
/// table already has normals.
pub(crate) fn attach_normals(table: &mut PointTable, triangles: &[Triangle]) {
    if triangles.is_empty()
        || ["nx", "ny", "nz"]
            .iter()
            .all(|c| table.columns.iter().any(|t| t.eq_ignore_ascii_case(c)))
    {
        return;
    }
    let (normals, missing) = vertex_normals(&table.points, triangles);
    if missing > 0 {
        table.warnings.push(format!(
            "{}: {missing} of {} vertices lie on no triangle of non-zero area; no normals were taken from the faces (the commands estimate them from the points)",
            table.path.display(),
            table.points.len()
        ));
        return;
    }
    for (c, name) in ["nx", "ny", "nz"].into_iter().enumerate() {
        table.columns.push(name.into());
        table.extra.push(normals.iter().map(|n| n[c]).collect());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_weighted_normals_of_a_roof() {
        // two triangles sharing the edge 0-1: a flat one of area 2 and a
        // steep one of area 0.5; the shared vertices lean to the big one
        let p = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(0.0, 2.0, 0.0),
            Point3::new(0.0, 0.0, -0.5),
        ];
        let mut tris = Vec::new();
        fan(&[0, 1, 2], &mut tris);
        fan(&[1, 0, 3], &mut tris);
        let (n, missing) = vertex_normals(&p, &tris);
        assert_eq!(missing, 0);
        assert_eq!(n[2], Vector3::z());
        // (0,0,4) + (0,-1,0) normalised
        let want = Vector3::new(0.0, -1.0, 4.0) / 17f64.sqrt();
        assert!((n[0] - want).norm() < 1e-15, "{}", n[0]);
        assert_eq!(n[3], -Vector3::y());
        // a quad fans into two triangles
        let mut quad = Vec::new();
        fan(&[0, 1, 2, 3], &mut quad);
        assert_eq!(quad, vec![[0, 1, 2], [0, 2, 3]]);
    }
}
