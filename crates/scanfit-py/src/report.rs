//! The library's reports as Python dicts, with the key names of the command
//! line's JSON (the surface document's `quality`, `--json`'s
//! `samples_to_points`), so a script can read either.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use scanfit::base::{Projection, ProjectionAxis};
use scanfit::metrics::{ErrorStats, ParamQuality};
use scanfit::pipeline::{Assessment, SurfaceQuality};

use crate::convert::vec1;

/// `{count, mean, max, max_index, rmse}`.
pub fn stats<'py>(py: Python<'py>, s: &ErrorStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("count", s.count)?;
    d.set_item("mean", s.mean)?;
    d.set_item("max", s.max)?;
    d.set_item("max_index", s.max_index)?;
    d.set_item("rmse", s.rmse)?;
    Ok(d)
}

/// The projection direction of ``params="plane"`` and the fold shares that
/// chose it, with the keys of the command line's ``projection``: ``axis``
/// (``"best-fit plane"``, ``"x"``, ``"y"`` or ``"z"``), ``direction``,
/// ``fold_shares`` (per candidate name), ``sampled``, ``extent``.
pub fn projection<'py>(py: Python<'py>, p: &Projection) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("axis", p.axis.name())?;
    d.set_item("direction", [p.direction.x, p.direction.y, p.direction.z])?;
    let shares = PyDict::new(py);
    for (a, s) in ProjectionAxis::ALL.iter().zip(p.fold_shares) {
        shares.set_item(a.name(), s)?;
    }
    d.set_item("fold_shares", shares)?;
    d.set_item("sampled", p.sampled)?;
    d.set_item("extent", p.extent)?;
    Ok(d)
}

/// The parameterization measures: fold-overs, stretch, anisotropy.
pub fn param_quality<'py>(py: Python<'py>, q: &ParamQuality) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("triangles", q.triangles)?;
    d.set_item("fold_overs", q.fold_overs)?;
    d.set_item("l2_stretch", q.l2_stretch)?;
    d.set_item("max_anisotropy", q.max_anisotropy)?;
    Ok(d)
}

/// The surface document's `quality` (`scanfit/1` schema field names) plus
/// `samples_to_points` as the command line's `--json` prints it.
pub fn quality<'py>(
    py: Python<'py>,
    q: &SurfaceQuality,
    correction_rmse: Vec<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("points", q.points)?;
    d.set_item("mean_error", q.at_parameters.mean)?;
    d.set_item("max_error", q.at_parameters.max)?;
    d.set_item("rmse", q.at_parameters.rmse)?;
    d.set_item("mean_distance", q.orthogonal.mean)?;
    d.set_item("max_distance", q.orthogonal.max)?;
    d.set_item("rmse_distance", q.orthogonal.rmse)?;
    d.set_item("unconverged", q.unconverged)?;
    d.set_item("grid_rmse", q.grid_rmse)?;
    d.set_item("triangles", q.parameterization.triangles)?;
    d.set_item("fold_overs", q.parameterization.fold_overs)?;
    d.set_item("l2_stretch", q.parameterization.l2_stretch)?;
    d.set_item("max_anisotropy", q.parameterization.max_anisotropy)?;
    d.set_item("correction_rmse", correction_rmse)?;
    let s = &q.samples_to_points;
    let t = PyDict::new(py);
    t.set_item("samples", s.stats.count)?;
    t.set_item("grid", [s.grid.0, s.grid.1])?;
    t.set_item("mean", s.stats.mean)?;
    t.set_item("max", s.stats.max)?;
    t.set_item("rmse", s.stats.rmse)?;
    t.set_item("point_spacing", s.spacing)?;
    t.set_item("far_spacings", s.far_spacings)?;
    t.set_item("far_share", s.far_share)?;
    let e = &q.extent;
    t.set_item("outside_box", e.samples_outside)?;
    t.set_item("outside_box_spacings", e.samples_outside_spacings)?;
    t.set_item("control_net_outside_box", e.control_outside)?;
    t.set_item("leaves_data", e.leaves)?;
    d.set_item("samples_to_points", t)?;
    Ok(d)
}

/// Warns (`UserWarning`) when the surface leaves the data: its samples
/// reach farther outside the points' bounding box than the library's limit
/// ([`scanfit::pipeline::Extent`]; the command line refuses to write such
/// a surface unless `--allow-extrapolation`).
fn warn_extent(py: Python<'_>, q: &SurfaceQuality) -> PyResult<()> {
    let e = &q.extent;
    if !e.leaves {
        return Ok(());
    }
    let msg = format!(
        "the surface leaves the data: samples reach {:.6e} ({:.0} point spacings) outside the points' bounding box and control points {:.6e} (limit {:.6e}); quality['samples_to_points'] has the numbers",
        e.samples_outside, e.samples_outside_spacings, e.control_outside, e.limit
    );
    let cat = py.get_type::<pyo3::exceptions::PyUserWarning>();
    let text = std::ffi::CString::new(msg).unwrap_or_default();
    PyErr::warn(py, &cat, &text, 1)
}

/// Puts an assessment into `d`: `quality` (see [`quality`]), `residuals`
/// (`|P_i - S(u_i, v_i)|` per point), `distances` (orthogonal, per point)
/// and `converged` (per point, of the point inversion); warns when the
/// surface leaves the data.
pub fn assessment(
    d: &Bound<'_, PyDict>,
    a: &Assessment,
    correction_rmse: Vec<f64>,
) -> PyResult<()> {
    let py = d.py();
    warn_extent(py, &a.quality)?;
    d.set_item("quality", quality(py, &a.quality, correction_rmse)?)?;
    d.set_item("residuals", vec1(py, a.residuals.clone()))?;
    d.set_item("distances", vec1(py, a.distances().to_vec()))?;
    let mut converged = vec![true; a.distances().len()];
    for &i in &a.unconverged {
        if let Some(c) = converged.get_mut(i) {
            *c = false;
        }
    }
    d.set_item("converged", vec1(py, converged))?;
    Ok(())
}
