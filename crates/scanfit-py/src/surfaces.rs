//! The surface pipelines: `fit_surface` (`scanfit fit`), `mba`
//! (`scanfit mba`), `coons` (`scanfit coons`) and `turntable`
//! (`scanfit turntable`), each a call of its `scanfit::pipeline` module with
//! the command line's defaults as keyword defaults, the report as a dict.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use scanfit::base::turntable::{AxisChoice, Ends};
use scanfit::base::{BoundaryFit, CoonsProjection};
use scanfit::fit::surface::{KnotPlacement, SurfaceFitConfig};
use scanfit::mba::adjust::AdjustConfig;
use scanfit::mba::{ControlFormula, MbaConfig, Start};
use scanfit::pde::PdeConfig;
use scanfit::pipeline::coons::{run as run_coons, CoonsConfig, CoonsRoute};
use scanfit::pipeline::mba::{run as run_mba, MbaRunConfig};
use scanfit::pipeline::surface_fit::{run as run_fit, FitConfig, ParameterSource};
use scanfit::pipeline::turntable::{run as run_turntable, TurntableConfig, WeightComparison};
use scanfit::progress::NoProgress;
use scanfit::project::{DirectedConfig, GridIterationConfig, InversionConfig, WeightFactor};
use scanfit::up_axis::UpAxis;
use scanfit::PointCloud;

use crate::cloud::{cloud_arg, criterion_of, CloudArg};
use crate::convert::{bad_choice, err, pair, uv_arrays, uv_columns, value_err, vec1, vec3};
use crate::geometry::{PyCurve, PySurface};
use crate::report::{assessment, param_quality, stats};

/// A weight factor by its command-line name.
pub fn weight_of(s: &str) -> PyResult<WeightFactor> {
    match s {
        "moon" => Ok(WeightFactor::DistanceOffset),
        "aza04" => Ok(WeightFactor::PointDistance),
        "as05" => Ok(WeightFactor::DampedDistanceOffset),
        "axis4" => Ok(WeightFactor::LineOffset),
        o => Err(bad_choice("weight", o, &["moon", "aza04", "as05", "axis4"])),
    }
}

/// Puts `u` and `v` arrays of `uv` into `d`.
fn put_uv(d: &Bound<'_, PyDict>, uv: &[[f64; 2]]) -> PyResult<()> {
    let (u, v) = uv_arrays(d.py(), uv);
    d.set_item("u", u)?;
    d.set_item("v", v)
}

/// The settings of `fit_surface` from its keywords (shared with the
/// distributed fit, `scanfit.sums.NormalEquations`).
pub fn fit_config(
    ctrl: Option<&Bound<'_, PyAny>>,
    degree: Option<&Bound<'_, PyAny>>,
    params: &str,
    knots: &str,
    smooth: Option<f64>,
    periodic_u: bool,
    correct: usize,
) -> PyResult<FitConfig> {
    let mut cfg = FitConfig::default();
    if let Some(c) = ctrl {
        cfg.fit.ctrl = pair(c, "ctrl")?;
        cfg.ctrl_from_density = false;
    }
    if let Some(l) = smooth {
        cfg.fit.smoothing = l;
        cfg.relative_smoothing = None;
    }
    if let Some(g) = degree {
        cfg.fit.degree = pair(g, "degree")?;
    }
    cfg.params = match params {
        "plane" => ParameterSource::Plane,
        "uv" => ParameterSource::uv_attributes(),
        o => return Err(bad_choice("params", o, &["plane", "uv"])),
    };
    cfg.fit.knots = match knots {
        "distribution" => KnotPlacement::Distribution,
        "uniform" => KnotPlacement::Uniform,
        o => return Err(bad_choice("knots", o, &["distribution", "uniform"])),
    };
    cfg.fit.periodic_u = periodic_u;
    cfg.correction_rounds = correct;
    Ok(cfg)
}

/// The level loop's settings of `mba` from its keywords (shared with the
/// distributed MBA, `scanfit.sums.MbaLevels`).
pub fn mba_config(
    levels: usize,
    base: Option<&Bound<'_, PyAny>>,
    tolerance: Option<f64>,
    hjelle: bool,
    start: &str,
) -> PyResult<MbaConfig> {
    let start = match start {
        "mean" => Start::Mean,
        "fitted" => Start::Fitted,
        o => return Err(bad_choice("start", o, &["mean", "fitted"])),
    };
    let c = MbaConfig {
        base: base.map(|b| pair(b, "base")).transpose()?,
        max_levels: levels,
        tolerance,
        formula: if hjelle {
            ControlFormula::Hjelle
        } else {
            ControlFormula::LeeWolbergShin
        },
        start,
    };
    Ok(c)
}

/// Least-squares B-spline surface through scattered points (``scanfit fit``).
///
/// Parameters:
///     points: an ``(N, 3)`` array or a ``Cloud``.
///     ctrl: control net ``(nu, nv)`` or one int for both (default: from
///         the point density, ``round(sqrt(points / 16))`` per direction, 5
///         to 32).
///     degree: degrees ``(p, q)`` or one int (default bicubic).
///     params: where the points' ``(u, v)`` come from: ``"plane"`` (the
///         best-fit plane, scaled to the unit square; for height-field-like
///         patches) or ``"uv"`` (the ``u`` and ``v`` attributes of a Cloud).
///     uv: an ``(N, 2)`` array of given parameters (overrides ``params``).
///     knots: ``"distribution"`` (interior knots follow the parameters,
///         NURBS Book eq. 9.69) or ``"uniform"``.
///     smooth: thin-plate smoothing weight on ``∫∫ S_uu² + 2 S_uv² + S_vv²``
///         (0 = the bare least-squares fit; default: scaled to the data,
///         ``0.001 x points / (nu x nv)²``, which keeps sparsely covered
///         spans from flying off; the weight used is ``result["smoothing"]``).
///     periodic_u: close the surface in ``u`` (needs given parameters).
///     correct: rounds of Hoschek's parameter correction (re-project, refit).
///
/// Returns a dict: ``surface`` (``Surface``), ``smoothing`` (the weight
/// used), ``u``, ``v`` (the points' parameters), ``quality`` (the surface document's quality: ``mean_error``,
/// ``max_error``, ``rmse`` at the parameters (PDE paper eq. 15),
/// ``*_distance`` orthogonal, ``grid_rmse`` (MBA paper eq. 17), fold-overs,
/// ``samples_to_points``), ``residuals`` and ``distances`` per point,
/// ``converged`` per point, ``rounds`` (the correction rounds), with
/// ``params="plane"`` ``projection`` (the direction the points were
/// projected along: ``axis`` is ``"best-fit plane"``, or ``"x"``, ``"y"``,
/// ``"z"`` when the best-fit plane folds the points over and that axis does
/// not; ``fold_shares`` per candidate, measured on a seeded sample of 4000
/// points; ``direction``, ``sampled``, ``extent``). A surface
/// whose samples leave the points' bounding box by more than the library's
/// limit (``quality["samples_to_points"]["leaves_data"]``) raises a
/// ``UserWarning`` (the command line refuses to write it).
///
/// Example::
///
///     >>> cloud = scanfit.read_cloud("examples/data/terrain_50k.xyz")
///     >>> r = scanfit.fit_surface(cloud, ctrl=(30, 30))
///     >>> r["quality"]["rmse_distance"]  # doctest: +SKIP
///     29.6
#[pyfunction]
#[pyo3(signature = (points, ctrl = None, degree = None, params = "plane", uv = None, knots = "distribution", smooth = None, periodic_u = false, correct = 0))]
#[allow(clippy::too_many_arguments)]
pub fn fit_surface<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    ctrl: Option<Bound<'py, PyAny>>,
    degree: Option<Bound<'py, PyAny>>,
    params: &str,
    uv: Option<Bound<'py, PyAny>>,
    knots: &str,
    smooth: Option<f64>,
    periodic_u: bool,
    correct: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let mut cloud = cloud_arg(points, "points")?;
    let mut cfg = fit_config(
        ctrl.as_ref(),
        degree.as_ref(),
        params,
        knots,
        smooth,
        periodic_u,
        correct,
    )?;
    if let Some(uv) = uv {
        let n = cloud.get().len();
        let (u, v) = uv_columns(&uv, n)?;
        let c = cloud.get().clone().with_attribute("u", u).map_err(err)?;
        cloud = CloudArg::Owned(c.with_attribute("v", v).map_err(err)?);
        cfg.params = ParameterSource::uv_attributes();
    }
    let c = cloud.get();
    let r = py.detach(|| run_fit(c, &cfg, &NoProgress)).map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("surface", PySurface::new(r.surface.clone()))?;
    d.set_item("smoothing", r.smoothing)?;
    put_uv(&d, &r.uv)?;
    assessment(
        &d,
        &r.assessment,
        r.rounds.iter().map(|x| x.errors.rmse).collect(),
    )?;
    let rounds = PyList::empty(py);
    for x in &r.rounds {
        let e = PyDict::new(py);
        e.set_item("round", x.round)?;
        e.set_item("rmse", x.errors.rmse)?;
        e.set_item("max", x.errors.max)?;
        rounds.append(e)?;
    }
    d.set_item("rounds", rounds)?;
    if let Some(p) = &r.projection {
        d.set_item("projection", crate::report::projection(py, p)?)?;
    }
    Ok(d)
}

/// Multilevel B-spline approximation of 2.5D points, ``z = f(x, y)``
/// (Lee, Wolberg & Shin 1997; ``scanfit mba``), optionally with the MBA
/// paper's projection adjustment of the control points (sections 2.2-2.4).
///
/// Parameters:
///     points: an ``(N, 3)`` array or a ``Cloud`` (z is the height).
///     levels: most levels, each doubling the lattice (default 6).
///     base: cells ``(m, n)`` of the first lattice (default: 1 along the
///         shorter side, the aspect ratio along the longer).
///     tolerance: stop once the vertical RMSE (with ``adjust``, the eq. 17
///         RMSE) is at most this, in data units.
///     hjelle: Hjelle's control-value formula (turntable paper eq. 6)
///         instead of Lee-Wolberg-Shin eq. 4.
///     adjust: project the knot grid onto the data along z and move the
///         control values by ``alpha`` times the distance (MBA paper).
///     alpha: step factor of the adjustment (default 1.49, the paper's).
///     weight: the directed projection's weight factor: ``"moon"``
///         (turntable eq. 19), ``"aza04"`` (MBA eq. 13), ``"as05"`` (eq. 14),
///         ``"axis4"`` (eq. 15).
///     adjust_steps: most adjustment steps per level (default 5).
///     start: the function level 0 starts from, as ``scanfit mba --start``:
///         ``"fitted"`` (the default: the constant that leaves the smallest
///         residual at the points after all levels, at the mean's cost) or
///         ``"mean"`` (the mean height); ``None`` is ``"fitted"``, or
///         ``"mean"`` with ``adjust=True`` (the adjustment starts from the
///         mean; ``"fitted"`` with it is refused).
///     up: the height axis, as ``scanfit mba --up``: ``"auto"`` (the
///         default: the thin axis of a sheet, else z), ``"x"``, ``"y"`` or
///         ``"z"``. A y-up scan is fitted as ``y = f(x, -z)`` (the z-up fit
///         turned), not as a wall of spikes over x, y.
///
/// Returns a dict: ``surface``, ``cells``, ``up`` (the height axis used), ``u``, ``v``, ``vertical``
/// (``|z - f(x, y)|`` per point), ``levels`` (one dict per level:
/// ``level``, ``control_points``, ``vertical``, ``grid_rmse``,
/// ``adjusted``, ``seconds``), ``seconds``, ``quality``, ``residuals``,
/// ``distances``, ``converged``.
///
/// Example::
///
///     >>> r = scanfit.mba(cloud, levels=5, adjust=True)
///     >>> [l["grid_rmse"] for l in r["levels"]]  # doctest: +SKIP
#[pyfunction]
#[pyo3(signature = (points, levels = 6, base = None, tolerance = None, hjelle = false, adjust = false, alpha = 1.49, weight = "moon", adjust_steps = 5, start = None, up = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn mba<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    levels: usize,
    base: Option<Bound<'py, PyAny>>,
    tolerance: Option<f64>,
    hjelle: bool,
    adjust: bool,
    alpha: f64,
    weight: &str,
    adjust_steps: usize,
    start: Option<&str>,
    up: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let start = match (start, adjust) {
        (Some("fitted"), true) => {
            return Err(value_err(
                "start='fitted' with adjust=True: the adjustment changes the lattices between levels, so the constant's levels no longer give the start; it starts from the mean (leave start out)".into(),
            ))
        }
        (Some(s), _) => s,
        (None, true) => "mean",
        (None, false) => "fitted",
    };
    let cloud = cloud_arg(points, "points")?;
    let mut cfg = MbaRunConfig::default();
    cfg.up = match up {
        "auto" => UpAxis::automatic(cloud.get().points()),
        "x" => UpAxis::X,
        "y" => UpAxis::Y,
        "z" => UpAxis::Z,
        o => return Err(bad_choice("up", o, &["auto", "x", "y", "z"])),
    };
    cfg.mba = mba_config(levels, base.as_ref(), tolerance, hjelle, start)?;
    let weight = weight_of(weight)?;
    cfg.adjust = adjust.then(|| AdjustConfig {
        alpha,
        projection: DirectedConfig {
            weight,
            ..Default::default()
        },
        max_steps: adjust_steps,
        ..Default::default()
    });
    let c = cloud.get();
    let r = py.detach(|| run_mba(c, &cfg, &NoProgress)).map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("surface", PySurface::new(r.surface.clone()))?;
    d.set_item("cells", r.cells)?;
    d.set_item("up", r.up.name())?;
    put_uv(&d, &r.uv)?;
    d.set_item("vertical", vec1(py, r.vertical.clone()))?;
    let rows = PyList::empty(py);
    for l in &r.levels {
        let e = PyDict::new(py);
        e.set_item("level", l.level)?;
        e.set_item("control_points", l.control_points)?;
        e.set_item("vertical", stats(py, &l.vertical)?)?;
        e.set_item("grid_rmse", l.grid_rmse)?;
        match &l.adjusted {
            Some(a) => {
                let x = PyDict::new(py);
                x.set_item("vertical_rmse", a.vertical_rmse)?;
                x.set_item("grid_rmse", a.grid_rmse)?;
                x.set_item("steps", a.steps)?;
                e.set_item("adjusted", x)?;
            }
            None => e.set_item("adjusted", py.None())?,
        }
        e.set_item("seconds", l.seconds)?;
        rows.append(e)?;
    }
    d.set_item("levels", rows)?;
    d.set_item("seconds", r.seconds)?;
    assessment(&d, &r.assessment, Vec::new())?;
    Ok(d)
}

/// One patch of points to a surface by the Coons paper (B-spline route) or
/// the PDE paper (``pde=(m, n)``; ``scanfit coons``): boundary loop (alpha
/// shape), corners, one B-spline per side, the bilinearly blended Coons
/// patch, the points' parameters on it, then a least-squares B-spline
/// surface (``ctrl``, default from the point density; ``degree``; ``smooth``,
/// default scaled to the data, as ``fit_surface``) or the thin-plate PDE deformation with
/// ``m x n`` sine terms (PDE paper eqs. 11-14), exported as a B-spline
/// within ``export_tolerance`` (default 1e-4 x the bounding-box diagonal).
///
/// Parameters:
///     corners: ``None`` (detect) or the loop positions of the corners, as
///         ``boundary`` lists them; ``sides``: 4 or 3.
///     criterion: ``"angle"`` (Coons paper eqs. 10-12) or ``"curvature"``
///         (PDE paper 4.1).
///     alpha, alpha_factor: the alpha shape (as ``boundary``).
///     curves: ``"lsq"`` (end-pinned least squares, ``curve_ctrl`` control
///         points, default automatic) or ``"interpolate"``.
///     params: ``"grid"`` (the Coons paper's grid iteration with step ``h``
///         and threshold ``epsilon`` in data units, default 1e-3 x the
///         bounding-box diagonal; default on the B-spline route) or ``"closest"``
///         (exact closest point; default on the PDE route).
///     rigidity: the PDE's ``D`` (default 1).
///
/// Returns a dict: ``surface``, ``coons_surface`` (the patch in B-spline
/// form), ``boundary_curves`` (``Curve`` per side), ``corners`` (input
/// indices), ``u``, ``v``, ``outside`` (bool per point), ``coons_distances``
/// and ``coons_errors`` (PDE paper eq. 15 for the patch alone), ``route``,
/// ``projection``, ``pde`` (``None`` or ``errors``, ``export_tolerance``,
/// ``export_deviation``), ``quality``, ``residuals``, ``distances``.
///
/// Example::
///
///     >>> r = scanfit.coons(scanfit.read_cloud("examples/data/patch_20k.ply"), pde=(5, 5))
///     >>> r["quality"]["rmse"]  # doctest: +SKIP
///     0.0699
#[pyfunction]
#[pyo3(signature = (points, pde = None, ctrl = None, degree = None, smooth = None, rigidity = 1.0, export_tolerance = None, params = None, h = 0.001, epsilon = None, corners = None, sides = 4, criterion = "angle", alpha = None, alpha_factor = 2.5, curves = "lsq", curve_ctrl = None))]
#[allow(clippy::too_many_arguments)]
pub fn coons<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    pde: Option<Bound<'py, PyAny>>,
    ctrl: Option<Bound<'py, PyAny>>,
    degree: Option<Bound<'py, PyAny>>,
    smooth: Option<f64>,
    rigidity: f64,
    export_tolerance: Option<f64>,
    params: Option<&str>,
    h: f64,
    epsilon: Option<f64>,
    corners: Option<Vec<usize>>,
    sides: usize,
    criterion: &str,
    alpha: Option<f64>,
    alpha_factor: f64,
    curves: &str,
    curve_ctrl: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let cloud = cloud_arg(points, "points")?;
    let mut cfg = CoonsConfig::default();
    cfg.route = match pde {
        Some(t) => {
            if ctrl.is_some() || degree.is_some() || smooth.is_some() {
                return Err(value_err(
                    "pde and ctrl/degree/smooth exclude each other: the PDE route has sine terms, the B-spline route a control net; choose one".into(),
                ));
            }
            let (m, n) = pair(&t, "pde")?;
            CoonsRoute::Pde {
                pde: PdeConfig { m, n, d: rigidity },
                export_tolerance,
            }
        }
        None => {
            let mut f = SurfaceFitConfig {
                degree: degree
                    .map(|g| pair(&g, "degree"))
                    .transpose()?
                    .unwrap_or((3, 3)),
                ..Default::default()
            };
            if let Some(c) = ctrl {
                f.ctrl = pair(&c, "ctrl")?;
                cfg.ctrl_from_density = false;
            }
            if let Some(l) = smooth {
                f.smoothing = l;
                cfg.relative_smoothing = None;
            }
            CoonsRoute::Bspline(f)
        }
    };
    // the grid iteration's epsilon: given in data units, else relative to the diagonal
    let grid = GridIterationConfig {
        h,
        epsilon: epsilon.unwrap_or(GridIterationConfig::default().epsilon),
        ..Default::default()
    };
    if epsilon.is_some() {
        cfg.relative_epsilon = None;
    }
    cfg.projection = match params {
        None if matches!(cfg.route, CoonsRoute::Bspline(_)) => {
            Some(CoonsProjection::GridIteration(grid))
        }
        None => None,
        Some("grid") => Some(CoonsProjection::GridIteration(grid)),
        Some("closest") => Some(CoonsProjection::Inversion(InversionConfig::default())),
        Some(o) => return Err(bad_choice("params", o, &["grid", "closest"])),
    };
    if !(sides == 3 || sides == 4) {
        return Err(value_err(format!(
            "sides = {sides}: a Coons patch has 4 or 3 sides"
        )));
    }
    cfg.base.boundary.alpha = alpha;
    cfg.base.boundary.alpha_factor = alpha_factor;
    cfg.base.corners.criterion = criterion_of(criterion)?;
    cfg.base.corners.count = sides;
    if let Some(c) = &corners {
        if c.len() != sides {
            return Err(value_err(format!(
                "corners lists {} positions but sides is {sides}; give one position per corner",
                c.len()
            )));
        }
    }
    cfg.base.corner_positions = corners;
    cfg.base.curves.degree = 3;
    cfg.base.curves.fit = match curves {
        "lsq" => BoundaryFit::LeastSquares {
            ctrl_count: curve_ctrl,
        },
        "interpolate" => BoundaryFit::Interpolation,
        o => return Err(bad_choice("curves", o, &["lsq", "interpolate"])),
    };
    let c = cloud.get();
    let r = py.detach(|| run_coons(c, &cfg, &NoProgress)).map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("surface", PySurface::new(r.surface.clone()))?;
    d.set_item("coons_surface", PySurface::new(r.coons_surface.clone()))?;
    let bc = PyList::empty(py);
    for b in &r.base.curves {
        bc.append(PyCurve::new(b.curve.clone()))?;
    }
    d.set_item("boundary_curves", bc)?;
    let outer = r.base.boundary.outer_loop();
    let corner_idx: Vec<usize> = r
        .base
        .corners
        .corners
        .iter()
        .filter_map(|&k| outer.get(k).copied())
        .collect();
    d.set_item("corners", corner_idx)?;
    d.set_item("corner_angles", r.base.corner_angles.clone())?;
    put_uv(&d, &r.parameters.uv)?;
    d.set_item("outside", vec1(py, r.parameters.outside.clone()))?;
    d.set_item("coons_distances", vec1(py, r.coons_distances.clone()))?;
    d.set_item("coons_errors", stats(py, &r.coons_errors)?)?;
    d.set_item("route", &r.route)?;
    d.set_item("projection", r.projection_name())?;
    match &r.pde {
        Some(p) => {
            let e = PyDict::new(py);
            e.set_item("errors", stats(py, &p.fit.errors)?)?;
            e.set_item("export_tolerance", p.export_tolerance)?;
            e.set_item("export_deviation", p.export_deviation)?;
            d.set_item("pde", e)?;
        }
        None => d.set_item("pde", py.None())?,
    }
    assessment(&d, &r.assessment, Vec::new())?;
    Ok(d)
}

/// Cylinder-like clouds by the virtual turntable (``scanfit turntable``):
/// the cloud turns about its axis in ``views`` steps, each turn's visible
/// points (hidden point removal) give a height field (MBA); on ``layers``
/// layers the height fields' grid rows form closed curves projected onto
/// the cloud (directed projection, ``weight``), which give a base surface,
/// refined ``refine`` times; every point's projection onto it is its
/// ``(u, v)``, and a least-squares bicubic surface closed around the axis
/// (``ctrl``, first count around) is fitted.
///
/// Parameters:
///     axis: ``None`` (the principal axis), ``"x"``, ``"y"``, ``"z"`` or a
///         direction ``(x, y, z)``.
///     grid: grid points per view and layer (default 32).
///     rounds: most projection rounds of the layer curves (default 10).
///     margin: fraction of the height left out at each closed end (default
///         0.03; an end the data show to be open, a rim with no points near
///         the axis, gets none: ``open_ends`` says which).
///     ends: ``"exclude"`` (points beyond the end layers are left out of
///         the fit) or ``"extend"``.
///     compare_weights: also run the paper's Tables 1-2 comparison of the
///         weight factors for ``compare_rounds`` rounds.
///
/// Returns a dict: ``surface``, ``base_surface``, ``u``, ``v``, ``fitted``
/// (bool per point), ``axis``, ``centre``, ``radius``, ``visible`` (per
/// view), ``layer_rmse``, ``refine_rmse``, ``base_distance``,
/// ``beyond_end_layers``, ``distance_all_points``, ``surface_to_cloud``,
/// ``parametric``, ``weight_comparison``, ``quality`` (over the fitted
/// points), ``residuals``, ``distances``, ``converged``.
#[pyfunction]
#[pyo3(signature = (points, axis = None, views = 4, grid = 32, layers = 40, weight = "moon", rounds = 10, refine = 2, margin = 0.03, ends = "exclude", ctrl = None, compare_weights = false, compare_rounds = 5))]
#[allow(clippy::too_many_arguments)]
pub fn turntable<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    axis: Option<Bound<'py, PyAny>>,
    views: usize,
    grid: usize,
    layers: usize,
    weight: &str,
    rounds: usize,
    refine: usize,
    margin: f64,
    ends: &str,
    ctrl: Option<Bound<'py, PyAny>>,
    compare_weights: bool,
    compare_rounds: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let cloud = cloud_arg(points, "points")?;
    let weight = weight_of(weight)?;
    let mut cfg = TurntableConfig::default();
    let t = &mut cfg.turntable;
    t.axis = match axis {
        None => AxisChoice::Principal,
        Some(a) => match a.extract::<String>().ok().as_deref() {
            Some("x") => AxisChoice::Given(scanfit::Vector3::x()),
            Some("y") => AxisChoice::Given(scanfit::Vector3::y()),
            Some("z") => AxisChoice::Given(scanfit::Vector3::z()),
            Some("auto") => AxisChoice::Principal,
            Some(o) => return Err(bad_choice("axis", o, &["auto", "x", "y", "z"])),
            None => AxisChoice::Given(vec3(&a, "axis")?),
        },
    };
    t.views.views = views;
    t.views.grid_u = grid;
    t.layers.layers = layers;
    t.layers.max_rounds = rounds;
    t.layers.projection.weight = weight;
    t.layers.margin = margin;
    t.refine.rounds = refine;
    t.refine.projection.weight = weight;
    t.ends = match ends {
        "exclude" => Ends::Exclude,
        "extend" => Ends::Extend,
        o => return Err(bad_choice("ends", o, &["exclude", "extend"])),
    };
    if let Some(c) = ctrl {
        t.fit.ctrl = pair(&c, "ctrl")?;
    }
    if compare_weights {
        cfg.compare_weights = Some(WeightComparison::with_rounds(compare_rounds));
    }
    let c: &PointCloud = cloud.get();
    let r = py
        .detach(|| run_turntable(c, &cfg, &NoProgress))
        .map_err(err)?;
    let t = &r.turntable;
    let d = PyDict::new(py);
    d.set_item("surface", PySurface::new(t.surface.clone()))?;
    d.set_item("base_surface", PySurface::new(t.base.clone()))?;
    put_uv(&d, &t.uv)?;
    d.set_item("fitted", vec1(py, t.fitted.clone()))?;
    let f = &t.frame;
    d.set_item("axis", [f.axis.x, f.axis.y, f.axis.z])?;
    d.set_item("centre", [f.centre.x, f.centre.y, f.centre.z])?;
    d.set_item("radius", f.radius)?;
    d.set_item(
        "visible",
        t.views.iter().map(|v| v.visible.len()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "layer_points",
        t.loops.iter().map(Vec::len).collect::<Vec<_>>(),
    )?;
    d.set_item("layer_rmse", t.layers.rmse.clone())?;
    d.set_item("base_grid", (t.grid_u, t.heights.len()))?;
    d.set_item("refine_rmse", t.refine_rmse.clone())?;
    d.set_item("base_distance", stats(py, &t.base_errors)?)?;
    d.set_item("beyond_end_layers", t.on_v_boundary)?;
    d.set_item("open_ends", (t.end_shapes[0].open, t.end_shapes[1].open))?;
    d.set_item("distance_all_points", stats(py, &t.errors_all)?)?;
    d.set_item("surface_to_cloud", stats(py, &t.surface_to_cloud)?)?;
    d.set_item("parametric", stats(py, &r.parametric)?)?;
    d.set_item(
        "fold_overs_inside_layers",
        param_quality(py, &t.quality_inside)?,
    )?;
    match &r.weight_comparison {
        Some(w) => {
            let l = PyList::empty(py);
            for x in w {
                let e = PyDict::new(py);
                e.set_item("weight", x.weight.name())?;
                e.set_item("rmse", x.rmse.clone())?;
                l.append(e)?;
            }
            d.set_item("weight_comparison", l)?;
        }
        None => d.set_item("weight_comparison", py.None())?,
    }
    assessment(&d, &r.assessment, Vec::new())?;
    Ok(d)
}
