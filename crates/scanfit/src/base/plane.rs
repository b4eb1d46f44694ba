//! The simplest base surface: the least-squares plane of the points.
//!
//! The points are projected onto the plane spanned by the two principal
//! directions of their covariance (PCA); the projections, scaled to the unit
//! square, are the parameters. This parameterizes any patch that is a height
//! field over its best-fit plane (terrain, a face seen from the front, a gently
//! curved panel); it folds over where the patch turns back over that plane.

use crate::{Error, Point3, Result, Vector3};

/// The plane and the parameters it gives.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneParameterization {
    /// Centroid of the points.
    pub origin: Point3,
    /// First principal direction (`u`).
    pub e1: Vector3,
    /// Second principal direction (`v`).
    pub e2: Vector3,
    /// Normal (`e1 x e2`).
    pub normal: Vector3,
    /// `(min, max)` of the projections on `e1` and `e2`.
    pub bounds: [(f64, f64); 2],
    /// Parameters in `[0, 1]^2`, one per point.
    pub uv: Vec<[f64; 2]>,
}

/// Parameters of `points` on their best-fit plane. Axis signs are made
/// deterministic (largest component positive), so the result does not depend
/// on the eigen solver.
pub fn plane_parameters(points: &[Point3]) -> Result<PlaneParameterization> {
    crate::validate_points(points)?;
    if points.len() < 3 {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed: 3,
            what: "a best-fit plane".into(),
        });
    }
    let pca = crate::geom::pca(points).ok_or(Error::TooFewPoints {
        got: 0,
        needed: 3,
        what: "a best-fit plane".into(),
    })?;
    let c = pca.centroid.coords;
    let orient = |v: Vector3| {
        let j = v.iamax();
        if v[j] < 0.0 {
            -v
        } else {
            v
        }
    };
    let a1 = orient(pca.axes[0]);
    let normal = orient(pca.axes[2]);
    let a2 = normal.cross(&a1);
    let (l1, l2) = (pca.values[0], pca.values[1]);
    if l2.is_nan() || l2 <= 1e-24 * l1.max(f64::MIN_POSITIVE) {
        return Err(Error::InvalidInput(
            "the points are collinear (or coincide): they span no plane to parameterize over"
                .into(),
        ));
    }
    // in-plane axes of the minimum-area bounding rectangle
    let flat: Vec<[f64; 2]> = points
        .iter()
        .map(|p| [(p.coords - c).dot(&a1), (p.coords - c).dot(&a2)])
        .collect();
    let (cos, sin) = min_area_rectangle_direction(&flat);
    let mut e1 = a1 * cos + a2 * sin;
    let extent = |e: &Vector3| {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                let s = (p.coords - c).dot(e);
                (lo.min(s), hi.max(s))
            });
        hi - lo
    };
    if extent(&normal.cross(&e1)) > extent(&e1) {
        e1 = normal.cross(&e1);
    }
    let e1 = orient(e1);
    let e2 = normal.cross(&e1);
    let proj: Vec<(f64, f64)> = points
        .iter()
        .map(|p| ((p.coords - c).dot(&e1), (p.coords - c).dot(&e2)))
        .collect();
    let (mut lo1, mut hi1, mut lo2, mut hi2) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(s, t) in &proj {
        lo1 = lo1.min(s);
        hi1 = hi1.max(s);
        lo2 = lo2.min(t);
        hi2 = hi2.max(t);
    }
    let uv = proj
        .iter()
        .map(|&(s, t)| {
            [
                ((s - lo1) / (hi1 - lo1)).clamp(0.0, 1.0),
                ((t - lo2) / (hi2 - lo2)).clamp(0.0, 1.0),
            ]
        })
        .collect();
    Ok(PlaneParameterization {
        origin: Point3::from(c),
        e1,
        e2,
        normal,
        bounds: [(lo1, hi1), (lo2, hi2)],
        uv,
    })
}

/// Direction `(cos, sin)` of an edge of the minimum-area rectangle enclosing
/// `pts` (Freeman & Shapira 1975: one side is collinear with a hull edge).
fn min_area_rectangle_direction(pts: &[[f64; 2]]) -> (f64, f64) {
    let hull = convex_hull(pts);
    let mut best = (f64::INFINITY, (1.0, 0.0));
    for k in 0..hull.len() {
        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        if len == 0.0 {
            continue;
        }
        let (c, s) = (dx / len, dy / len);
        let (mut lo1, mut hi1, mut lo2, mut hi2) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in &hull {
            let (x, y) = (p[0] * c + p[1] * s, -p[0] * s + p[1] * c);
            lo1 = lo1.min(x);
            hi1 = hi1.max(x);
            lo2 = lo2.min(y);
            hi2 = hi2.max(y);
        }
        let area = (hi1 - lo1) * (hi2 - lo2);
        if area < best.0 {
            best = (area, (c, s));
        }
    }
    best.1
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, no collinear points.
fn convex_hull(pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> = pts.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let order: Vec<[f64; 2]> = if pass == 0 {
            p.clone()
        } else {
            p.iter().rev().copied().collect()
        };
        for q in order {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terrain_like_points_map_to_the_unit_square() {
        let pts: Vec<Point3> = (0..400)
            .map(|k| {
                let (x, y) = ((k % 20) as f64 * 3.0, (k / 20) as f64);
                Point3::new(x + 1000.0, y - 50.0, 0.1 * (x * 0.3).sin())
            })
            .collect();
        let pp = plane_parameters(&pts).unwrap();
        assert!((pp.normal.z.abs() - 1.0).abs() < 1e-3);
        assert!(pp.normal.z > 0.0);
        // u follows x (the longer extent), v follows y
        assert!((pp.uv[19][0] - 1.0).abs() < 1e-12 && pp.uv[0][0].abs() < 1e-12);
        assert!((pp.uv[399][1] - 1.0).abs() < 1e-12 || pp.uv[399][1].abs() < 1e-12);
        assert!(plane_parameters(&[
            Point3::origin(),
            Point3::new(1., 1., 1.),
            Point3::new(2., 2., 2.)
        ])
        .is_err());
    }

    #[test]
    fn a_rotated_square_patch_fills_the_parameter_square() {
        // a nearly square patch rotated by 20 degrees: PCA's in-plane axes are
        // arbitrary, the minimum-area rectangle's are not
        let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
        let mut pts = Vec::new();
        for i in 0..50 {
            for j in 0..48 {
                let (x, y) = (i as f64 * 0.61, j as f64 * 0.66);
                pts.push(Point3::new(
                    x * c - y * s,
                    x * s + y * c,
                    0.01 * ((i * j) % 7) as f64,
                ));
            }
        }
        let pp = plane_parameters(&pts).unwrap();
        // all four corners of the parameter square are occupied
        for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]] {
            let d = pp
                .uv
                .iter()
                .map(|t| (t[0] - corner[0]).hypot(t[1] - corner[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-4, "corner {corner:?} empty: {d}");
        }
    }
}
