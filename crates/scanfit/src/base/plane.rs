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
    let n = points.len() as f64;
    let c = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
    let mut cov = nalgebra::Matrix3::zeros();
    for p in points {
        let d = p.coords - c;
        cov += d * d.transpose();
    }
    let eig = nalgebra::SymmetricEigen::new(cov / n);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let orient = |v: Vector3| {
        let j = v.iamax();
        if v[j] < 0.0 {
            -v
        } else {
            v
        }
    };
    let e1 = orient(eig.eigenvectors.column(idx[0]).into());
    let normal = orient(eig.eigenvectors.column(idx[2]).into());
    let e2 = normal.cross(&e1);
    let (l1, l2) = (eig.eigenvalues[idx[0]], eig.eigenvalues[idx[1]]);
    if !(l2 > 1e-24 * l1.max(f64::MIN_POSITIVE)) {
        return Err(Error::InvalidInput(
            "the points are collinear (or coincide): they span no plane to parameterize over"
                .into(),
        ));
    }
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
}
