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

/// The best-fit plane's frame: the centroid, the in-plane axes along the
/// minimum-area bounding rectangle and the normal, without the parameters
/// (no per-point array is kept: the points are streamed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFrame {
    /// Centroid of the points.
    pub origin: Point3,
    /// First in-plane axis (the long side of the minimum-area rectangle).
    pub e1: Vector3,
    /// Second in-plane axis (`normal x e1`).
    pub e2: Vector3,
    /// Normal (`e1 x e2`; the covariance's smallest principal direction).
    pub normal: Vector3,
}

/// The frame of [`plane_parameters`] alone: PCA normal and the axes of the
/// minimum-area rectangle of the projections (Freeman & Shapira 1975). Axis
/// signs are deterministic (largest component positive).
///
/// The rectangle needs the convex hull of the projections only; points
/// strictly inside the octagon of the extreme projections in eight
/// directions cannot be hull vertices and are dropped before the hull
/// (Akl & Toussaint 1978), so the memory is that of the few points near the
/// outline, not a copy of the cloud.
///
/// Errors: invalid coordinates, fewer than 3 points, collinear points.
///
/// ```
/// use scanfit::base::plane_frame;
/// use scanfit::Point3;
/// let pts: Vec<Point3> = (0..60)
///     .map(|k| Point3::new((k % 10) as f64 * 2.0, (k / 10) as f64, 5.0))
///     .collect();
/// let f = plane_frame(&pts).unwrap();
/// assert!((f.normal.z - 1.0).abs() < 1e-12);
/// assert!((f.e1.x - 1.0).abs() < 1e-12); // the long side is along x
/// ```
pub fn plane_frame(points: &[Point3]) -> Result<PlaneFrame> {
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
    let flat = |p: &Point3| [(p.coords - c).dot(&a1), (p.coords - c).dot(&a2)];
    let (cos, sin) = min_area_rectangle_direction(&hull_candidates(points.iter().map(flat)));
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
    Ok(PlaneFrame {
        origin: Point3::from(c),
        e1,
        e2,
        normal,
    })
}

/// Parameters of `points` on their best-fit plane. Axis signs are made
/// deterministic (largest component positive), so the result does not depend
/// on the eigen solver.
pub fn plane_parameters(points: &[Point3]) -> Result<PlaneParameterization> {
    let PlaneFrame {
        origin,
        e1,
        e2,
        normal,
    } = plane_frame(points)?;
    let c = origin.coords;
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
        origin,
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

/// The points of `pts` that can be vertices of their convex hull: all but
/// those strictly inside the octagon of the extreme points in the directions
/// `x`, `y`, `x + y` and `x - y` (Akl & Toussaint 1978), with a margin of
/// 1e-9 of the extent so that rounding never drops a hull vertex. The hull
/// of the candidates is the hull of all points.
fn hull_candidates(pts: impl Iterator<Item = [f64; 2]> + Clone) -> Vec<[f64; 2]> {
    let dirs = [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-1.0, 1.0]];
    // extreme point per direction and sign, in counter-clockwise order of
    // the outward directions (+x, +x+y, +y, -x+y, -x, -x-y, -y, x-y)
    let mut ext = [[f64::NAN; 2]; 8];
    let mut best = [f64::NEG_INFINITY; 8];
    let mut scale = 0.0f64;
    for p in pts.clone() {
        scale = scale.max(p[0].abs()).max(p[1].abs());
        for (k, d) in dirs.iter().enumerate() {
            let s = p[0] * d[0] + p[1] * d[1];
            if s > best[k] {
                (best[k], ext[k]) = (s, p);
            }
            if -s > best[k + 4] {
                (best[k + 4], ext[k + 4]) = (-s, p);
            }
        }
    }
    let mut octagon: Vec<[f64; 2]> = Vec::with_capacity(8);
    for q in ext {
        if octagon.last() != Some(&q) && octagon.first() != Some(&q) {
            octagon.push(q);
        }
    }
    let tol = 1e-9 * scale * scale;
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let inside = |p: [f64; 2]| {
        octagon.len() >= 3
            && (0..octagon.len())
                .all(|k| cross(octagon[k], octagon[(k + 1) % octagon.len()], p) > tol)
    };
    pts.filter(|&p| !inside(p)).collect()
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
