//! Curve parameterization: the seven methods of [CURVE12]
//! ([CURVE12]) and knot placement.
//!
//! | method | file | parameters |
//! |---|---|---|
//! | uniform, chord length, centripetal, exponential(a) | [`exponential`] | `u_i - u_{i-1} ∝ |P_i - P_{i-1}|^a` with a = 0, 1, 1/2, a |
//! | universal (Lim 1999) | [`universal`] | maxima of the basis functions on uniform knots |
//! | hybrid (the paper's eq. 3.1) | [`hybrid`] | `u_i - u_{i-1} ∝ sqrt|B_i - B_{i-1}|`, B_i = max N_i |
//! | the paper's new method (eqs. 3.2-3.4) | [`proposed`] | exponential(0.8) -> averaging knots -> maxima -> pairwise median shift |
//!
//! Every method returns parameters in `[0, 1]`, first 0 and last 1, strictly
//! increasing, or an error naming the two points where they are not.

mod basis_max;
pub mod exponential;
pub mod hybrid;
pub mod knots;
pub mod proposed;
pub mod universal;

pub use basis_max::basis_maximum;

use crate::bspline::KnotVector;
use crate::{Error, Point3, Result};

/// Default exponent of the exponential method and of the new method's first
/// step ([CURVE12], section 3.2 step 1: "a = 0.8 ... based on experiment").
pub const DEFAULT_EXPONENT: f64 = 0.8;

/// A curve parameterization method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Equally spaced parameters (exponent 0).
    Uniform,
    /// Chord length (exponent 1).
    ChordLength,
    /// Centripetal, Lee 1989 (exponent 1/2).
    Centripetal,
    /// Exponential with exponent `a` in `[0, 1]` (Lee 1989; default 0.8).
    Exponential(f64),
    /// Universal: parameters at the maxima of the basis functions on uniform knots (Lim 1999).
    Universal,
    /// Hybrid (the method the paper improves on): centripetal formula applied to
    /// the basis-function maxima (eq. 3.1). Fails with coincident parameters on
    /// symmetric data such as data set 3.
    Hybrid,
    /// The paper's new method with the given exponential start (default 0.8).
    Proposed(f64),
}

impl Method {
    /// Every method with the paper's defaults, in the order of the paper's figures.
    pub const ALL: [Method; 7] = [
        Method::Centripetal,
        Method::Exponential(DEFAULT_EXPONENT),
        Method::Uniform,
        Method::Proposed(DEFAULT_EXPONENT),
        Method::ChordLength,
        Method::Hybrid,
        Method::Universal,
    ];

    /// Short name (as used on the command line).
    pub fn name(&self) -> &'static str {
        match self {
            Method::Uniform => "uniform",
            Method::ChordLength => "chord",
            Method::Centripetal => "centripetal",
            Method::Exponential(_) => "exponential",
            Method::Universal => "universal",
            Method::Hybrid => "hybrid",
            Method::Proposed(_) => "proposed",
        }
    }

    /// Parses a command-line name (`uniform`, `chord`, `centripetal`,
    /// `exponential[:a]`, `universal`, `hybrid`, `proposed[:a]`/`new`).
    pub fn parse(s: &str) -> Result<Self> {
        let (name, arg) = match s.split_once(':') {
            Some((n, a)) => (n, Some(a)),
            None => (s, None),
        };
        let exponent = |a: Option<&str>| -> Result<f64> {
            match a {
                None => Ok(DEFAULT_EXPONENT),
                Some(a) => a
                    .parse::<f64>()
                    .ok()
                    .filter(|v| (0.0..=1.0).contains(v))
                    .ok_or_else(|| {
                        Error::InvalidInput(format!(
                            "exponent '{a}' in '{s}' must be a number in [0, 1]"
                        ))
                    }),
            }
        };
        Ok(match name.to_ascii_lowercase().as_str() {
            "uniform" => Method::Uniform,
            "chord" | "chord-length" | "chordlength" => Method::ChordLength,
            "centripetal" => Method::Centripetal,
            "exponential" | "exp" => Method::Exponential(exponent(arg)?),
            "universal" => Method::Universal,
            "hybrid" => Method::Hybrid,
            "proposed" | "new" => Method::Proposed(exponent(arg)?),
            _ => {
                return Err(Error::InvalidInput(format!(
                    "unknown parameterization '{s}'; use one of uniform, chord, centripetal, exponential[:a], universal, hybrid, proposed[:a]"
                )))
            }
        })
    }

    /// The exponent when the method belongs to the exponential family.
    pub fn exponent(&self) -> Option<f64> {
        match self {
            Method::Uniform => Some(0.0),
            Method::ChordLength => Some(1.0),
            Method::Centripetal => Some(0.5),
            Method::Exponential(a) => Some(*a),
            _ => None,
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Method::Exponential(a) | Method::Proposed(a) if *a != DEFAULT_EXPONENT => {
                write!(f, "{}:{a}", self.name())
            }
            _ => f.write_str(self.name()),
        }
    }
}

/// The outcome of a parameterization.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameterization {
    /// One parameter per point (for a closed curve one more: the closing 1.0).
    pub params: Vec<f64>,
    /// Knots the method prescribes for interpolation (universal: uniform knots;
    /// new method: the averaging knots of its exponential start), if any.
    pub knots: Option<KnotVector>,
}

/// Parameterizes `points` for a curve of degree `degree` (the degree matters for
/// the methods that use basis functions). With `closed`, the points form a loop:
/// the closing chord is included and one extra parameter (1.0) is returned for
/// the repeated first point; only the exponential family supports loops.
pub fn parameterize(
    points: &[Point3],
    method: Method,
    degree: usize,
    closed: bool,
) -> Result<Parameterization> {
    crate::validate_points(points)?;
    let needed = if closed { 3 } else { degree.max(1) + 1 };
    if points.len() < needed {
        return Err(Error::TooFewPoints {
            got: points.len(),
            needed,
            what: format!("{method} parameterization for degree {degree}"),
        });
    }
    let open_only = |m: &Method| -> Result<()> {
        if closed {
            return Err(Error::InvalidInput(format!(
                "{m} parameterization is defined for open curves only; use chord, centripetal or exponential for a closed curve"
            )));
        }
        Ok(())
    };
    let (params, knots) = match method {
        Method::Uniform | Method::ChordLength | Method::Centripetal | Method::Exponential(_) => {
            let a = method.exponent().unwrap_or(1.0);
            (exponential::params(points, a, closed)?, None)
        }
        Method::Universal => {
            open_only(&method)?;
            let (u, k) = universal::params(points.len(), degree)?;
            (u, Some(k))
        }
        Method::Hybrid => {
            open_only(&method)?;
            let (u, k) = hybrid::params(points, degree)?;
            (u, Some(k))
        }
        Method::Proposed(a) => {
            open_only(&method)?;
            let (u, k) = proposed::params(points, degree, a)?;
            (u, Some(k))
        }
    };
    check_increasing(&params, &method.to_string())?;
    Ok(Parameterization { params, knots })
}

/// Errors unless `params` is strictly increasing, finite and in `[0, 1]`.
pub fn check_increasing(params: &[f64], method: &str) -> Result<()> {
    if let Some(i) = params
        .iter()
        .position(|u| !u.is_finite() || !(0.0..=1.0).contains(u))
    {
        return Err(Error::InvalidInput(format!(
            "{method} parameterization gives parameter {} for point {i}, outside [0, 1]",
            params[i]
        )));
    }
    if let Some(i) = params.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::CoincidentParameters {
            method: method.to_string(),
            first: i,
            second: i + 1,
            u_first: params[i],
            u_second: params[i + 1],
        });
    }
    Ok(())
}
