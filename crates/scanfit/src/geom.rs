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
        let s = self.values[0] + self.values[1] + self.values[2];
        if s > 0.0 {
            self.values[2].max(0.0) / s
        } else {
            0.0
        }
    }
}

/// PCA of `points` (`None` for no points). The covariance is accumulated
/// about the first point and then re-centred, which keeps it accurate for
/// coordinates far from the origin (georeferenced scans).
pub fn pca<'a>(points: impl IntoIterator<Item = &'a Point3>) -> Option<Pca> {
    let mut it = points.into_iter();
    let first = it.next()?.coords;
    let (mut n, mut sum, mut cov) = (1.0, Vector3::zeros(), nalgebra::Matrix3::zeros());
    for p in it {
        let d = p.coords - first;
        sum += d;
        cov += d * d.transpose();
        n += 1.0;
    }
    let mean = sum / n;
    let cov = cov / n - mean * mean.transpose();
    let eig = nalgebra::SymmetricEigen::new(cov);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    Some(Pca {
        centroid: Point3::from(first + mean),
        values: idx.map(|i| eig.eigenvalues[i]),
        axes: idx.map(|i| eig.eigenvectors.column(i).into()),
    })
}
