//! The library's one error type.

/// Everything that can go wrong in the library. Messages say what is wrong,
/// where (point index, knot index) and what to change; the variants carry
/// the where as data ([`Error::point_indices`], [`Error::patch`], the
/// setting's name), so a front can map a point index to a line of its file
/// or a setting to its option without reading the message.
///
/// `#[non_exhaustive]`: new variants may be added; match with a wildcard.
///
/// ```
/// use scanfit::{validate_points, Error, Point3};
///
/// let e = validate_points(&[Point3::new(0., 0., 0.), Point3::new(f64::NAN, 1., 2.)])
///     .unwrap_err();
/// assert_eq!(e.point_indices(), vec![1]);
/// assert!(matches!(e, Error::NonFinite { index: 1, .. }));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
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
    /// One point cannot be used (its coordinates, its position in the data).
    #[error("point {index} {problem}")]
    BadPoint {
        /// index of the point
        index: usize,
        /// what is wrong with it and what to change, e.g. "has a coordinate of
        /// magnitude 1e300; ..."
        problem: String,
    },
    /// A point's given parameters lie outside the surface's domain.
    #[error(
        "point {index} has parameters ({u}, {v}) outside the domain [{}, {}] x [{}, {}]",
        u_range.0, u_range.1, v_range.0, v_range.1
    )]
    ParametersOutsideDomain {
        /// index of the point
        index: usize,
        /// its u
        u: f64,
        /// its v
        v: f64,
        /// the domain in u
        u_range: (f64, f64),
        /// the domain in v
        v_range: (f64, f64),
    },
    /// A setting of a config has a value the algorithm cannot use.
    #[error("{setting} = {value}: {hint}")]
    InvalidSetting {
        /// the config field, e.g. `alpha` or `far_spacings`
        setting: &'static str,
        /// the value given, printed
        value: String,
        /// what is allowed, what to change
        hint: String,
    },
    /// Two inputs that must have the same length do not.
    #[error("{got} {what} given for {expected} points; give one per point")]
    LengthMismatch {
        /// what was given per point, e.g. "parameter pairs"
        what: &'static str,
        /// number of points
        expected: usize,
        /// number given
        got: usize,
    },
    /// An error in one patch of a multi-patch input.
    #[error("patch {patch}: {source}")]
    InPatch {
        /// the patch's id
        patch: usize,
        /// what went wrong in it
        source: Box<Error>,
    },
    /// A fitted surface reaches farther outside the bounding box of its
    /// points than [`crate::pipeline::Extent::limit`] (a fit that flew off
    /// where there are no data); a pipeline returns it unless told to allow
    /// extrapolation.
    #[error(
        "{}the surface leaves the data: samples reach {:e} ({:.0} point spacings, {:.1}% of the diagonal) outside {} points' bounding box and control points {:e} (limit {:e}); fit it with fewer control points or terms, or allow extrapolation",
        patch.map(|p| format!("patch {p}: ")).unwrap_or_default(),
        extent.samples_outside,
        extent.samples_outside_spacings,
        100.0 * extent.samples_outside / extent.diagonal.max(f64::MIN_POSITIVE),
        if patch.is_some() { "its" } else { "the" },
        extent.control_outside,
        extent.limit
    )]
    LeavesData {
        /// The patch's id (label), for one patch of several.
        patch: Option<i64>,
        /// How far it left.
        extent: crate::pipeline::Extent,
    },
    /// Any other invalid argument.
    #[error("{0}")]
    InvalidInput(String),
}

impl Error {
    /// The indices of the input points this error is about (empty when it
    /// is not about particular points), for a front to name their place in
    /// its file.
    pub fn point_indices(&self) -> Vec<usize> {
        match self {
            Error::NonFinite { index, .. }
            | Error::BadPoint { index, .. }
            | Error::ParametersOutsideDomain { index, .. } => vec![*index],
            Error::DuplicatePoints { first, second, .. }
            | Error::CoincidentParameters { first, second, .. } => vec![*first, *second],
            Error::InPatch { source, .. } => source.point_indices(),
            _ => Vec::new(),
        }
    }

    /// The patch this error is about, if it came from one patch of several.
    pub fn patch(&self) -> Option<usize> {
        match self {
            Error::InPatch { patch, .. } => Some(*patch),
            _ => None,
        }
    }

    /// This error as one of patch `patch`.
    pub fn in_patch(self, patch: usize) -> Error {
        Error::InPatch {
            patch,
            source: Box::new(self),
        }
    }
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
