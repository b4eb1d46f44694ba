//! Curve fitting: global interpolation (open, with end derivatives, closed) and
//! least-squares approximation with optional bending-energy smoothing.
//!
//! High-level entry points take points and a config ([`interpolate`],
//! [`approximate`]); the low-level ones ([`interpolate_with`],
//! [`least_squares_with`], [`interpolate_closed_with`]) take given parameters and
//! knots. Every system is banded (or cyclic banded): nothing builds a dense
//! matrix whose size grows with the data.

pub mod banded;
pub mod bending;
pub mod cyclic;
mod interpolate;
mod least_squares;

pub use interpolate::{
    interpolate, interpolate_closed_with, interpolate_with, InterpolationConfig,
};
pub use least_squares::{
    approximate, least_squares_closed_with, least_squares_with, ApproximationConfig,
    LeastSquaresOptions,
};

use crate::bspline::Curve;
use crate::param::Method;

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
