//! The library's one error type.

/// Everything that can go wrong in the library. Messages say what is wrong,
/// where (point index, knot index) and what to change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A knot vector is malformed.
    #[error("invalid knot vector: {0}")]
    InvalidKnots(String),
    /// Too few points for the requested degree or control-point count.
    #[error(
        "{got} points given, but {what} needs at least {needed}; {}",
        too_few_hint(what)
    )]
    TooFewPoints {
        /// points given
        got: usize,
        /// points needed
        needed: usize,
        /// what needs them
        what: String,
    },
    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate ({value}); remove or fix it")]
    NonFinite {
        /// index of the point
        index: usize,
        /// the offending value, printed
        value: String,
    },
    /// Two consecutive points are identical (zero chord).
    #[error("points {first} and {second} coincide (distance {distance:e}); remove the duplicate")]
    DuplicatePoints {
        /// first point index
        first: usize,
        /// second point index
        second: usize,
        /// their distance
        distance: f64,
    },
    /// A parameterization produced non-increasing parameters.
    #[error("{method} parameterization gives {} parameters at points {first} and {second} (u = {u_first} then {u_second}); the interpolation matrix would be singular, choose another method (e.g. centripetal)", if u_first == u_second { "coincident" } else { "decreasing" })]
    CoincidentParameters {
        /// method name
        method: String,
        /// first point index
        first: usize,
        /// second point index
        second: usize,
        /// parameter of the first point
        u_first: f64,
        /// parameter of the second point
        u_second: f64,
    },
    /// A linear system is singular or too ill-conditioned to trust.
    #[error("{what}: the linear system is singular or ill-conditioned (condition estimate {condition:e}); {hint}")]
    Singular {
        /// which system
        what: String,
        /// 1-norm condition estimate (infinite when a zero pivot was met)
        condition: f64,
        /// what to change
        hint: String,
    },
    /// Any other invalid argument.
    #[error("{0}")]
    InvalidInput(String),
}

/// Result alias for the library.
pub type Result<T> = std::result::Result<T, Error>;

/// What to change when too few points are given for `what`.
fn too_few_hint(what: &str) -> &'static str {
    if what.contains("least-squares") || what.contains("control") {
        "lower the control-point count (or the degree) or give more points"
    } else if what.contains("degree") || what.contains("interpolation") {
        "lower the degree or give more points"
    } else {
        "give more points"
    }
}
