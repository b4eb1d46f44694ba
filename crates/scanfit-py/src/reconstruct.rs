//! `reconstruct` (`scanfit reconstruct`, over
//! `scanfit::pipeline::reconstruct`) and `scanfit.Model`, the multi-patch
//! result whose patches share their edge curves, written through
//! scanfit-io (model JSON, STEP shell, IGES).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use scanfit::network::FaceFit;
use scanfit::pde::PdeConfig;
use scanfit::pipeline::reconstruct::{run, ReconstructConfig};
use scanfit::progress::NoProgress;
use scanfit::topology::PatchComplex;
use scanfit_io::iges::iges_model_file;
use scanfit_io::model::ModelDoc;
use scanfit_io::step_shell::step_shell_file;

use crate::cloud::cloud_arg;
use crate::convert::{bad_choice, err, io_err, pair, value_err};
use crate::geometry::{product_name, text_out, PyCurve, PySurface};
use crate::report::stats;

/// A multi-patch model: surfaces (faces) that share their boundary curves
/// (edges) and corners (vertices), as ``reconstruct`` returns it.
#[pyclass(name = "Model", module = "scanfit", frozen)]
pub struct PyModel {
    inner: PatchComplex,
}

#[pymethods]
impl PyModel {
    /// The patches' surfaces, a dict of patch id -> ``Surface``.
    #[getter]
    fn surfaces(&self) -> Vec<(i64, PySurface)> {
        self.inner
            .faces
            .iter()
            .map(|f| (f.id, PySurface::new(f.surface.clone())))
            .collect()
    }

    /// The shared edge curves, one ``Curve`` per edge.
    #[getter]
    fn edge_curves(&self) -> Vec<PyCurve> {
        self.inner
            .edges
            .iter()
            .map(|e| PyCurve::new(e.curve.clone()))
            .collect()
    }

    /// Whether every edge has two patches (the patches bound a solid).
    #[getter]
    fn closed(&self) -> bool {
        self.inner.is_closed()
    }

    /// The ``scanfit-model/1`` JSON document (geometry and topology; the
    /// command line adds provenance and the error report): the text, or
    /// written to ``path``.
    #[pyo3(signature = (path = None))]
    fn to_json(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        text_out(
            py,
            ModelDoc::new(&self.inner).to_json().map_err(io_err)?,
            path,
        )
    }

    /// One sewn STEP shell (a closed solid when every edge has two
    /// patches): the text, or written to ``path``.
    #[pyo3(signature = (path = None))]
    fn to_step(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        let name = product_name(&path);
        let t = step_shell_file(&self.inner, &name).map_err(io_err)?;
        text_out(py, t.text, path)
    }

    /// IGES: every patch (entity 128), then every edge curve once (126).
    #[pyo3(signature = (path = None))]
    fn to_iges(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        let name = product_name(&path);
        let t = iges_model_file(&self.inner, &name).map_err(io_err)?;
        text_out(py, t, path)
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({} patches, {} edges, {} vertices, {})",
            self.inner.faces.len(),
            self.inner.edges.len(),
            self.inner.vertices.len(),
            if self.inner.is_closed() {
                "closed"
            } else {
                "open"
            }
        )
    }
}

/// A whole object from a segmented scan (``scanfit reconstruct``; PDE
/// paper sections 4-5, Coons paper section III): the points carry an
/// integer patch id (attribute ``labels``, default the first of ``label``,
/// ``segment``, ``segment_id``, ``class``, ``scalar_label``); negative ids
/// and ``ignore`` are left out. Corners shared by the patches around them,
/// one curve per shared edge fitted once, then per patch the Coons patch of
/// its side curves and the PDE deformation (``pde=(m, n)``, default 5 x 5)
/// or a least-squares B-spline (``fit="bspline"``, ``ctrl`` default 8 x 8)
/// whose boundary rows are the edge curves, so neighbours meet exactly.
///
/// Returns a dict: ``model`` (``Model``, or ``None`` when a patch has more
/// than four sides; ``model_error`` says why), ``patches`` (per patch:
/// ``id``, ``sides``, ``edges``, ``points``, ``coons_errors``, ``errors``,
/// ``orthogonal``, ``conversion_deviation``, ``surface``), ``edges`` (per
/// edge: ``vertices``, ``patches``, ``max_gap``, ``max_normal_angle_deg``,
/// ``curve_error``, ``curve``), ``totals``.
///
/// Example::
///
///     >>> r = scanfit.reconstruct(scanfit.read_cloud("examples/data/vessel_30k.ply"))
///     >>> r["model"]
///     Model(14 patches, 28 edges, 16 vertices, closed)
///     >>> r["model"].to_step("vessel.stp")  # doctest: +SKIP
#[pyfunction]
#[pyo3(signature = (points, labels = None, ignore = None, fit = "pde", pde = None, ctrl = None, contact = 3.0, export_tolerance = None))]
#[allow(clippy::too_many_arguments)]
pub fn reconstruct<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    labels: Option<String>,
    ignore: Option<Vec<i64>>,
    fit: &str,
    pde: Option<Bound<'py, PyAny>>,
    ctrl: Option<Bound<'py, PyAny>>,
    contact: f64,
    export_tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let cloud = cloud_arg(points, "points")?;
    let mut cfg = ReconstructConfig::default();
    cfg.network.labels.attribute = labels;
    cfg.network.labels.ignore = ignore.unwrap_or_default();
    cfg.network.contact_factor = contact;
    cfg.tolerance = export_tolerance;
    cfg.fit = match fit {
        "pde" => {
            if ctrl.is_some() {
                return Err(value_err(
                    "ctrl is for fit=\"bspline\"; the PDE route takes pde=(m, n)".into(),
                ));
            }
            let (m, n) = pde.map(|t| pair(&t, "pde")).transpose()?.unwrap_or((5, 5));
            FaceFit::Pde(PdeConfig {
                m,
                n,
                ..Default::default()
            })
        }
        "bspline" => {
            if pde.is_some() {
                return Err(value_err(
                    "pde and fit=\"bspline\" exclude each other; choose one route".into(),
                ));
            }
            FaceFit::Bspline {
                ctrl: ctrl
                    .map(|c| pair(&c, "ctrl"))
                    .transpose()?
                    .unwrap_or((8, 8)),
            }
        }
        o => return Err(bad_choice("fit", o, &["pde", "bspline"])),
    };
    let c = cloud.get();
    let r = py.detach(|| run(c, &cfg, &NoProgress)).map_err(err)?;
    let d = PyDict::new(py);
    d.set_item(
        "model",
        PyModel {
            inner: r.complex.clone(),
        },
    )?;
    d.set_item("model_error", py.None())?;
    let patches = PyList::empty(py);
    for (p, f) in r.patches.iter().zip(&r.faces) {
        let e = PyDict::new(py);
        e.set_item("id", p.id)?;
        e.set_item("sides", p.sides)?;
        e.set_item("edges", p.edges)?;
        e.set_item("points", p.points)?;
        e.set_item("coons_errors", stats(py, &p.coons_errors)?)?;
        e.set_item("errors", stats(py, &p.errors)?)?;
        e.set_item("orthogonal", stats(py, &p.orthogonal)?)?;
        e.set_item("conversion_deviation", p.conversion_deviation)?;
        e.set_item("surface", PySurface::new(f.surface.clone()))?;
        patches.append(e)?;
    }
    d.set_item("patches", patches)?;
    let edges = PyList::empty(py);
    for (k, x) in r.edges.iter().enumerate() {
        let e = PyDict::new(py);
        e.set_item("vertices", x.vertices)?;
        e.set_item("patches", x.patches)?;
        e.set_item("max_gap", x.max_gap)?;
        e.set_item("max_normal_angle_deg", x.max_angle.to_degrees())?;
        e.set_item("curve_error", x.curve_error)?;
        match r.network.edges.get(k) {
            Some(ne) => e.set_item("curve", PyCurve::new(ne.curve.clone()))?,
            None => e.set_item("curve", py.None())?,
        }
        edges.append(e)?;
    }
    d.set_item("edges", edges)?;
    let t = &r.totals;
    let totals = PyDict::new(py);
    totals.set_item("patches", r.patches.len())?;
    totals.set_item("edges", r.edges.len())?;
    totals.set_item("vertices", r.network.vertices.len())?;
    totals.set_item("errors", stats(py, &t.errors)?)?;
    totals.set_item("orthogonal", stats(py, &t.orthogonal)?)?;
    totals.set_item("max_gap", t.max_gap)?;
    totals.set_item("max_normal_angle_deg", t.max_angle.to_degrees())?;
    totals.set_item("diagonal", t.diagonal)?;
    totals.set_item("closed", t.closed)?;
    d.set_item("totals", totals)?;
    Ok(d)
}
