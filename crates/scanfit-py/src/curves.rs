//! The curve pipelines: `fit_curve` (`scanfit curve fit`) and
//! `compare_curves` (`scanfit curve compare`), over
//! `scanfit::pipeline::curve`.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use scanfit::param::Method;
use scanfit::pipeline::curve::{compare, run, CompareConfig, CurveConfig, CurveFitKind};
use scanfit::progress::NoProgress;
use scanfit::quality::CurveQuality;

use crate::convert::{err, value_err, vec1, vec3};
use crate::geometry::PyCurve;

/// The quality table's fields (the curve document's `quality`).
fn quality<'py>(py: Python<'py>, q: &CurveQuality) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("max_deviation", q.max_deviation)?;
    d.set_item("max_deviation_index", q.max_deviation_index)?;
    d.set_item("mean_deviation", q.mean_deviation)?;
    d.set_item("rms_deviation", q.rms_deviation)?;
    d.set_item("max_distance", q.max_distance)?;
    d.set_item("max_curvature", q.max_curvature)?;
    d.set_item("max_curvature_at", q.max_curvature_at)?;
    d.set_item("curvature_sign_changes", q.curvature_sign_changes)?;
    d.set_item("self_intersections", q.self_intersections)?;
    d.set_item("length", q.length)?;
    d.set_item("polygon_length", q.polygon_length)?;
    d.set_item("length_ratio", q.length_ratio)?;
    Ok(d)
}

/// A method by its command-line name (`proposed[:a]`, `chord`, ...).
fn method_of(s: &str) -> PyResult<Method> {
    Method::parse(s).map_err(err)
}

/// A B-spline curve through (interpolation) or near (least squares) a
/// sequence of points (``scanfit curve fit``).
///
/// Parameters:
///     points: an ``(N, 3)`` array, in order along the curve.
///     degree: the degree (default 3).
///     method: the parameterization (the curve paper's seven): ``"uniform"``,
///         ``"chord"``, ``"centripetal"``, ``"exponential[:a]"``,
///         ``"universal"``, ``"hybrid"``, ``"proposed[:a]"``; default the
///         paper's proposed method (a = 0.8) for open curves, centripetal for
///         closed ones.
///     ctrl: least squares with this many control points (default:
///         interpolation through every point).
///     closed: the points form a loop: a periodic curve.
///     free_ends: least squares only: let the ends move (default pinned).
///     smooth: least squares only: bending-energy weight ``λ ∫|C''|² du``.
///     end_tangents: interpolation only: ``(d0, d1)``, the derivatives
///         ``dC/du`` at the start and end.
///
/// Returns a dict: ``curve`` (``Curve``), ``params`` (each point's ``u``),
/// ``method``, ``kind``, ``condition`` (of the system), ``fitted_points``,
/// ``quality`` (deviations, curvature, loops, length ratio).
///
/// Example::
///
///     >>> import numpy as np
///     >>> pts = np.loadtxt("examples/data/dataset1.csv", delimiter=",", skiprows=1)
///     >>> r = scanfit.fit_curve(np.column_stack([pts, np.zeros(len(pts))]))  # doctest: +SKIP
#[pyfunction]
#[pyo3(signature = (points, degree = 3, method = None, ctrl = None, closed = false, free_ends = false, smooth = 0.0, end_tangents = None))]
#[allow(clippy::too_many_arguments)]
pub fn fit_curve<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    degree: usize,
    method: Option<&str>,
    ctrl: Option<usize>,
    closed: bool,
    free_ends: bool,
    smooth: f64,
    end_tangents: Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let pts = crate::convert::points(points, "points")?;
    let mut cfg = CurveConfig::default();
    cfg.degree = degree;
    cfg.method = method.map(method_of).transpose()?;
    cfg.closed = closed;
    cfg.kind = match ctrl {
        Some(n) => {
            if end_tangents.is_some() {
                return Err(value_err(
                    "end_tangents is for interpolation; least squares (ctrl) pins or frees the ends (free_ends)".into(),
                ));
            }
            CurveFitKind::LeastSquares {
                ctrl_count: n,
                fix_ends: !free_ends,
                smoothing: smooth,
            }
        }
        None => {
            if free_ends || smooth != 0.0 {
                return Err(value_err(
                    "free_ends and smooth are for least squares; give ctrl (the number of control points)".into(),
                ));
            }
            CurveFitKind::Interpolation {
                end_derivatives: match end_tangents {
                    None => None,
                    Some((a, b)) => {
                        Some((vec3(&a, "end_tangents[0]")?, vec3(&b, "end_tangents[1]")?))
                    }
                },
            }
        }
    };
    let r = py.detach(|| run(&pts, &cfg, &NoProgress)).map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("curve", PyCurve::new(r.fit.curve.clone()))?;
    d.set_item("params", vec1(py, r.fit.params.clone()))?;
    d.set_item("method", r.fit.method.name())?;
    d.set_item("kind", cfg.kind.label())?;
    d.set_item("condition", r.fit.condition)?;
    d.set_item("fitted_points", r.fitted_points)?;
    d.set_item("quality", quality(py, &r.quality)?)?;
    Ok(d)
}

/// Interpolation with every parameterization method of the curve paper,
/// side by side (``scanfit curve compare``): a list of dicts, one per
/// method in ``methods`` (default all seven, in the paper's order), each
/// with ``method`` and either ``curve``, ``params``, ``quality`` or
/// ``error`` (why the method failed, e.g. the hybrid method's coincident
/// parameters on symmetric data). Raises ``ScanfitError`` only when every
/// method fails.
#[pyfunction]
#[pyo3(signature = (points, degree = 3, methods = None))]
pub fn compare_curves<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    degree: usize,
    methods: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyList>> {
    let pts = crate::convert::points(points, "points")?;
    let mut cfg = CompareConfig::default();
    cfg.degree = degree;
    if let Some(ms) = methods {
        cfg.methods = ms.iter().map(|m| method_of(m)).collect::<PyResult<_>>()?;
    }
    let rows = py
        .detach(|| compare(&pts, &cfg, &NoProgress))
        .map_err(err)?;
    let out = PyList::empty(py);
    for row in &rows {
        let d = PyDict::new(py);
        d.set_item("method", row.method.name())?;
        match &row.result {
            Ok((fit, q)) => {
                d.set_item("curve", PyCurve::new(fit.curve.clone()))?;
                d.set_item("params", vec1(py, fit.params.clone()))?;
                d.set_item("condition", fit.condition)?;
                d.set_item("quality", quality(py, q)?)?;
                d.set_item("error", py.None())?;
            }
            Err(e) => {
                d.set_item("curve", py.None())?;
                d.set_item("error", e.to_string())?;
            }
        }
        out.append(d)?;
    }
    Ok(out)
}
