//! `scanfit.Cloud`, `read_cloud`/`write_cloud` (through scanfit-io) and the
//! point-cloud tools of `scanfit cloud` (over `scanfit::pipeline::cloud`).

use std::path::PathBuf;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use scanfit::cloud::corners::CornerCriterion;
use scanfit::cloud::normals::Orientation;
use scanfit::pipeline::cloud::{
    boundary as run_boundary, hpr as run_hpr, info as run_info, normals as run_normals,
    CloudBoundaryConfig, CloudHprConfig, CloudInfoConfig, CloudNormalsConfig,
};
use scanfit::progress::NoProgress;
use scanfit::{Point3, PointCloud};
use scanfit_io::{Format, NonFinite, ReadOptions, WriteFormat};

use crate::convert::{
    bad_choice, err, g, io_err, points, points_array, value_err, values, vec1, vec3,
};

/// A point cloud: positions and named per-point attributes (normals
/// ``nx, ny, nz``, colours, labels, ``u, v``, ...).
///
/// Made by ``read_cloud(path)`` or ``Cloud(positions, attributes)``; every
/// pipeline takes a ``Cloud`` or a plain ``(N, 3)`` array.
///
/// Example::
///
///     >>> cloud = scanfit.read_cloud("examples/data/patch_20k.ply")
///     >>> cloud.positions.shape
///     (20000, 3)
///     >>> sorted(cloud.attributes)  # doctest: +SKIP
///     ['nx', 'ny', 'nz']
#[pyclass(name = "Cloud", module = "scanfit", frozen)]
pub struct PyCloud {
    /// The library's cloud.
    pub inner: PointCloud,
    /// The file it was read from.
    path: Option<String>,
    /// The reader's warnings.
    warnings: Vec<String>,
    /// Points dropped for a non-finite coordinate.
    dropped: usize,
}

impl PyCloud {
    /// Wraps a library cloud.
    pub fn new(inner: PointCloud) -> Self {
        Self {
            inner,
            path: None,
            warnings: Vec::new(),
            dropped: 0,
        }
    }
}

/// A cloud given to a pipeline: borrowed from a `Cloud` or built from an array.
pub enum CloudArg<'a> {
    /// A `scanfit.Cloud`.
    Borrowed(&'a PointCloud),
    /// Built from an `(N, 3)` array.
    Owned(PointCloud),
}

impl CloudArg<'_> {
    /// The cloud.
    pub fn get(&self) -> &PointCloud {
        match self {
            CloudArg::Borrowed(c) => c,
            CloudArg::Owned(c) => c,
        }
    }
}

/// `obj` as a cloud: a `Cloud` is borrowed, an array is copied once into
/// the library's point type.
pub fn cloud_arg<'a>(obj: &'a Bound<'_, PyAny>, what: &str) -> PyResult<CloudArg<'a>> {
    if let Ok(c) = obj.cast::<PyCloud>() {
        return Ok(CloudArg::Borrowed(&c.get().inner));
    }
    let pts = points(obj, what)?;
    Ok(CloudArg::Owned(PointCloud::new(pts).map_err(err)?))
}

#[pymethods]
impl PyCloud {
    /// A cloud from ``positions`` (``(N, 3)``) and ``attributes`` (a dict of
    /// name -> array of ``N`` numbers).
    #[new]
    #[pyo3(signature = (positions, attributes = None))]
    fn py_new(
        positions: &Bound<'_, PyAny>,
        attributes: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let pts = points(positions, "positions")?;
        let n = pts.len();
        let mut c = PointCloud::new(pts).map_err(err)?;
        if let Some(a) = attributes {
            for (k, v) in a.iter() {
                let name: String = k
                    .extract()
                    .map_err(|_| PyTypeError::new_err("attribute names must be strings"))?;
                let vals = values(&v, &format!("attribute {name:?}"), Some(n))?;
                c.set_attribute(&name, vals).map_err(err)?;
            }
        }
        Ok(Self::new(c))
    }

    /// The positions, an ``(N, 3)`` float64 array (a new array on each access).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        points_array(py, self.inner.points())
    }

    /// The attributes, a dict of name -> float64 array of length ``N``.
    #[getter]
    fn attributes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for a in self.inner.attributes() {
            d.set_item(&a.name, vec1(py, a.values.clone()))?;
        }
        Ok(d)
    }

    /// A copy of this cloud with the attribute ``name`` set to ``values``.
    fn with_attribute(&self, name: &str, values: &Bound<'_, PyAny>) -> PyResult<Self> {
        let vals = crate::convert::values(
            values,
            &format!("attribute {name:?}"),
            Some(self.inner.len()),
        )?;
        let c = self.inner.clone().with_attribute(name, vals).map_err(err)?;
        Ok(Self {
            inner: c,
            path: self.path.clone(),
            warnings: self.warnings.clone(),
            dropped: self.dropped,
        })
    }

    /// The file this cloud was read from, or ``None``.
    #[getter]
    fn path(&self) -> Option<String> {
        self.path.clone()
    }

    /// What the reader accepted but you should hear about (a header count
    /// that disagrees with the data, ...), one sentence each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// Points left out for a non-finite coordinate (``drop_non_finite=True``).
    #[getter]
    fn dropped_non_finite(&self) -> usize {
        self.dropped
    }

    /// Axis-aligned bounding box ``(min, max)``, two arrays of 3.
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (lo, hi) = self
            .inner
            .bounding_box()
            .unwrap_or((Point3::origin(), Point3::origin()));
        points_array(py, &[lo, hi])
    }

    /// ``scanfit cloud info``: count, bounding box, each attribute's range
    /// and (``spacing=True``) the nearest-neighbour spacing statistics, as a dict.
    #[pyo3(signature = (spacing = true))]
    fn info<'py>(&self, py: Python<'py>, spacing: bool) -> PyResult<Bound<'py, PyDict>> {
        let mut cfg = CloudInfoConfig::default();
        cfg.spacing = spacing;
        let c = &self.inner;
        let r = py.detach(|| run_info(c, &cfg, &NoProgress)).map_err(err)?;
        let d = PyDict::new(py);
        d.set_item("points", r.points)?;
        d.set_item("bbox_min", [r.bbox_min.x, r.bbox_min.y, r.bbox_min.z])?;
        d.set_item("bbox_max", [r.bbox_max.x, r.bbox_max.y, r.bbox_max.z])?;
        d.set_item("diagonal", r.diagonal)?;
        let attrs = PyList::empty(py);
        for a in &r.attributes {
            let e = PyDict::new(py);
            e.set_item("name", &a.name)?;
            e.set_item("min", a.min)?;
            e.set_item("max", a.max)?;
            attrs.append(e)?;
        }
        d.set_item("attributes", attrs)?;
        match r.spacing {
            Some(s) => {
                let e = PyDict::new(py);
                e.set_item("min", s.min)?;
                e.set_item("median", s.median)?;
                e.set_item("mean", s.mean)?;
                e.set_item("max", s.max)?;
                e.set_item("duplicates", s.duplicates)?;
                d.set_item("spacing", e)?;
            }
            None => d.set_item("spacing", py.None())?,
        }
        Ok(d)
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        let names: Vec<&str> = self
            .inner
            .attributes()
            .iter()
            .map(|a| a.name.as_str())
            .collect();
        let (lo, hi) = self
            .inner
            .bounding_box()
            .unwrap_or((Point3::origin(), Point3::origin()));
        format!(
            "Cloud({} points{}, attributes=[{}], box=({}, {}, {})..({}, {}, {}))",
            self.inner.len(),
            self.path
                .as_ref()
                .map(|p| format!(" from {p:?}"))
                .unwrap_or_default(),
            names.join(", "),
            g(lo.x, 6),
            g(lo.y, 6),
            g(lo.z, 6),
            g(hi.x, 6),
            g(hi.y, 6),
            g(hi.z, 6)
        )
    }
}

/// Reads a point file into a ``Cloud``: PLY, PCD, LAS/LAZ or text (XYZ,
/// CSV, TXT, PTS, ASC), chosen by ``format`` (``"ply"``, ``"pcd"``,
/// ``"las"``, ``"text"``), else by the extension, else by the first bytes.
/// A non-finite coordinate raises ``ScanfitError`` naming the file and line
/// (or byte offset), unless ``drop_non_finite=True`` leaves such points out
/// (``cloud.dropped_non_finite`` counts them). Every other column or
/// property becomes an attribute.
///
/// Example::
///
///     >>> cloud = scanfit.read_cloud("examples/data/terrain_50k.xyz")
///     >>> len(cloud)
///     50000
#[pyfunction]
#[pyo3(signature = (path, format = None, drop_non_finite = false))]
pub fn read_cloud(
    py: Python<'_>,
    path: PathBuf,
    format: Option<&str>,
    drop_non_finite: bool,
) -> PyResult<PyCloud> {
    let format = match format {
        None => None,
        Some("ply") => Some(Format::Ply),
        Some("pcd") => Some(Format::Pcd),
        Some("las") | Some("laz") => Some(Format::Las),
        Some("text") | Some("xyz") | Some("csv") => Some(Format::Text),
        Some(f) => return Err(bad_choice("format", f, &["ply", "pcd", "las", "text"])),
    };
    let options = ReadOptions {
        format,
        non_finite: if drop_non_finite {
            NonFinite::Drop
        } else {
            NonFinite::Reject
        },
    };
    let table = py
        .detach(|| scanfit_io::read_cloud(&path, &options))
        .map_err(io_err)?;
    let warnings = table.warnings.clone();
    let dropped = table.dropped_non_finite;
    let shown = path.display().to_string();
    let cloud = py
        .detach(|| table.into_cloud())
        .map_err(|e| value_err(format!("{shown}: {e}")))?;
    Ok(PyCloud {
        inner: cloud,
        path: Some(shown),
        warnings,
        dropped,
    })
}

/// Writes a cloud (a ``Cloud``, or an ``(N, 3)`` array with ``attributes``)
/// to ``path``: binary PLY (``.ply``, doubles) or text with a header line
/// (``.xyz``, ``.txt``, ``.csv``, ``.pts``, ``.asc``), every attribute a
/// column; ``ascii=True`` writes ascii PLY. The write is atomic.
#[pyfunction]
#[pyo3(signature = (path, cloud, attributes = None, ascii = false))]
pub fn write_cloud(
    py: Python<'_>,
    path: PathBuf,
    cloud: &Bound<'_, PyAny>,
    attributes: Option<&Bound<'_, PyDict>>,
    ascii: bool,
) -> PyResult<()> {
    let owned;
    let c: &PointCloud = match cloud.cast::<PyCloud>() {
        Ok(c) => {
            if attributes.is_some() {
                return Err(value_err(
                    "attributes are given with an array; a Cloud carries its own (use cloud.with_attribute)".into(),
                ));
            }
            &c.get().inner
        }
        Err(_) => {
            owned = PyCloud::py_new(cloud, attributes)?;
            &owned.inner
        }
    };
    let format = match WriteFormat::from_path(&path) {
        Some(WriteFormat::PlyBinary) if ascii => WriteFormat::PlyAscii,
        Some(f) => f,
        None => {
            return Err(value_err(format!(
                "{}: unknown point format; use .ply, .xyz, .txt, .csv, .pts or .asc",
                path.display()
            )))
        }
    };
    py.detach(|| scanfit_io::write_cloud(&path, c, format))
        .map_err(io_err)
}

/// PCA normals over the ``k`` nearest neighbours with the surface variation
/// (``scanfit cloud normals``). ``orient``: ``"mst"`` (one orientation
/// propagated over a minimum spanning tree, seeded at the extreme point
/// along ``hint`` in each connected part, Hoppe 1992), ``"view"`` (towards
/// ``viewpoint``) or ``"none"``.
///
/// Returns a dict: ``normals`` ``(N, 3)``, ``variation`` ``(N,)``,
/// ``mean_variation``, ``components``, ``degenerate`` (indices) and
/// ``cloud`` (the input with ``nx, ny, nz, variation`` added).
///
/// Example::
///
///     >>> r = scanfit.normals(cloud, k=16)
///     >>> r["normals"].shape
///     (30000, 3)
#[pyfunction]
#[pyo3(signature = (points, k = 16, orient = "mst", hint = (0.0, 0.0, 1.0), viewpoint = None))]
pub fn normals<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    k: usize,
    orient: &str,
    hint: (f64, f64, f64),
    viewpoint: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let cloud = cloud_arg(points, "points")?;
    let hint = scanfit::Vector3::new(hint.0, hint.1, hint.2);
    let orientation = match orient {
        "mst" => Orientation::SpanningTree { hint },
        "view" => match viewpoint {
            Some(v) => Orientation::Viewpoint(Point3::from(vec3(v, "viewpoint")?)),
            None => {
                return Err(value_err(
                    "orient = \"view\" needs viewpoint=(x, y, z)".into(),
                ))
            }
        },
        "none" => Orientation::None,
        o => return Err(bad_choice("orient", o, &["mst", "view", "none"])),
    };
    let mut cfg = CloudNormalsConfig::default();
    cfg.normals.k = k;
    cfg.normals.orientation = orientation;
    let c = cloud.get();
    let r = py
        .detach(|| run_normals(c, &cfg, &NoProgress))
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item(
        "normals",
        crate::convert::vectors_array(py, &r.normals.normals)?,
    )?;
    d.set_item("variation", vec1(py, r.normals.variation.clone()))?;
    d.set_item("mean_variation", r.mean_variation)?;
    d.set_item("components", r.normals.components)?;
    d.set_item(
        "degenerate",
        vec1(
            py,
            r.normals
                .degenerate
                .iter()
                .map(|&i| i as u64)
                .collect::<Vec<_>>(),
        ),
    )?;
    d.set_item("cloud", PyCloud::new(r.cloud))?;
    Ok(d)
}

/// The points visible from ``viewpoint`` by hidden point removal (Katz, Tal
/// & Basri 2007: spherical flipping with radius ``R = max distance x
/// 10^gamma``, then the convex hull; ``scanfit cloud hpr``).
///
/// Returns a dict: ``visible`` (ascending indices), ``hidden`` (count),
/// ``mask`` (bool per point) and ``cloud`` (the visible points with their
/// attributes and ``index``).
#[pyfunction]
#[pyo3(signature = (points, viewpoint, gamma = 2.0))]
pub fn hpr<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    viewpoint: &Bound<'py, PyAny>,
    gamma: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let cloud = cloud_arg(points, "points")?;
    let mut cfg = CloudHprConfig::from_viewpoint(Point3::from(vec3(viewpoint, "viewpoint")?));
    cfg.hpr.gamma = gamma;
    let c = cloud.get();
    let r = py.detach(|| run_hpr(c, &cfg, &NoProgress)).map_err(err)?;
    let d = PyDict::new(py);
    let n = c.len();
    d.set_item("mask", vec1(py, r.visible_mask(n)))?;
    d.set_item(
        "visible",
        vec1(py, r.visible.iter().map(|&i| i as u64).collect::<Vec<_>>()),
    )?;
    d.set_item("hidden", r.hidden)?;
    d.set_item("cloud", PyCloud::new(r.cloud))?;
    Ok(d)
}

/// Boundary loops of a sheet-like patch (alpha shape in its best-fit plane)
/// and the corners of the outer loop (``scanfit cloud boundary``).
///
/// ``alpha``: the alpha radius in data units (default ``alpha_factor`` x
/// the median Delaunay edge). ``corners``: how many (4 or 3 for Coons
/// patches, 0 for the loop only), by ``criterion`` ``"angle"`` (smallest
/// turning angle, Coons paper eqs. 10-12) or ``"curvature"`` (three-point
/// curvature, PDE paper 4.1), at least ``min_separation`` of the loop
/// length apart; ``corner_at`` gives loop positions instead.
///
/// Returns a dict like the command's JSON: ``alpha``, ``spacing``,
/// ``plane`` (``origin``, ``normal``), ``loops`` (each ``indices``,
/// ``area``), ``outer``, ``corners`` (each ``position`` in the outer loop,
/// ``index`` in the input, ``value``: angle in degrees or curvature) or
/// ``None``, ``sides`` (input indices per side) or ``None``.
#[pyfunction]
#[pyo3(signature = (points, alpha = None, alpha_factor = 2.5, corners = 4, criterion = "angle", corner_offset = None, min_separation = 0.03, corner_at = None))]
#[allow(clippy::too_many_arguments)]
pub fn boundary<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    alpha: Option<f64>,
    alpha_factor: f64,
    corners: usize,
    criterion: &str,
    corner_offset: Option<usize>,
    min_separation: f64,
    corner_at: Option<Vec<usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    let cloud = cloud_arg(points, "points")?;
    let mut cfg = CloudBoundaryConfig::default();
    cfg.boundary.alpha = alpha;
    cfg.boundary.alpha_factor = alpha_factor;
    cfg.corners.count = corners;
    cfg.corners.criterion = criterion_of(criterion)?;
    cfg.corners.offset = corner_offset;
    cfg.corners.min_separation = min_separation;
    cfg.corner_positions = corner_at;
    let c = cloud.get();
    let r = py
        .detach(|| run_boundary(c, &cfg, &NoProgress))
        .map_err(err)?;
    let b = &r.boundary;
    let d = PyDict::new(py);
    d.set_item("alpha", b.alpha)?;
    d.set_item("spacing", b.spacing)?;
    let plane = PyDict::new(py);
    let (o, n) = (b.plane.origin, b.plane.normal);
    plane.set_item("origin", [o.x, o.y, o.z])?;
    plane.set_item("normal", [n.x, n.y, n.z])?;
    d.set_item("plane", plane)?;
    d.set_item("outer", b.outer)?;
    let loops = PyList::empty(py);
    for (l, area) in b.loops.iter().zip(&b.areas) {
        let e = PyDict::new(py);
        e.set_item(
            "indices",
            vec1(py, l.iter().map(|&i| i as u64).collect::<Vec<_>>()),
        )?;
        e.set_item("area", area)?;
        loops.append(e)?;
    }
    d.set_item("loops", loops)?;
    let outer = r.outer();
    match &r.corners {
        Some(cs) => {
            let list = PyList::empty(py);
            for &k in &cs.corners {
                let e = PyDict::new(py);
                e.set_item("position", k)?;
                e.set_item("index", outer[k])?;
                e.set_item("value", r.corner_value(k))?;
                list.append(e)?;
            }
            d.set_item("corners", list)?;
            let sides: Vec<Vec<usize>> = cs
                .sides
                .iter()
                .map(|s| s.iter().map(|&k| outer[k]).collect())
                .collect();
            d.set_item("sides", sides)?;
        }
        None => {
            d.set_item("corners", py.None())?;
            d.set_item("sides", py.None())?;
        }
    }
    Ok(d)
}

/// `"angle"` or `"curvature"`.
pub fn criterion_of(s: &str) -> PyResult<CornerCriterion> {
    match s {
        "angle" => Ok(CornerCriterion::TurningAngle),
        "curvature" => Ok(CornerCriterion::ThreePointCurvature),
        o => Err(bad_choice("criterion", o, &["angle", "curvature"])),
    }
}
