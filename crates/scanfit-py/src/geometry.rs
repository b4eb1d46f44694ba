//! `scanfit.Surface` and `scanfit.Curve`: the library's B-spline surface and
//! curve with vectorized evaluation, derivatives, projection, their
//! control net and knots, and export through the scanfit-io writers.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyType;
use rayon::prelude::*;
use scanfit::bspline::{tessellate, BasisWorkspace, Curve, Surface};
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit::quality::closest_points;
use scanfit::{Point3, Vector3};
use scanfit_io::json::{parse_curve, parse_surface, CurveDoc, SurfaceDoc};
use scanfit_io::ply::{mesh_obj, mesh_ply, PlyFormat};
use scanfit_io::step::{step_file, CadItem};
use scanfit_io::{gltf::mesh_glb, iges::iges_file, write_atomic};

use crate::convert::{array, err, g, io_err, pair, parameters, rows3, value_err, vec1};

/// Refuses parameters outside `[lo, hi]` (a periodic direction wraps).
fn check_domain(vals: &[f64], (lo, hi): (f64, f64), periodic: bool, what: &str) -> PyResult<()> {
    if periodic {
        return Ok(());
    }
    if let Some(i) = vals.iter().position(|&x| x < lo || x > hi) {
        return Err(value_err(format!(
            "{what}[{i}] = {} is outside the domain [{lo}, {hi}]; clip it (np.clip) or use a parameter inside",
            vals[i]
        )));
    }
    Ok(())
}

/// Writes `text` to `path` atomically, or returns it when `path` is None.
pub(crate) fn text_out(
    py: Python<'_>,
    text: String,
    path: Option<PathBuf>,
) -> PyResult<Option<String>> {
    match path {
        None => Ok(Some(text)),
        Some(p) => {
            py.detach(|| write_atomic(&p, text.as_bytes()))
                .map_err(io_err)?;
            Ok(None)
        }
    }
}

/// The name a CAD file gives its product: the file stem, else "scanfit".
pub(crate) fn product_name(path: &Option<PathBuf>) -> String {
    path.as_ref()
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scanfit".into())
}

/// `item` as a STEP (`iges = false`) or IGES file: the text, or written to `path`.
fn cad_out(
    py: Python<'_>,
    item: CadItem<'_>,
    path: Option<PathBuf>,
    iges: bool,
) -> PyResult<Option<String>> {
    let name = product_name(&path);
    let text = if iges {
        iges_file(&[item], &name)
    } else {
        step_file(&[item], &name)
    };
    text_out(py, text.map_err(io_err)?, path)
}

/// A tensor-product B-spline (or NURBS) surface ``S(u, v)``.
///
/// Fitted surfaces come from the pipelines (``fit_surface``, ``mba``,
/// ``coons``, ``turntable``, ``reconstruct``); ``Surface.from_json`` reads a
/// document the command line or ``to_json`` wrote.
///
/// Example::
///
///     >>> import numpy as np, scanfit
///     >>> x, y = np.meshgrid(np.linspace(0, 1, 30), np.linspace(0, 1, 30))
///     >>> pts = np.column_stack([x.ravel(), y.ravel(), (x * y).ravel()])
///     >>> s = scanfit.fit_surface(pts, ctrl=(6, 6))["surface"]
///     >>> s.degree
///     (3, 3)
///     >>> float(s.evaluate(0.5, 0.5)[2])  # doctest: +ELLIPSIS
///     0.25...
#[pyclass(name = "Surface", module = "scanfit", frozen)]
#[derive(Clone)]
pub struct PySurface {
    /// The library's surface.
    pub inner: Surface,
}

impl PySurface {
    /// Wraps a library surface.
    pub fn new(inner: Surface) -> Self {
        Self { inner }
    }

    /// `(u, v)` flattened with their common shape, checked against the domain.
    fn uv(
        &self,
        u: &Bound<'_, PyAny>,
        v: &Bound<'_, PyAny>,
    ) -> PyResult<(Vec<f64>, Vec<f64>, Vec<usize>)> {
        let (mut vals, shape) = parameters(&[(u, "u"), (v, "v")])?;
        let vs = vals.pop().unwrap_or_default();
        let us = vals.pop().unwrap_or_default();
        let (du, dv) = self.inner.domain();
        let (pu, pv) = self.inner.periodic();
        check_domain(&us, du, pu, "u")?;
        check_domain(&vs, dv, pv, "v")?;
        Ok((us, vs, shape))
    }
}

#[pymethods]
impl PySurface {
    /// Points ``S(u, v)``: ``u`` and ``v`` are numbers or arrays of one shape;
    /// the result has that shape plus a last axis of 3 (``(3,)`` for
    /// scalars). Parameters outside the domain raise ``ScanfitError``
    /// (periodic directions wrap).
    ///
    /// Example::
    ///
    ///     >>> uu, vv = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 4), indexing="ij")
    ///     >>> surface.evaluate(uu, vv).shape
    ///     (5, 4, 3)
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (us, vs, shape) = self.uv(u, v)?;
        let s = &self.inner;
        let flat = py.detach(|| {
            let mut out = vec![0.0; us.len() * 3];
            out.par_chunks_mut(3)
                .zip(us.par_iter().zip(vs.par_iter()))
                .for_each(|(o, (&u, &v))| {
                    let p = s.point(u, v);
                    o.copy_from_slice(&[p.x, p.y, p.z]);
                });
            out
        });
        rows3(py, flat, &shape)
    }

    /// Partial derivatives ``d^(k+l) S / du^k dv^l`` for ``k + l <= order``
    /// (NURBS Book A3.6, A4.4 for rational surfaces): an array of shape
    /// ``u.shape + (order + 1, order + 1, 3)`` whose entry ``[..., k, l, :]``
    /// is that derivative (zero where ``k + l > order``); ``[..., 0, 0, :]``
    /// is the point.
    ///
    /// Example::
    ///
    ///     >>> d = surface.derivatives(0.3, 0.6, order=1)
    ///     >>> su, sv = d[1, 0], d[0, 1]       # tangents
    ///     >>> normal = np.cross(su, sv)
    #[pyo3(signature = (u, v, order = 1))]
    fn derivatives<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        order: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        if order > 7 {
            return Err(value_err(format!(
                "order = {order}: derivatives up to order 7 are supported"
            )));
        }
        let (us, vs, mut shape) = self.uv(u, v)?;
        let s = &self.inner;
        let (p, q) = s.degrees();
        let d1 = order + 1;
        let flat = py.detach(|| {
            let mut out = vec![0.0; us.len() * d1 * d1 * 3];
            out.par_chunks_mut(d1 * d1 * 3)
                .zip(us.par_iter().zip(vs.par_iter()))
                .for_each_init(
                    || {
                        (
                            BasisWorkspace::new(p, order),
                            BasisWorkspace::new(q, order),
                            vec![Vector3::zeros(); d1 * d1],
                        )
                    },
                    |(wu, wv, d), (o, (&u, &v))| {
                        s.derivatives_into(u, v, wu, wv, order, d);
                        for (c, x) in o.chunks_mut(3).zip(d.iter()) {
                            c.copy_from_slice(&[x.x, x.y, x.z]);
                        }
                    },
                );
            out
        });
        shape.extend([d1, d1]);
        rows3(py, flat, &shape)
    }

    /// Unit normals ``S_u x S_v / |S_u x S_v|`` (zero where the surface is
    /// degenerate), shaped like ``evaluate``.
    fn normal<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (us, vs, shape) = self.uv(u, v)?;
        let s = &self.inner;
        let (p, q) = s.degrees();
        let flat = py.detach(|| {
            let mut out = vec![0.0; us.len() * 3];
            out.par_chunks_mut(3)
                .zip(us.par_iter().zip(vs.par_iter()))
                .for_each_init(
                    || (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1)),
                    |(wu, wv), (o, (&u, &v))| {
                        let n = s.normal(u, v, wu, wv);
                        o.copy_from_slice(&[n.x, n.y, n.z]);
                    },
                );
            out
        });
        rows3(py, flat, &shape)
    }

    /// Orthogonal projection of ``points`` (``(N, 3)``) onto the surface
    /// (KD-tree start on a sample grid, then Newton; NURBS Book section
    /// 6.1): returns ``(u, v, distance)``, three arrays of length ``N``.
    ///
    /// Example::
    ///
    ///     >>> u, v, d = surface.project(points)
    ///     >>> float(d.max())              # the largest orthogonal deviation
    fn project<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let pts = crate::convert::points(points, "points")?;
        let s = &self.inner;
        let inv = py
            .detach(|| {
                SurfaceInverter::new(s, InversionConfig::default()).map(|i| i.invert_all(&pts))
            })
            .map_err(err)?;
        Ok((
            vec1(py, inv.iter().map(|i| i.uv[0]).collect::<Vec<_>>()),
            vec1(py, inv.iter().map(|i| i.uv[1]).collect::<Vec<_>>()),
            vec1(py, inv.iter().map(|i| i.distance).collect::<Vec<_>>()),
        ))
    }

    /// The control net, shape ``(count_u, count_v, 3)`` (``P_ij`` at
    /// ``[i, j]``; a periodic direction lists its wrapped points too).
    #[getter]
    fn control_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (cu, cv) = self.inner.counts();
        let flat = self
            .inner
            .control_points()
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .collect();
        rows3(py, flat, &[cu, cv])
    }

    /// The weights, shape ``(count_u, count_v)``, or ``None`` (polynomial).
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let (cu, cv) = self.inner.counts();
        self.inner
            .weights()
            .map(|w| array(py, w.to_vec(), &[cu, cv]))
            .transpose()
    }

    /// The knot vectors ``(knots_u, knots_v)``.
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> (Bound<'py, PyAny>, Bound<'py, PyAny>) {
        (
            vec1(py, self.inner.knots_u().as_slice().to_vec()),
            vec1(py, self.inner.knots_v().as_slice().to_vec()),
        )
    }

    /// Degrees ``(p, q)``.
    #[getter]
    fn degree(&self) -> (usize, usize) {
        self.inner.degrees()
    }

    /// Control-net size ``(count_u, count_v)``.
    #[getter]
    fn counts(&self) -> (usize, usize) {
        self.inner.counts()
    }

    /// Periodic (closed) in ``(u, v)``.
    #[getter]
    fn periodic(&self) -> (bool, bool) {
        self.inner.periodic()
    }

    /// The parameter domain ``((u0, u1), (v0, v1))``.
    #[getter]
    fn domain(&self) -> ((f64, f64), (f64, f64)) {
        self.inner.domain()
    }

    /// The surface as a ``scanfit/1`` JSON document (the command line's
    /// ``-o`` format): the text, or written to ``path`` (atomically) when
    /// given.
    #[pyo3(signature = (path = None))]
    fn to_json(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        text_out(
            py,
            SurfaceDoc::new(&self.inner).to_json().map_err(io_err)?,
            path,
        )
    }

    /// A surface from ``scanfit/1`` JSON text (as ``to_json`` or the command
    /// line's ``-o`` write); ``Surface.read_json(path)`` reads a file.
    #[classmethod]
    fn from_json(_cls: &Bound<'_, PyType>, text: &str) -> PyResult<Self> {
        let (_, s) = parse_surface(std::path::Path::new("<json text>"), text).map_err(io_err)?;
        Ok(Self::new(s))
    }

    /// A surface from a ``scanfit/1`` JSON file.
    #[classmethod]
    fn read_json(_cls: &Bound<'_, PyType>, path: PathBuf) -> PyResult<Self> {
        let (_, s) = scanfit_io::json::read_surface(&path).map_err(io_err)?;
        Ok(Self::new(s))
    }

    /// The surface as a STEP file (AP214, ``B_SPLINE_SURFACE_WITH_KNOTS`` on
    /// an ``ADVANCED_FACE``): the text, or written to ``path``.
    #[pyo3(signature = (path = None))]
    fn to_step(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        cad_out(py, CadItem::Surface(&self.inner), path, false)
    }

    /// The surface as an IGES 5.3 file (entity 128): the text, or written to
    /// ``path``.
    #[pyo3(signature = (path = None))]
    fn to_iges(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        cad_out(py, CadItem::Surface(&self.inner), path, true)
    }

    /// A triangle mesh on a regular ``(nu + 1) x (nv + 1)`` parameter grid:
    /// a dict with ``vertices`` ``(V, 3)``, ``normals`` ``(V, 3)``, ``uv``
    /// ``(V, 2)`` and ``triangles`` ``(T, 3)`` (uint32, counter-clockwise in
    /// ``(u, v)``). ``samples`` defaults to 4 per control point, 32 to 400
    /// (as the command line's ``--mesh``).
    #[pyo3(signature = (samples = None))]
    fn mesh<'py>(
        &self,
        py: Python<'py>,
        samples: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let m = self.tessellation(py, samples)?;
        let d = pyo3::types::PyDict::new(py);
        d.set_item("vertices", crate::convert::points_array(py, &m.vertices)?)?;
        d.set_item("normals", crate::convert::vectors_array(py, &m.normals)?)?;
        let uv: Vec<f64> = m.uv.iter().flat_map(|t| [t[0], t[1]]).collect();
        d.set_item("uv", array(py, uv, &[m.uv.len(), 2])?)?;
        let tri: Vec<u32> = m.triangles.iter().flatten().copied().collect();
        d.set_item("triangles", array(py, tri, &[m.triangles.len(), 3])?)?;
        Ok(d)
    }

    /// Writes the mesh of ``mesh(samples)`` to ``path``: OBJ (``.obj``, with
    /// ``vt`` parameters and ``vn`` normals), binary PLY (``.ply``) or glTF
    /// binary (``.glb``), by extension.
    #[pyo3(signature = (path, samples = None))]
    fn to_mesh(
        &self,
        py: Python<'_>,
        path: PathBuf,
        samples: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let m = self.tessellation(py, samples)?;
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let name = product_name(&Some(path.clone()));
        let bytes = match ext.as_str() {
            "obj" => mesh_obj(&m, "scanfit surface"),
            "ply" => mesh_ply(&m, None, None, PlyFormat::Binary),
            "glb" => mesh_glb(&m, None, &name),
            _ => {
                return Err(value_err(format!(
                    "{}: unknown mesh format; use .obj, .ply or .glb",
                    path.display()
                )))
            }
        };
        py.detach(|| write_atomic(&path, &bytes)).map_err(io_err)
    }

    fn __repr__(&self) -> String {
        let s = &self.inner;
        let (p, q) = s.degrees();
        let (cu, cv) = s.counts();
        let ((u0, u1), (v0, v1)) = s.domain();
        let (pu, pv) = s.periodic();
        let lo = s.control_points().iter().fold(
            Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            |a, b| a.inf(b),
        );
        let hi = s.control_points().iter().fold(
            Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
            |a, b| a.sup(b),
        );
        format!(
            "Surface(degree=({p}, {q}), control_points=({cu}, {cv}), domain=[{}, {}] x [{}, {}]{}{}, \
             control net box=({}, {}, {})..({}, {}, {}))",
            g(u0, 4),
            g(u1, 4),
            g(v0, 4),
            g(v1, 4),
            match (pu, pv) {
                (false, false) => String::new(),
                _ => format!(", periodic=({}, {})", py_bool(pu), py_bool(pv)),
            },
            if s.weights().is_some() { ", rational" } else { "" },
            g(lo.x, 4),
            g(lo.y, 4),
            g(lo.z, 4),
            g(hi.x, 4),
            g(hi.y, 4),
            g(hi.z, 4)
        )
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }

    /// Pickling: the JSON document, which round-trips exactly.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let from = slf.get_type().getattr("from_json")?;
        Ok((
            from,
            (SurfaceDoc::new(&slf.get().inner)
                .to_json()
                .map_err(io_err)?,),
        ))
    }
}

impl PySurface {
    fn tessellation(
        &self,
        py: Python<'_>,
        samples: Option<Bound<'_, PyAny>>,
    ) -> PyResult<scanfit::bspline::Mesh> {
        let (cu, cv) = self.inner.counts();
        let (nu, nv) = match samples {
            Some(s) => pair(&s, "samples")?,
            None => ((cu * 4).clamp(32, 400), (cv * 4).clamp(32, 400)),
        };
        if nu == 0 || nv == 0 || nu.saturating_mul(nv) > 100_000_000 {
            return Err(value_err(format!(
                "samples = ({nu}, {nv}): give 1 to 10^8 grid cells in all"
            )));
        }
        let s = &self.inner;
        Ok(py.detach(|| tessellate(s, nu, nv)))
    }
}

/// "True" or "False".
fn py_bool(b: bool) -> &'static str {
    if b {
        "True"
    } else {
        "False"
    }
}

/// A B-spline (or NURBS) curve ``C(u)``.
///
/// Example::
///
///     >>> t = np.linspace(0, 1, 40)
///     >>> pts = np.column_stack([t, np.sin(3 * t), 0 * t])
///     >>> c = scanfit.fit_curve(pts)["curve"]      # interpolation
///     >>> c.evaluate([0.0, 1.0]).shape
///     (2, 3)
#[pyclass(name = "Curve", module = "scanfit", frozen)]
#[derive(Clone)]
pub struct PyCurve {
    /// The library's curve.
    pub inner: Curve,
}

impl PyCurve {
    /// Wraps a library curve.
    pub fn new(inner: Curve) -> Self {
        Self { inner }
    }

    fn us(&self, u: &Bound<'_, PyAny>) -> PyResult<(Vec<f64>, Vec<usize>)> {
        let (mut vals, shape) = parameters(&[(u, "u")])?;
        let us = vals.pop().unwrap_or_default();
        check_domain(&us, self.inner.domain(), self.inner.is_periodic(), "u")?;
        Ok((us, shape))
    }
}

#[pymethods]
impl PyCurve {
    /// Points ``C(u)``: ``u`` a number or an array; the result has its shape
    /// plus a last axis of 3.
    fn evaluate<'py>(&self, py: Python<'py>, u: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let (us, shape) = self.us(u)?;
        let c = &self.inner;
        let flat = py.detach(|| {
            let mut pts = vec![Point3::origin(); us.len()];
            c.eval_many(&us, &mut pts);
            pts.iter().flat_map(|p| [p.x, p.y, p.z]).collect()
        });
        rows3(py, flat, &shape)
    }

    /// Derivatives ``d^k C / du^k`` for ``k = 0..order``: shape
    /// ``u.shape + (order + 1, 3)`` (``[..., 0, :]`` is the point).
    #[pyo3(signature = (u, order = 1))]
    fn derivatives<'py>(
        &self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        order: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        if order > 7 {
            return Err(value_err(format!(
                "order = {order}: derivatives up to order 7 are supported"
            )));
        }
        let (us, mut shape) = self.us(u)?;
        let c = &self.inner;
        let p = c.degree();
        let flat = py.detach(|| {
            let mut out = vec![0.0; us.len() * (order + 1) * 3];
            out.par_chunks_mut((order + 1) * 3)
                .zip(us.par_iter())
                .for_each_init(
                    || {
                        (
                            BasisWorkspace::new(p, order),
                            vec![Vector3::zeros(); order + 1],
                        )
                    },
                    |(ws, d), (o, &u)| {
                        c.derivatives_into(u, ws, d);
                        for (c, x) in o.chunks_mut(3).zip(d.iter()) {
                            c.copy_from_slice(&[x.x, x.y, x.z]);
                        }
                    },
                );
            out
        });
        shape.push(order + 1);
        rows3(py, flat, &shape)
    }

    /// Closest points on the curve to ``points`` (``(N, 3)``): Newton on
    /// ``(C(u) - q) . C'(u) = 0`` (NURBS Book section 6.1) from the nearest
    /// of ``samples_per_span`` samples per knot span. Returns
    /// ``(u, distance)``, two arrays of length ``N``.
    #[pyo3(signature = (points, samples_per_span = 16))]
    fn project<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        samples_per_span: usize,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let pts = crate::convert::points(points, "points")?;
        if samples_per_span == 0 || samples_per_span > 10_000 {
            return Err(value_err(format!(
                "samples_per_span = {samples_per_span}: give 1 to 10000"
            )));
        }
        let c = &self.inner;
        let res = py.detach(|| closest_points(c, &pts, samples_per_span));
        Ok((
            vec1(py, res.iter().map(|r| r.0).collect::<Vec<_>>()),
            vec1(py, res.iter().map(|r| r.1).collect::<Vec<_>>()),
        ))
    }

    /// Control points, shape ``(n, 3)``.
    #[getter]
    fn control_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::convert::points_array(py, self.inner.control_points())
    }

    /// Weights (length ``n``) or ``None``.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        self.inner.weights().map(|w| vec1(py, w.to_vec()))
    }

    /// The knot vector.
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, self.inner.knots().as_slice().to_vec())
    }

    /// The degree.
    #[getter]
    fn degree(&self) -> usize {
        self.inner.degree()
    }

    /// Periodic (closed and smooth at the seam).
    #[getter]
    fn periodic(&self) -> bool {
        self.inner.is_periodic()
    }

    /// The parameter domain ``(u0, u1)``.
    #[getter]
    fn domain(&self) -> (f64, f64) {
        self.inner.domain()
    }

    /// Arc length (Gauss-free: polyline of ``samples_per_span`` samples per span).
    #[pyo3(signature = (samples_per_span = 64))]
    fn length(&self, samples_per_span: usize) -> f64 {
        self.inner.length(samples_per_span.max(1))
    }

    /// The curve as a ``scanfit/1`` JSON document: the text, or written to
    /// ``path``.
    #[pyo3(signature = (path = None))]
    fn to_json(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        text_out(
            py,
            CurveDoc::new(&self.inner).to_json().map_err(io_err)?,
            path,
        )
    }

    /// A curve from ``scanfit/1`` JSON text.
    #[classmethod]
    fn from_json(_cls: &Bound<'_, PyType>, text: &str) -> PyResult<Self> {
        let (_, c) = parse_curve(std::path::Path::new("<json text>"), text).map_err(io_err)?;
        Ok(Self::new(c))
    }

    /// A curve from a ``scanfit/1`` JSON file.
    #[classmethod]
    fn read_json(_cls: &Bound<'_, PyType>, path: PathBuf) -> PyResult<Self> {
        let (_, c) = scanfit_io::json::read_curve(&path).map_err(io_err)?;
        Ok(Self::new(c))
    }

    /// The curve as a STEP file (``B_SPLINE_CURVE_WITH_KNOTS``): the text,
    /// or written to ``path``.
    #[pyo3(signature = (path = None))]
    fn to_step(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        cad_out(py, CadItem::Curve(&self.inner), path, false)
    }

    /// The curve as an IGES file (entity 126): the text, or written to ``path``.
    #[pyo3(signature = (path = None))]
    fn to_iges(&self, py: Python<'_>, path: Option<PathBuf>) -> PyResult<Option<String>> {
        cad_out(py, CadItem::Curve(&self.inner), path, true)
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        let (u0, u1) = c.domain();
        format!(
            "Curve(degree={}, control_points={}, domain=[{}, {}]{}{}, length={})",
            c.degree(),
            c.control_points().len(),
            g(u0, 4),
            g(u1, 4),
            if c.is_periodic() { ", periodic" } else { "" },
            if c.is_rational() { ", rational" } else { "" },
            g(c.length(16), 6)
        )
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }

    /// Pickling: the JSON document.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let from = slf.get_type().getattr("from_json")?;
        Ok((
            from,
            (CurveDoc::new(&slf.get().inner).to_json().map_err(io_err)?,),
        ))
    }
}
