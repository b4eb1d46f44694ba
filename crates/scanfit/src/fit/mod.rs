//! Curve fitting: global interpolation (open, with end derivatives, closed) and
//! least-squares approximation with optional bending-energy smoothing.
//!
//! High-level entry points take points and a config ([`interpolate`],
//! [`approximate`]); the low-level ones ([`interpolate_with`],
//! [`least_squares_with`], [`interpolate_closed_with`]) take given parameters and
//! knots. Every system is banded (or cyclic banded): nothing builds a dense
//! matrix whose size grows with the data.

pub mod banded;
pub mod correction;
pub mod cyclic;
pub mod gram;
pub mod grid;
mod interpolate;
pub mod knot_ranks;
mod least_squares;
pub mod surface;

pub use interpolate::{
    interpolate, interpolate_closed_with, interpolate_with, InterpolationConfig,
};
pub(crate) use least_squares::lsq_values;
pub use least_squares::{
    approximate, least_squares_closed_with, least_squares_with, ApproximationConfig,
    LeastSquaresOptions,
};

use crate::bspline::Curve;
use crate::geom::validate_distinct_consecutive;
use crate::param::Method;
use crate::{Error, Point3, Result};

/// Condition estimates above this are reported as an error (about 1/(2^12 eps)):
/// the solution would have fewer than 4 significant digits.
pub const CONDITION_LIMIT: f64 = 1e12;

/// A fitted curve with the parameters its data points received and diagnostics.
#[derive(Debug, Clone)]
pub struct CurveFit {
    /// The fitted curve.
    pub curve: Curve,
    /// Parameter of each data point (for closed curves: without the closing 1.0).
    pub params: Vec<f64>,
    /// Parameterization method used.
    pub method: Method,
    /// 1-norm condition estimate of the solved system.
    pub condition: f64,
}

/// Validates fitting input and returns the points to fit: finite coordinates,
/// degree >= 1, at least `p + 1` points, no two consecutive points equal. For a
/// closed curve a last point repeating the first (a loop given closed
/// explicitly) is dropped.
fn prepare_points<'a>(
    points: &'a [Point3],
    p: usize,
    closed: bool,
    what: &str,
) -> Result<&'a [Point3]> {
    if p == 0 {
        return Err(Error::InvalidInput("degree must be at least 1".into()));
    }
    crate::validate_points(points)?;
    let mut pts = points;
    if closed && pts.len() > 2 && pts[0] == pts[pts.len() - 1] {
        pts = &pts[..pts.len() - 1];
    }
    // a closed curve of degree p needs 2p + 1 points (p + 1 distinct spans and
    // its p wrapped control points must not overlap)
    let needed = if closed { 2 * p + 1 } else { p + 1 };
    if pts.len() < needed {
        return Err(Error::TooFewPoints {
            got: pts.len(),
            needed,
            what: what.to_string(),
        });
    }
    validate_distinct_consecutive(pts, closed)?;
    Ok(pts)
}

/// Checks optional point weights (one finite non-negative value per point) and
/// a smoothing weight (finite, non-negative); shared by curve and surface fits.
pub(crate) fn validate_weights_and_smoothing(
    weights: Option<&[f64]>,
    points: usize,
    smoothing: f64,
) -> Result<()> {
    if let Some(w) = weights {
        if w.len() != points {
            return Err(Error::LengthMismatch {
                what: "weights",
                expected: points,
                got: w.len(),
            });
        }
        if let Some(i) = w.iter().position(|&x| !(x.is_finite() && x >= 0.0)) {
            return Err(Error::BadPoint {
                index: i,
                problem: format!(
                    "has weight {}; weights must be finite and non-negative",
                    w[i]
                ),
            });
        }
    }
    if !(smoothing.is_finite() && smoothing >= 0.0) {
        return Err(Error::InvalidSetting {
            setting: "smoothing",
            value: smoothing.to_string(),
            hint: format!("smoothing weight {smoothing} must be finite and non-negative"),
        });
    }
    Ok(())
}
