//! The L2 stretch of [`parameterization_quality`] on the Delaunay
//! triangulation of plane parameters of a dome on a disc, against the same
//! measure computed independently on the grid's own triangles (no border
//! slivers), each triangle's map taken into the dome's tangent plane at its
//! centroid: the slivers along the disc's outline, which made it 1e11, are
//! left out.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use scanfit::bspline::{KnotVector, Surface};
use scanfit::metrics::parameterization_quality;
use scanfit::{Point3, Vector3};

/// The dome of [`dome_on_a_disc`] as a biquadratic Bezier patch over its
/// parameters: `x, y` are linear in `u, v` (the turn by 0.3 rad undone) and
/// `z = 8 - 8 ((u - 0.5)^2 + (v - 0.5)^2) / 0.35^2`, whose Bernstein
/// coefficients are those of `(t - 0.5)^2`: 0.25, -0.25, 0.25. The
/// measure projects each triangle's map into this surface's tangent plane.
fn dome_surface() -> Surface {
    let k = KnotVector::uniform_clamped(2, 3).unwrap();
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let square = [0.25, -0.25, 0.25];
    let mut ctrl = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            // a linear map's Bezier control points are its values at i/2, j/2
            let (a, b) = ((i as f64 / 2.0 - 0.5) / 0.35, (j as f64 / 2.0 - 0.5) / 0.35);
            let (x, y) = (c * a + s * b, -s * a + c * b);
            let z = 8.0 - 8.0 * (square[i] + square[j]) / (0.35 * 0.35);
            ctrl.push(Point3::new(10.0 * x, 10.0 * y, z));
        }
    }
    Surface::new(k.clone(), k, ctrl).unwrap()
}

/// Points, their parameters and their grid indices.
type Dome = (Vec<Point3>, Vec<[f64; 2]>, Vec<(usize, usize)>);

/// A dome z = 8 (1 - r^2) over the disc of radius 9.7 on the grid of
/// step 1/3 (the trimmed-measure CLI test's), and plane parameters: the
/// grid turned by 0.3 rad and scaled into the unit square (turned, so
/// the rim's collinear grid points are collinear only to round-off).
fn dome_on_a_disc() -> Dome {
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let (mut pts, mut uv, mut ij) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=60 {
        for j in 0..=60 {
            let (x, y) = (-1.0 + i as f64 / 30.0, -1.0 + j as f64 / 30.0);
            let r2 = x * x + y * y;
            if r2 < 0.97 * 0.97 {
                pts.push(Point3::new(10.0 * x, 10.0 * y, 8.0 * (1.0 - r2)));
                uv.push([0.5 + 0.35 * (c * x - s * y), 0.5 + 0.35 * (s * x + c * y)]);
                ij.push((i, j));
            }
        }
    }
    (pts, uv, ij)
}

#[test]
fn border_slivers_do_not_count_in_the_stretch() {
    let (pts, uv, ij) = dome_on_a_disc();
    let surface = dome_surface();
    // the patch passes through the points at their parameters
    for (p, t) in pts.iter().zip(&uv) {
        assert!((surface.point(t[0], t[1]) - p).norm() < 1e-9, "{p:?}");
    }
    let q = parameterization_quality(&surface, &pts, &uv).unwrap();
    // clean: the grid's own squares inside the disc, two triangles each
    let at = |i: usize, j: usize| ij.iter().position(|&k| k == (i, j));
    let (mut num, mut a3, mut auv) = (0.0, 0.0, 0.0);
    for i in 0..60 {
        for j in 0..60 {
            if let (Some(a), Some(b), Some(c), Some(d)) =
                (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1))
            {
                for [x, y, z] in [[a, b, c], [a, c, d]] {
                    let e1 = pts[y] - pts[x];
                    let e2 = pts[z] - pts[x];
                    let (d1, d2) = (
                        [uv[y][0] - uv[x][0], uv[y][1] - uv[x][1]],
                        [uv[z][0] - uv[x][0], uv[z][1] - uv[x][1]],
                    );
                    let det = d1[0] * d2[1] - d2[0] * d1[1];
                    // the tangent plane at the centroid: the dome's normal
                    // (0.16 X, 0.16 Y, 1) there, X and Y linear in u, v
                    let m = (pts[x].coords + pts[y].coords + pts[z].coords) / 3.0;
                    let n = Vector3::new(0.16 * m.x, 0.16 * m.y, 1.0).normalize();
                    let tangent = |w: Vector3| w - n * w.dot(&n);
                    let su = tangent((e1 * d2[1] - e2 * d1[1]) / det);
                    let sv = tangent((e2 * d1[0] - e1 * d2[0]) / det);
                    let area3 = 0.5 * e1.cross(&e2).dot(&n).abs();
                    num += 0.5 * (su.norm_squared() + sv.norm_squared()) * area3;
                    a3 += area3;
                    auv += 0.5 * det.abs();
                }
            }
        }
    }
    let clean = (num / a3 * auv / a3).sqrt();
    // measured 1.0606 on the grid's own triangles, 1.0625 on the Delaunay
    // triangles (1e11 before the border slivers were peeled)
    println!("L2 stretch {} (grid triangles {clean})", q.l2_stretch);
    assert!(clean > 1.0 && clean < 1.12, "{clean}");
    assert!(
        (q.l2_stretch - clean).abs() < 0.05 * clean,
        "{} vs {clean} on the grid's triangles",
        q.l2_stretch
    );
    assert!(q.max_anisotropy < 100.0, "{q:?}");
}
