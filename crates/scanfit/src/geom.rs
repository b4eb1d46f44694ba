//! The one point/vector type of the library, and input validation shared by all algorithms.

use crate::{Error, Result};

/// A point in 3D space (f64).
pub type Point3 = nalgebra::Point3<f64>;
/// A vector in 3D space (f64).
pub type Vector3 = nalgebra::Vector3<f64>;

/// Largest coordinate magnitude the library accepts: squared distances of
/// larger values overflow f64.
pub const MAX_COORDINATE: f64 = 1e150;

/// Checks that every coordinate is finite and of a magnitude whose squared
/// distances stay representable; the error names the first bad point.
pub fn validate_points(points: &[Point3]) -> Result<()> {
    for (index, p) in points.iter().enumerate() {
        if let Some(v) = p.coords.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                index,
                value: v.to_string(),
            });
        }
        if let Some(v) = p.coords.iter().find(|v| v.abs() > MAX_COORDINATE) {
            return Err(Error::BadPoint {
                index,
                problem: format!(
                    "has a coordinate of magnitude {v:e}; values beyond {MAX_COORDINATE:e} overflow squared distances, rescale the data"
                ),
            });
        }
    }
    // tiny data: distances would underflow (points that differ would coincide)
    let extent = bbox_diagonal(points);
    if points.len() > 1 && extent > 0.0 && extent < 1e-140 {
        return Err(Error::InvalidInput(format!(
            "the points span only {extent:e}; distances this small underflow, rescale the data"
        )));
    }
    Ok(())
}

/// Checks that no two consecutive points coincide (relative to the data's size).
/// With `closed`, the last and first points are consecutive too.
pub(crate) fn validate_distinct_consecutive(points: &[Point3], closed: bool) -> Result<()> {
    let scale = bbox_diagonal(points).max(f64::MIN_POSITIVE);
    let tol = scale * 1e-14;
    let n = points.len();
    let pairs = if closed && n > 1 {
        n
    } else {
        n.saturating_sub(1)
    };
    for i in 0..pairs {
        let j = (i + 1) % n;
        let d = (points[j] - points[i]).norm();
        if d <= tol {
            return Err(Error::DuplicatePoints {
                first: i,
                second: j,
                distance: d,
            });
        }
    }
    Ok(())
}

/// Length of the diagonal of the axis-aligned bounding box (0 for no points).
pub(crate) fn bbox_diagonal(points: &[Point3]) -> f64 {
    let Some(first) = points.first() else {
        return 0.0;
    };
    let (mut lo, mut hi) = (first.coords, first.coords);
    for p in points {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    (hi - lo).norm()
}

/// Principal component analysis of a point set: centroid, covariance
/// eigenvalues (descending) and the matching unit axes. The last axis is the
/// normal of the best-fit (total least squares) plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pca {
    /// Mean of the points.
    pub centroid: Point3,
    /// Eigenvalues of the covariance matrix, largest first (variances along the axes).
    pub values: [f64; 3],
    /// Unit eigenvectors, in the order of `values`; the signs are the eigen solver's.
    pub axes: [Vector3; 3],
}

impl Pca {
    /// Surface variation `l3 / (l1 + l2 + l3)` (Pauly et al. 2002): 0 on a
    /// plane, 1/3 for isotropic noise; a cheap curvature/noise indicator.
    pub fn variation(&self) -> f64 {
        surface_variation(&self.values)
    }
}

/// [`Pca::variation`] of eigenvalues `l1 >= l2 >= l3`.
pub(crate) fn surface_variation(values: &[f64; 3]) -> f64 {
    let s = values[0] + values[1] + values[2];
    if s > 0.0 {
        values[2].max(0.0) / s
    } else {
        0.0
    }
}

/// Centroid and covariance of `points` (`None` for no points), the
/// covariance as `[c00, c11, c22, c01, c02, c12]`. It is accumulated about
/// the first point and then re-centred, which keeps it accurate for
/// coordinates far from the origin (georeferenced scans).
pub(crate) fn covariance(points: impl IntoIterator<Item = Vector3>) -> Option<(Point3, [f64; 6])> {
    let mut it = points.into_iter();
    let first = it.next()?;
    let (mut n, mut sum, mut c) = (1.0, Vector3::zeros(), [0.0; 6]);
    for p in it {
        let d = p - first;
        sum += d;
        c[0] += d.x * d.x;
        c[1] += d.y * d.y;
        c[2] += d.z * d.z;
        c[3] += d.x * d.y;
        c[4] += d.x * d.z;
        c[5] += d.y * d.z;
        n += 1.0;
    }
    let m = sum / n;
    let cov = [
        c[0] / n - m.x * m.x,
        c[1] / n - m.y * m.y,
        c[2] / n - m.z * m.z,
        c[3] / n - m.x * m.y,
        c[4] / n - m.x * m.z,
        c[5] / n - m.y * m.z,
    ];
    Some((Point3::from(first + m), cov))
}

/// PCA of `points` (`None` for no points). The covariance is accumulated
/// about the first point and then re-centred, which keeps it accurate for
/// coordinates far from the origin (georeferenced scans).
pub fn pca<'a>(points: impl IntoIterator<Item = &'a Point3>) -> Option<Pca> {
    let (centroid, cov) = covariance(points.into_iter().map(|p| p.coords))?;
    Some(pca_of(centroid, &cov))
}

/// The PCA of a covariance from [`covariance`] (nalgebra's iterative
/// symmetric eigen solver).
pub(crate) fn pca_of(centroid: Point3, c: &[f64; 6]) -> Pca {
    let cov = nalgebra::Matrix3::new(c[0], c[3], c[4], c[3], c[1], c[5], c[4], c[5], c[2]);
    let eig = nalgebra::SymmetricEigen::new(cov);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    Pca {
        centroid,
        values: idx.map(|i| eig.eigenvalues[i]),
        axes: idx.map(|i| eig.eigenvectors.column(i).into()),
    }
}
