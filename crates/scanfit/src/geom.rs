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
            return Err(Error::InvalidInput(format!(
                "point {index} has a coordinate of magnitude {v:e}; values beyond {MAX_COORDINATE:e} overflow squared distances, rescale the data"
            )));
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
