//! `scanfit curve fit` and `scanfit curve compare` as library calls.
//!
//! * [`run`]: one B-spline curve through ([`interpolate`], NURBS Book
//!   eq. 9.5 with optional end derivatives, or periodic) or near
//!   ([`approximate`], least squares with optional bending-energy
//!   smoothing) a sequence of points, with its [`CurveQuality`]
//!   (deviations, curvature sign changes, loops, length ratio).
//! * [`compare`]: interpolation with every parameterization method of the
//!   curve paper side by side, each with its quality or its error.

use crate::centring::Centring;
use crate::fit::{approximate, interpolate, ApproximationConfig, CurveFit, InterpolationConfig};
use crate::param::{Method, DEFAULT_EXPONENT};
use crate::progress::Progress;
use crate::quality::{curve_quality, CurveQuality, QualityConfig};
use crate::{Error, Point3, Result, Vector3};

/// Interpolation or least squares.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum CurveFitKind {
    /// Through every point (the default), optionally with the end
    /// derivatives `dC/du` at `u = 0` and `u = 1` (open curves only).
    Interpolation {
        /// `(start, end)` derivatives, or `None` for the not-a-knot-free
        /// standard system.
        end_derivatives: Option<(Vector3, Vector3)>,
    },
    /// Least squares with `ctrl_count` control points (distinct ones when
    /// closed).
    LeastSquares {
        /// Number of control points.
        ctrl_count: usize,
        /// Pin the ends to the first and last points (open curves only).
        fix_ends: bool,
        /// Weight `lambda` of the bending energy `∫|C''(u)|^2 du`.
        smoothing: f64,
    },
}

impl CurveFitKind {
    /// "interpolation" or "least squares".
    pub fn label(&self) -> &'static str {
        match self {
            CurveFitKind::Interpolation { .. } => "interpolation",
            CurveFitKind::LeastSquares { .. } => "least squares",
        }
    }
}

/// Settings of [`run`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct CurveConfig {
    /// Degree (default 3).
    pub degree: usize,
    /// Parameterization; `None` (default): the curve paper's proposed method
    /// (a = 0.8) for open curves, centripetal for closed ones (the
    /// basis-maxima methods are defined for open curves only).
    pub method: Option<Method>,
    /// The points form a closed loop: a periodic curve (default false).
    pub closed: bool,
    /// Interpolation (default) or least squares.
    pub kind: CurveFitKind,
    /// The quality measures (default [`QualityConfig::default`]).
    pub quality: QualityConfig,
}

impl Default for CurveConfig {
    fn default() -> Self {
        Self {
            degree: 3,
            method: None,
            closed: false,
            kind: CurveFitKind::Interpolation {
                end_derivatives: None,
            },
            quality: QualityConfig::default(),
        }
    }
}

impl CurveConfig {
    /// The method used: the given one or the default for open / closed curves.
    pub fn method(&self) -> Method {
        self.method.unwrap_or(if self.closed {
            Method::Centripetal
        } else {
            Method::Proposed(DEFAULT_EXPONENT)
        })
    }
}

/// What [`run`] returns.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CurveReport {
    /// The curve, the points' parameters, the method and the condition.
    pub fit: CurveFit,
    /// Its quality against the points it was fitted to.
    pub quality: CurveQuality,
    /// Number of points fitted (a closed input's repeated last point is not).
    pub fitted_points: usize,
}

/// Fits one curve to `points` (see the module documentation).
///
/// ```
/// use scanfit::pipeline::curve::{run, CurveConfig, CurveFitKind};
/// use scanfit::progress::NoProgress;
/// use scanfit::Point3;
///
/// let pts: Vec<Point3> = (0..40)
///     .map(|k| { let t = k as f64 / 39.0; Point3::new(t, (3.0 * t).sin(), 0.0) })
///     .collect();
/// let r = run(&pts, &CurveConfig::default(), &NoProgress)?;
/// assert!(r.quality.max_deviation < 1e-9); // interpolation
/// let mut cfg = CurveConfig::default();
/// cfg.kind = CurveFitKind::LeastSquares { ctrl_count: 8, fix_ends: true, smoothing: 0.0 };
/// let r = run(&pts, &cfg, &NoProgress)?;
/// assert_eq!(r.fit.curve.control_points().len(), 8);
/// assert!(r.quality.max_deviation < 0.02); // at the (uncorrected) parameters
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn run(
    points: &[Point3],
    config: &CurveConfig,
    progress: &dyn Progress,
) -> Result<CurveReport> {
    // computed relative to the data's centre, moved back exactly (issue 14)
    let centring = Centring::of(points);
    let local = if centring.is_identity() {
        std::borrow::Cow::Borrowed(points)
    } else {
        std::borrow::Cow::Owned(centring.points(points))
    };
    Ok(centring.restore(run_centred(&local, config, progress)?))
}

/// [`run`] on points whose centre is at the origin.
fn run_centred(
    points: &[Point3],
    config: &CurveConfig,
    progress: &dyn Progress,
) -> Result<CurveReport> {
    let method = config.method();
    progress.stage(&format!("fitting {} points", points.len()), None);
    let fit = match config.kind {
        CurveFitKind::LeastSquares {
            ctrl_count,
            fix_ends,
            smoothing,
        } => approximate(
            points,
            &ApproximationConfig {
                degree: config.degree,
                ctrl_count,
                method,
                fix_ends,
                smoothing,
                weights: None,
                closed: config.closed,
            },
        )?,
        CurveFitKind::Interpolation { end_derivatives } => {
            if config.closed && end_derivatives.is_some() {
                return Err(Error::InvalidSetting {
                    setting: "end_derivatives",
                    value: "given".into(),
                    hint: "a closed (periodic) curve has no ends; leave them out".into(),
                });
            }
            interpolate(
                points,
                &InterpolationConfig {
                    degree: config.degree,
                    method,
                    end_derivatives,
                    closed: config.closed,
                },
            )?
        }
    };
    progress.stage("measuring", None);
    let used = points.get(..fit.params.len()).unwrap_or(points);
    let quality = curve_quality(&fit.curve, used, &fit.params, &config.quality);
    Ok(CurveReport {
        fitted_points: used.len(),
        fit,
        quality,
    })
}

/// Settings of [`compare`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CompareConfig {
    /// Degree of the interpolating curves (default 3).
    pub degree: usize,
    /// The methods compared (default [`Method::ALL`], the order of the
    /// curve paper's figures).
    pub methods: Vec<Method>,
    /// The quality measures (default [`QualityConfig::default`]).
    pub quality: QualityConfig,
}

impl Default for CompareConfig {
    fn default() -> Self {
        Self {
            degree: 3,
            methods: Method::ALL.to_vec(),
            quality: QualityConfig::default(),
        }
    }
}

/// One method's result in a [`compare`] run.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct MethodResult {
    /// The method.
    pub method: Method,
    /// Its curve and quality, or why it failed (e.g. the hybrid method's
    /// coincident parameters on symmetric data).
    pub result: std::result::Result<(CurveFit, CurveQuality), Error>,
}

/// Interpolates `points` with each method of `config` (one progress step
/// each). An error only when every method fails, then the first one's
/// (the input is the problem, not the method).
///
/// ```
/// use scanfit::pipeline::curve::{compare, CompareConfig};
/// use scanfit::progress::NoProgress;
/// use scanfit::Point3;
///
/// let pts: Vec<Point3> = (0..12)
///     .map(|k| Point3::new(k as f64, ((k * k) % 5) as f64, 0.0))
///     .collect();
/// let rows = compare(&pts, &CompareConfig::default(), &NoProgress)?;
/// assert_eq!(rows.len(), 7);
/// assert!(rows[0].result.is_ok()); // centripetal
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn compare(
    points: &[Point3],
    config: &CompareConfig,
    progress: &dyn Progress,
) -> Result<Vec<MethodResult>> {
    progress.stage("parameterizations", Some(config.methods.len() as u64));
    let mut rows = Vec::with_capacity(config.methods.len());
    for &method in &config.methods {
        progress.stage(&method.to_string(), None);
        let cfg = InterpolationConfig {
            degree: config.degree,
            method,
            ..Default::default()
        };
        let result = interpolate(points, &cfg).map(|f| {
            let q = curve_quality(&f.curve, points, &f.params, &config.quality);
            (f, q)
        });
        rows.push(MethodResult { method, result });
        progress.advance(1);
    }
    if let Some(Err(e)) = rows.first().map(|r| &r.result) {
        if rows.iter().all(|r| r.result.is_err()) {
            return Err(e.clone());
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    #[test]
    fn closed_defaults_to_centripetal_and_refuses_end_derivatives() {
        let pts: Vec<Point3> = (0..16)
            .map(|k| {
                let t = k as f64 / 16.0 * std::f64::consts::TAU;
                Point3::new(t.cos(), 2.0 * t.sin(), 0.0)
            })
            .collect();
        let mut cfg = CurveConfig {
            closed: true,
            ..Default::default()
        };
        let r = run(&pts, &cfg, &NoProgress).unwrap();
        assert_eq!(r.fit.method, Method::Centripetal);
        assert!(r.fit.curve.is_periodic());
        assert_eq!(r.quality.self_intersections, 0);
        cfg.kind = CurveFitKind::Interpolation {
            end_derivatives: Some((Vector3::x(), Vector3::y())),
        };
        let e = run(&pts, &cfg, &NoProgress).unwrap_err();
        assert!(
            matches!(
                e,
                Error::InvalidSetting {
                    setting: "end_derivatives",
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn compare_fails_only_when_every_method_fails() {
        // two points coincide: every method refuses
        let pts = vec![
            Point3::new(0., 0., 0.),
            Point3::new(1., 0., 0.),
            Point3::new(1., 0., 0.),
            Point3::new(2., 1., 0.),
            Point3::new(3., 0., 0.),
        ];
        let e = compare(&pts, &CompareConfig::default(), &NoProgress).unwrap_err();
        assert_eq!(e.point_indices(), vec![1, 2]);
    }
}
