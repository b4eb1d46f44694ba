//! The rest of `fit_surface` over points in chunks (module `scanfit.sums`,
//! driven by `scanfit.dask.fit_surface`): the settings that need the whole
//! cloud in the single-process fit, each as passes of mergeable sums.
//!
//! * `PlanePasses`: the best-fit plane's parameters (`params="plane"`) in
//!   three passes: the covariance sums about the first point (PCA) with the
//!   seeded fold sample that chooses the projection direction (the best-fit
//!   plane, or a coordinate axis when the plane folds the points over and
//!   the axis does not; `scanfit::base::PlaneMoments`: the points of
//!   smallest index hash, merged across tasks, so the choice is the
//!   single-process fit's), the convex hull in the plane (its minimum-area
//!   rectangle), the extents along the rectangle's axes; then every point's
//!   `(u, v)` is computed where the point is, as `scanfit.fit_surface`
//!   computes it.
//! * `FitSetup` and `KnotSearch`: the net and smoothing of `fit_surface` for
//!   the point count, and the knots from the parameter distribution
//!   ([NURBS97] eq. 9.69, `knots="distribution"`) from the few order
//!   statistics they need, found exactly by rounds of histograms
//!   (`scanfit::fit::knot_ranks`).
//! * `Parameterization`: what a chunk's task needs to give its points their
//!   parameters: the plane map (or the given `uv`), then the surfaces of
//!   the accepted rounds of Hoschek's parameter correction (`correct`), onto
//!   which the points are re-projected in turn, exactly as the single-process
//!   correction re-projects them round after round.

use numpy::{IntoPyArray, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use scanfit::base::{FlatHull, PlaneAxes, PlaneExtents, PlaneMap, PlaneMoments, Projection};
use scanfit::bspline::{KnotVector, Surface};
use scanfit::fit::knot_ranks::{KnotSearch, RankCounts, RankQuery};
use scanfit::fit::surface::SurfaceFitConfig;
use scanfit::mba::ResidualSums;
use scanfit::metrics::parametric_distances;
use scanfit::pipeline::surface_fit::ParameterSource;
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit::wire::{Reader, Writer};
use scanfit::{Error, Point3, Vector3};

use crate::convert::{err, uv_columns, value_err, vec3};
use crate::sums::{
    chunk, pickled, read, wire_inner, PyCentring, PyNormalEquations, PyResidualSums, Wire,
};
use crate::surfaces::fit_config;

// ---- the best-fit plane in passes --------------------------------------------

/// What one pass of `PlanePasses` computes per chunk.
#[derive(Clone)]
enum Stage {
    /// Covariance sums about the reference point (centred) and the fold
    /// sample.
    Moments(Point3),
    /// The convex hull in the plane of these axes.
    Hull(PlaneAxes),
    /// The extents along the rectangle's axes.
    Extents(Box<PlaneExtents>),
}

const STAGE_TAG: &[u8; 8] = b"SFPYPLS1";

fn write_axes(w: &mut Writer, a: &PlaneAxes) {
    let mut v: Vec<f64> = a.origin.coords.iter().copied().collect();
    for x in [a.a1, a.a2, a.normal] {
        v.extend(x.iter());
    }
    w.f64s(&v);
}

fn read_axes(r: &mut Reader<'_>) -> scanfit::Result<PlaneAxes> {
    let v = r.f64s()?;
    if v.len() != 12 {
        return Err(r.corrupt("the plane's axes"));
    }
    let vec = |k: usize| Vector3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
    Ok(PlaneAxes {
        origin: Point3::from(vec(0)),
        a1: vec(1),
        a2: vec(2),
        normal: vec(3),
    })
}

/// What the workers need for one pass of the best-fit plane (broadcast):
/// the centring and the stage (covariance sums, hull or extents).
#[pyclass(name = "PlaneStage", module = "scanfit.sums", frozen)]
#[derive(Clone)]
pub struct PyPlaneStage {
    centring: PyCentring,
    stage: Stage,
}

impl PyPlaneStage {
    fn bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(STAGE_TAG);
        self.centring.write(&mut w);
        match &self.stage {
            Stage::Moments(p) => {
                w.u64(0);
                w.f64s(p.coords.as_slice());
            }
            Stage::Hull(a) => {
                w.u64(1);
                write_axes(&mut w, a);
            }
            Stage::Extents(e) => {
                // the extents' own record follows this one's header
                w.u64(2);
                let mut out = w.finish();
                out.extend_from_slice(&e.to_bytes());
                return out;
            }
        }
        w.finish()
    }
}

impl Wire for PyPlaneStage {
    const KIND: &'static str = "PlaneStage";

    fn encode(&self) -> Vec<u8> {
        self.bytes()
    }

    fn decode(data: &[u8]) -> PyResult<Self> {
        let mut r = Reader::new(data, STAGE_TAG, "a plane pass").map_err(err)?;
        let centring = PyCentring::read(&mut r).map_err(err)?;
        let stage = match r.u64().map_err(err)? {
            0 => {
                let v = r.f64s().map_err(err)?;
                if v.len() != 3 {
                    return Err(err(r.corrupt("the reference point")));
                }
                r.end().map_err(err)?;
                Stage::Moments(Point3::new(v[0], v[1], v[2]))
            }
            1 => {
                let a = read_axes(&mut r).map_err(err)?;
                r.end().map_err(err)?;
                Stage::Hull(a)
            }
            // tag, centring (6 values), kind: the extents' record follows
            2 => Stage::Extents(Box::new(
                PlaneExtents::from_bytes(&data[8 + 6 * 8 + 8..]).map_err(err)?,
            )),
            x => return Err(err(r.corrupt(&format!("plane stage {x}")))),
        };
        Ok(Self { centring, stage })
    }
}

pickled!(PyPlaneStage {
    /// Empty sums of this stage (what each task fills).
    fn accumulator(&self) -> PyPlaneSums {
        PyPlaneSums {
            inner: match &self.stage {
                Stage::Moments(p) => Sums::Moments(Box::new(PlaneMoments::new(*p))),
                Stage::Hull(_) => Sums::Hull(FlatHull::default()),
                Stage::Extents(e) => Sums::Extents(e.clone()),
            },
        }
    }

    fn __repr__(&self) -> String {
        let s = match self.stage {
            Stage::Moments(_) => "covariance and fold sample",
            Stage::Hull(_) => "hull",
            Stage::Extents(_) => "extents",
        };
        format!("PlaneStage({s})")
    }
});

#[derive(Clone)]
enum Sums {
    Moments(Box<PlaneMoments>),
    Hull(FlatHull),
    Extents(Box<PlaneExtents>),
}

// version 2: the first pass's sums carry the fold sample (PlaneMoments)
const PLANE_SUMS_TAG: &[u8; 8] = b"SFPYPLA2";

/// The sums of one plane pass over some chunks (covariance sums with the
/// fold sample, a convex hull, or extents); mergeable and exact as bytes.
#[pyclass(name = "PlaneSums", module = "scanfit.sums")]
#[derive(Clone)]
pub struct PyPlaneSums {
    inner: Sums,
}

impl PyPlaneSums {
    fn bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(PLANE_SUMS_TAG);
        let (kind, bytes) = match &self.inner {
            Sums::Moments(c) => (0, c.to_bytes()),
            Sums::Hull(h) => (1, h.to_bytes()),
            Sums::Extents(e) => (2, e.to_bytes()),
        };
        w.u64(kind);
        let mut out = w.finish();
        out.extend_from_slice(&bytes);
        out
    }
}

impl Wire for PyPlaneSums {
    const KIND: &'static str = "PlaneSums";

    fn encode(&self) -> Vec<u8> {
        self.bytes()
    }

    fn decode(data: &[u8]) -> PyResult<Self> {
        let mut r = Reader::new(data, PLANE_SUMS_TAG, "plane sums").map_err(err)?;
        let kind = r.u64().map_err(err)?;
        // tag, kind: the stage's own record follows
        let rest = &data[16..];
        let inner = match kind {
            0 => Sums::Moments(Box::new(PlaneMoments::from_bytes(rest).map_err(err)?)),
            1 => Sums::Hull(FlatHull::from_bytes(rest).map_err(err)?),
            2 => Sums::Extents(Box::new(PlaneExtents::from_bytes(rest).map_err(err)?)),
            x => return Err(err(r.corrupt(&format!("plane sums kind {x}")))),
        };
        Ok(Self { inner })
    }
}

pickled!(PyPlaneSums {
    /// Adds an ``(N, 3)`` chunk (``N = 0`` allowed) for ``stage``.
    /// ``offset`` is the global row of the chunk's first point (its index in
    /// the whole data, in the order of a single-process call: the rows of
    /// the chunks and tiles before it); the first stage needs it, for the
    /// seeded sample that chooses the projection direction.
    #[pyo3(signature = (stage, points, offset = None))]
    fn add(
        &mut self,
        py: Python<'_>,
        stage: &PyPlaneStage,
        points: &Bound<'_, PyAny>,
        offset: Option<u64>,
    ) -> PyResult<()> {
        let p = stage.centring.apply(chunk(points)?);
        py.detach(|| match (&mut self.inner, &stage.stage) {
            (Sums::Moments(c), Stage::Moments(_)) => {
                let first = offset.ok_or_else(|| {
                    value_err("the first plane pass samples points by their global row: give offset=, the row of this chunk's first point in the whole data".into())
                })?;
                c.add(first, &p);
                Ok(())
            }
            (Sums::Hull(h), Stage::Hull(a)) => {
                h.add(a, &p);
                Ok(())
            }
            (Sums::Extents(e), Stage::Extents(_)) => {
                e.add(&p);
                Ok(())
            }
            _ => Err(value_err(
                "these plane sums belong to another stage; use stage.accumulator()".into(),
            )),
        })
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Adds the sums of other chunks (the same stage).
    fn merge(&mut self, other: &PyPlaneSums) -> PyResult<()> {
        match (&mut self.inner, &other.inner) {
            (Sums::Moments(a), Sums::Moments(b)) => a.merge(b).map_err(err),
            (Sums::Hull(a), Sums::Hull(b)) => {
                a.merge(b);
                Ok(())
            }
            (Sums::Extents(a), Sums::Extents(b)) => a.merge(b).map_err(err),
            _ => Err(value_err(
                "cannot merge plane sums of different stages".into(),
            )),
        }
    }

    fn __repr__(&self) -> String {
        match &self.inner {
            Sums::Moments(c) => format!("PlaneSums(covariance and fold sample, points={})", c.count()),
            Sums::Hull(h) => format!("PlaneSums(hull, vertices={})", h.vertices().len()),
            Sums::Extents(_) => "PlaneSums(extents)".into(),
        }
    }
});

/// The best-fit plane's parameters over points in chunks (``params="plane"``
/// of ``fit_surface``), on the client: three passes, each ``stage()``
/// broadcast, every chunk's ``PlaneSums`` merged and ``push``-ed; then
/// ``parameterization()``. ``first`` is the first point of the data (the
/// covariance is summed about it, as the single-process fit sums it),
/// ``count`` the number of points. The first pass also chooses the
/// projection direction (``projection``) from the seeded sample, as the
/// single-process fit does.
///
/// Example::
///
///     >>> plane = scanfit.sums.PlanePasses(centring, pts[0], len(pts))
///     >>> while not plane.done:
///     ...     stage = plane.stage(); s = stage.accumulator(); s.add(stage, pts, offset=0); plane.push(s)
///     >>> uv = plane.parameterization().uv(pts)
///     >>> plane.projection["axis"]  # doctest: +SKIP
///     'best-fit plane'
#[pyclass(name = "PlanePasses", module = "scanfit.sums")]
pub struct PyPlanePasses {
    centring: PyCentring,
    stage: Stage,
    map: Option<PlaneMap>,
    projection: Option<Projection>,
}

#[pymethods]
impl PyPlanePasses {
    /// The passes for ``count`` points whose first is ``first`` (data units).
    #[new]
    fn new(centring: &PyCentring, first: &Bound<'_, PyAny>, count: usize) -> PyResult<Self> {
        if count < 3 {
            return Err(err(Error::TooFewPoints {
                got: count,
                needed: 3,
                what: "a best-fit plane".into(),
            }));
        }
        let f = centring.apply(vec![Point3::from(vec3(first, "first")?)]);
        Ok(Self {
            centring: centring.clone(),
            stage: Stage::Moments(f[0]),
            map: None,
            projection: None,
        })
    }

    /// Whether the plane is known.
    #[getter]
    fn done(&self) -> bool {
        self.map.is_some()
    }

    /// The projection direction chosen by the first pass (``None`` before
    /// it): ``axis``, ``direction``, ``fold_shares``, ``sampled``, ``extent``
    /// (0 until the last pass), as ``scanfit.fit_surface``'s.
    #[getter]
    fn projection<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.projection
            .as_ref()
            .map(|p| crate::report::projection(py, p))
            .transpose()
    }

    /// What the workers need for the next pass.
    fn stage(&self) -> PyResult<PyPlaneStage> {
        if self.map.is_some() {
            return Err(value_err(
                "the plane is known; call parameterization()".into(),
            ));
        }
        Ok(PyPlaneStage {
            centring: self.centring.clone(),
            stage: self.stage.clone(),
        })
    }

    /// Finishes the pass from the merged sums of all chunks.
    fn push(&mut self, sums: &PyPlaneSums) -> PyResult<()> {
        match (&self.stage, &sums.inner) {
            (Stage::Moments(_), Sums::Moments(m)) => {
                if m.count() == 0.0 {
                    return Err(value_err("the covariance sums hold no point".into()));
                }
                let (axes, projection) = m.finish().map_err(err)?;
                self.projection = Some(projection);
                self.stage = Stage::Hull(axes);
            }
            (Stage::Hull(a), Sums::Hull(h)) => {
                self.stage =
                    Stage::Extents(Box::new(PlaneExtents::new(a, h.rectangle_direction())));
            }
            (Stage::Extents(_), Sums::Extents(e)) => {
                let map = e.finish().map_err(err)?;
                if let Some(p) = self.projection.as_mut() {
                    p.extent = map.extent();
                }
                self.map = Some(map);
            }
            _ => {
                return Err(value_err(
                    "these plane sums belong to another pass; sum the current stage()".into(),
                ))
            }
        }
        Ok(())
    }

    /// The parameterization of the points on the plane, once ``done``.
    fn parameterization(&self) -> PyResult<PyParameterization> {
        let map = self
            .map
            .ok_or_else(|| value_err("the plane is not known yet: push its passes".into()))?;
        Ok(PyParameterization {
            centring: self.centring.clone(),
            plane: Some(map),
            chain: Vec::new(),
            surface: None,
        })
    }
}

// ---- the points' parameters on the workers ------------------------------------

/// How a chunk's points get their parameters ``(u, v)`` (broadcast): from the
/// best-fit plane (``PlanePasses``) or given per point, then re-projected onto
/// the surfaces of the accepted correction rounds in turn (Hoschek's
/// parameter correction, as ``fit_surface(correct=k)``); optionally with the
/// surface fitted to those parameters, to measure its errors.
///
/// Example::
///
///     >>> p = scanfit.sums.Parameterization.given(centring)
///     >>> uv = p.uv(pts, uv0)                 # the given parameters
///     >>> q = p.fitted(equations).corrected()  # one correction round
///     >>> q.uv(pts, uv0)                       # re-projected onto the fit
#[pyclass(name = "Parameterization", module = "scanfit.sums", frozen)]
#[derive(Clone)]
pub struct PyParameterization {
    centring: PyCentring,
    plane: Option<PlaneMap>,
    /// Surfaces (centred) the points are re-projected onto, in order.
    chain: Vec<Surface>,
    /// The surface (centred) fitted to these parameters.
    surface: Option<Surface>,
}

const PARAM_TAG: &[u8; 8] = b"SFPYPAR1";

fn write_surface(w: &mut Writer, s: &Surface) {
    let (p, q) = s.degrees();
    w.usize(p);
    w.usize(q);
    w.f64s(s.knots_u().as_slice());
    w.f64s(s.knots_v().as_slice());
    let flat: Vec<f64> = s
        .control_points()
        .iter()
        .flat_map(|c| [c.x, c.y, c.z])
        .collect();
    w.f64s(&flat);
    let (pu, pv) = s.periodic();
    w.u64(u64::from(pu) | (u64::from(pv) << 1));
}

fn read_surface(r: &mut Reader<'_>) -> scanfit::Result<Surface> {
    let (p, q) = (r.usize()?, r.usize()?);
    let (ku, kv) = (r.f64s()?, r.f64s()?);
    let flat = r.f64s()?;
    let periodic = r.u64()?;
    if flat.len() % 3 != 0 {
        return Err(r.corrupt("the control points"));
    }
    let ctrl = flat
        .chunks_exact(3)
        .map(|c| Point3::new(c[0], c[1], c[2]))
        .collect();
    Surface::with_options(
        KnotVector::new(ku, p)?,
        KnotVector::new(kv, q)?,
        ctrl,
        None,
        periodic & 1 == 1,
        periodic & 2 == 2,
    )
}

impl PyParameterization {
    fn bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(PARAM_TAG);
        self.centring.write(&mut w);
        match &self.plane {
            Some(m) => {
                w.u64(1);
                m.write(&mut w);
            }
            None => w.u64(0),
        }
        w.usize(self.chain.len());
        for s in &self.chain {
            write_surface(&mut w, s);
        }
        match &self.surface {
            Some(s) => {
                w.u64(1);
                write_surface(&mut w, s);
            }
            None => w.u64(0),
        }
        w.finish()
    }

    /// The centred points of a chunk and their parameters.
    fn chunk_uv(
        &self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        uv: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<(Vec<Point3>, Vec<[f64; 2]>)> {
        let p = self.centring.apply(chunk(points)?);
        let start: Vec<[f64; 2]> = match (&self.plane, uv) {
            (Some(m), _) => p.iter().map(|q| m.uv(q)).collect(),
            (None, Some(uv)) => {
                if p.is_empty() {
                    Vec::new()
                } else {
                    let (u, v) = uv_columns(uv, p.len())?;
                    u.into_iter().zip(v).map(|(u, v)| [u, v]).collect()
                }
            }
            (None, None) => {
                return Err(value_err(
                    "these parameters are given per point: pass uv, an (N, 2) array".into(),
                ))
            }
        };
        let uv = py.detach(|| -> scanfit::Result<Vec<[f64; 2]>> {
            let mut uv = start;
            for s in &self.chain {
                let inv = SurfaceInverter::new(s, InversionConfig::default())?;
                uv = inv.invert_all_from(&p, &uv).iter().map(|r| r.uv).collect();
            }
            Ok(uv)
        });
        Ok((p, uv.map_err(err)?))
    }
}

impl Wire for PyParameterization {
    const KIND: &'static str = "Parameterization";

    fn encode(&self) -> Vec<u8> {
        self.bytes()
    }

    fn decode(data: &[u8]) -> PyResult<Self> {
        read(data, PARAM_TAG, "a parameterization", |r| {
            let centring = PyCentring::read(r)?;
            let plane = match r.u64()? {
                0 => None,
                1 => Some(PlaneMap::read(r)?),
                x => return Err(r.corrupt(&format!("plane flag {x}"))),
            };
            let n = r.usize()?;
            let mut chain = Vec::new();
            for _ in 0..n {
                chain.push(read_surface(r)?);
            }
            let surface = match r.u64()? {
                0 => None,
                1 => Some(read_surface(r)?),
                x => return Err(r.corrupt(&format!("surface flag {x}"))),
            };
            Ok(Self {
                centring,
                plane,
                chain,
                surface,
            })
        })
    }
}

pickled!(PyParameterization {
    /// Parameters given per point (``uv=`` of ``fit_surface``).
    #[staticmethod]
    fn given(centring: &PyCentring) -> Self {
        Self {
            centring: centring.clone(),
            plane: None,
            chain: Vec::new(),
            surface: None,
        }
    }

    /// The ``(N, 2)`` parameters of an ``(N, 3)`` chunk (``uv``: the given
    /// parameters, when not from the plane).
    #[pyo3(signature = (points, uv = None))]
    fn uv<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        uv: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (_, t) = self.chunk_uv(py, points, uv.as_ref())?;
        let n = t.len();
        let flat: Vec<f64> = t.into_iter().flatten().collect();
        flat.into_pyarray(py)
            .reshape([n, 2])
            .map_err(|e| value_err(e.to_string()))
    }

    /// The same parameters with ``equations`` solved: the surface whose
    /// errors ``errors`` measures (``equations.finish()`` is the same
    /// surface in data coordinates).
    fn fitted(&self, py: Python<'_>, equations: &PyNormalEquations) -> PyResult<Self> {
        let eq = equations.inner.clone();
        let s = py.detach(|| eq.finish(equations.smoothing)).map_err(err)?;
        Ok(Self {
            surface: Some(s),
            ..self.clone()
        })
    }

    /// One correction round on: the points re-projected onto the fitted
    /// surface, starting from these parameters.
    fn corrected(&self) -> PyResult<Self> {
        let s = self
            .surface
            .clone()
            .ok_or_else(|| value_err("no fitted surface: call fitted(equations) first".into()))?;
        let mut chain = self.chain.clone();
        chain.push(s);
        Ok(Self {
            chain,
            surface: None,
            ..self.clone()
        })
    }

    /// The errors ``|p - S(u, v)|`` of a chunk at its parameters on the
    /// fitted surface (mergeable statistics; the round's RMSE).
    #[pyo3(signature = (points, uv = None))]
    fn errors(
        &self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        uv: Option<Bound<'_, PyAny>>,
    ) -> PyResult<PyResidualSums> {
        let s = self
            .surface
            .as_ref()
            .ok_or_else(|| value_err("no fitted surface: call fitted(equations) first".into()))?;
        let (p, t) = self.chunk_uv(py, points, uv.as_ref())?;
        let mut inner = ResidualSums::default();
        let d = py.detach(|| parametric_distances(s, &p, &t));
        d.iter().for_each(|&x| inner.push(x));
        Ok(PyResidualSums { inner })
    }

    /// Correction rounds the parameters went through.
    #[getter]
    fn rounds(&self) -> usize {
        self.chain.len()
    }

    /// Whether the parameters come from the best-fit plane.
    #[getter]
    fn plane(&self) -> bool {
        self.plane.is_some()
    }

    fn __repr__(&self) -> String {
        format!(
            "Parameterization({}, rounds={}, fitted={})",
            if self.plane.is_some() {
                "plane"
            } else {
                "given"
            },
            self.chain.len(),
            self.surface.is_some()
        )
    }
});

// ---- the fit's settings and its knots ------------------------------------------

/// ``fit_surface``'s keywords resolved for ``count`` points (the net from the
/// density, the smoothing scaled to the data, as the single-process fit
/// resolves them), on the client: ``knot_search()`` for the distribution
/// knots, ``equations()`` for the empty normal equations.
///
/// Example::
///
///     >>> setup = scanfit.sums.FitSetup(len(pts), centring, ctrl=(12, 12))
///     >>> search = setup.knot_search()        # knots="distribution"
///     >>> while not search.done:
///     ...     q = search.query(); c = q.counts(); c.add(q, uv); search.push(c)
///     >>> eq = setup.equations(search)
#[pyclass(name = "FitSetup", module = "scanfit.sums", frozen)]
pub struct PyFitSetup {
    fit: SurfaceFitConfig,
    count: usize,
    centring: PyCentring,
    plane: bool,
    correct: usize,
    min_improvement: f64,
}

#[pymethods]
impl PyFitSetup {
    /// The settings (see the class documentation).
    #[new]
    #[pyo3(signature = (count, centring, ctrl = None, degree = None, params = "plane", knots = "distribution", smooth = None, periodic_u = false, correct = 0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        count: usize,
        centring: &PyCentring,
        ctrl: Option<Bound<'_, PyAny>>,
        degree: Option<Bound<'_, PyAny>>,
        params: &str,
        knots: &str,
        smooth: Option<f64>,
        periodic_u: bool,
        correct: usize,
    ) -> PyResult<Self> {
        let cfg = fit_config(
            ctrl.as_ref(),
            degree.as_ref(),
            params,
            knots,
            smooth,
            periodic_u,
            correct,
        )?;
        let plane = cfg.params == ParameterSource::Plane;
        if plane && periodic_u {
            return Err(err(Error::InvalidSetting {
                setting: "periodic_u",
                value: "true".into(),
                hint: "a periodic surface needs parameters that go around (given uv); a plane cannot close".into(),
            }));
        }
        Ok(Self {
            fit: cfg.resolved_fit(count),
            count,
            centring: centring.clone(),
            plane,
            correct: cfg.correction_rounds,
            min_improvement: cfg.correction.min_improvement,
        })
    }

    /// Whether the parameters come from the best-fit plane.
    #[getter]
    fn plane(&self) -> bool {
        self.plane
    }

    /// Most rounds of parameter correction.
    #[getter]
    fn correct(&self) -> usize {
        self.correct
    }

    /// The correction stops when a round improves the RMSE by less than
    /// this fraction.
    #[getter]
    fn min_improvement(&self) -> f64 {
        self.min_improvement
    }

    /// The control net ``(nu, nv)``.
    #[getter]
    fn ctrl(&self) -> (usize, usize) {
        self.fit.ctrl
    }

    /// The thin-plate weight.
    #[getter]
    fn smoothing(&self) -> f64 {
        self.fit.smoothing
    }

    /// The search for the distribution knots (``None`` for uniform knots).
    fn knot_search(&self) -> PyResult<Option<PyKnotSearch>> {
        use scanfit::fit::surface::KnotPlacement;
        if self.fit.knots == KnotPlacement::Uniform {
            return Ok(None);
        }
        Ok(Some(PyKnotSearch {
            inner: KnotSearch::new(self.count, &self.fit).map_err(err)?,
        }))
    }

    /// Empty normal equations: uniform knots, or those of a finished
    /// ``search``.
    #[pyo3(signature = (search = None))]
    fn equations(&self, search: Option<&PyKnotSearch>) -> PyResult<PyNormalEquations> {
        let inner = match search {
            Some(s) => s.inner.equations(&self.fit),
            None => self.fit.uniform_equations(),
        }
        .map_err(err)?;
        Ok(PyNormalEquations {
            inner,
            smoothing: self.fit.smoothing,
            centring: self.centring.clone(),
        })
    }
}

/// The knots from the parameter distribution (NURBS Book eq. 9.69) on the
/// client: rounds of ``query()`` (broadcast), ``RankCounts`` of every chunk
/// merged and ``push``-ed, until ``done``. Made by ``FitSetup.knot_search()``.
#[pyclass(name = "KnotSearch", module = "scanfit.sums")]
pub struct PyKnotSearch {
    inner: KnotSearch,
}

#[pymethods]
impl PyKnotSearch {
    /// Whether the knots are known.
    #[getter]
    fn done(&self) -> bool {
        self.inner.done()
    }

    /// Rounds over the points so far.
    #[getter]
    fn rounds(&self) -> usize {
        self.inner.rounds()
    }

    /// What every chunk counts next.
    fn query(&self) -> PyRankQuery {
        PyRankQuery {
            inner: self.inner.query(),
        }
    }

    /// Takes the merged counts of all chunks for the current query.
    fn push(&mut self, counts: &PyRankCounts) -> PyResult<()> {
        self.inner.push(&counts.inner).map_err(err)
    }
}

/// One round of a ``KnotSearch`` (broadcast): windows of parameter values
/// per direction, to be counted in bins or collected.
#[pyclass(name = "RankQuery", module = "scanfit.sums", frozen)]
pub struct PyRankQuery {
    inner: RankQuery,
}

wire_inner!(PyRankQuery, RankQuery, "RankQuery");

pickled!(PyRankQuery {
    /// Empty counts for this query (what each task fills).
    fn counts(&self) -> PyRankCounts {
        PyRankCounts {
            inner: self.inner.counts(),
        }
    }
});

/// The counts of some chunks' parameters for a ``RankQuery``; mergeable and
/// exact as bytes.
#[pyclass(name = "RankCounts", module = "scanfit.sums")]
#[derive(Clone)]
pub struct PyRankCounts {
    inner: RankCounts,
}

wire_inner!(PyRankCounts, RankCounts, "RankCounts");

pickled!(PyRankCounts {
    /// Counts an ``(N, 2)`` array of parameters (``N = 0`` allowed).
    fn add(&mut self, query: &PyRankQuery, uv: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = uv.len()?;
        if n == 0 {
            return Ok(());
        }
        let (u, v) = uv_columns(uv, n)?;
        let t: Vec<[f64; 2]> = u.into_iter().zip(v).map(|(u, v)| [u, v]).collect();
        KnotSearch::add(&query.inner, &mut self.inner, &t);
        Ok(())
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Adds the counts of other chunks (the same query).
    fn merge(&mut self, other: &PyRankCounts) -> PyResult<()> {
        self.inner.merge(&other.inner).map_err(err)
    }

    /// Bytes of the counts.
    #[getter]
    fn nbytes(&self) -> usize {
        self.inner.bytes()
    }
});

/// Adds the classes of this module to the native module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPlaneStage>()?;
    m.add_class::<PyPlaneSums>()?;
    m.add_class::<PyPlanePasses>()?;
    m.add_class::<PyParameterization>()?;
    m.add_class::<PyFitSetup>()?;
    m.add_class::<PyKnotSearch>()?;
    m.add_class::<PyRankQuery>()?;
    m.add_class::<PyRankCounts>()?;
    Ok(())
}
