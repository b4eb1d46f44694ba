//! The accumulators of a chunked or distributed fit (module `scanfit.sums`,
//! driven by `scanfit.dask`): the sums over points behind MBA ([LWS97]
//! eqs. 3-4, per level) and behind the least-squares surface (the normal
//! equations, [NURBS97] eq. 9.63), each created empty, fed chunks of points,
//! merged with another, finished, and picklable (an exact bytes round trip,
//! `scanfit::wire`), so that workers can return them to a client.
//!
//! * `Centring`: the translation of the data's bounding box the in-memory
//!   pipelines compute relative to (`scanfit::centring`); every chunk is
//!   moved by it before it is summed.
//! * `FrameSums`: the MBA frame (bounding box in x, y and the mean height).
//! * `MbaLevels`: the level loop on the client; `state()` is what is
//!   broadcast per level (`MbaState`: frame, the level lattices so far,
//!   the centring), `accumulator()` the level's empty `BaSums`.
//! * `BaSums`: one level's BA sums; `add(state, points)` evaluates the
//!   levels so far at the points, adds their residuals and returns the
//!   pass's `PassSums` (a row's statistics, the fitted start's sums).
//! * `ResidualSums`: mergeable error statistics (count, mean, max, RMSE).
//! * `NormalEquations`: the least-squares surface's normal equations with
//!   uniform knots, configured by `fit_surface`'s keywords.

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};
use scanfit::centring::Centring;
use scanfit::fit::surface::NormalEquations;
use scanfit::mba::sums::pass_sums;
use scanfit::mba::{
    lattice_surface, BaAccumulator, ControlFormula, Frame, FrameSums, Lattice, LevelInputs,
    MbaLevels, PassSums, ResidualSums, Start,
};
use scanfit::wire::{Reader, Writer};
use scanfit::{Point3, Vector3};

use crate::convert::{err, float_array, points, uv_columns, value_err, vec3};
use crate::geometry::PySurface;
use crate::report::stats;
use crate::surfaces::mba_config;

/// The points of a chunk: an `(N, 3)` array, `N = 0` allowed (an empty
/// chunk adds nothing).
pub(crate) fn chunk(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Point3>> {
    let a = float_array(obj, "points")?;
    if a.shape() == [0, 3] {
        return Ok(Vec::new());
    }
    points(obj, "points")
}

/// `(cls_restore, (kind, bytes))` for `__reduce__`: pickled as the exact
/// bytes, restored by `scanfit.sums._restore`.
pub(crate) fn reduce<'py>(
    py: Python<'py>,
    kind: &str,
    bytes: &[u8],
) -> PyResult<Bound<'py, PyTuple>> {
    let restore = py.import("scanfit.sums")?.getattr("_restore")?;
    let args = PyTuple::new(
        py,
        [
            kind.into_pyobject(py)?.into_any(),
            PyBytes::new(py, bytes).into_any(),
        ],
    )?;
    PyTuple::new(py, [restore, args.into_any()])
}

/// Reads a Python record: the tag, then `f` on the reader, then the end.
pub(crate) fn read<T>(
    bytes: &[u8],
    tag: &[u8; 8],
    what: &'static str,
    f: impl FnOnce(&mut Reader<'_>) -> scanfit::Result<T>,
) -> PyResult<T> {
    let mut r = Reader::new(bytes, tag, what).map_err(err)?;
    let t = f(&mut r).map_err(err)?;
    r.end().map_err(err)?;
    Ok(t)
}

/// A class of `scanfit.sums` that travels as exact bytes: its record
/// (`scanfit::wire`) and the name `scanfit.sums._restore` knows it by.
pub(crate) trait Wire: Sized {
    /// The class's name in `scanfit.sums._KINDS`.
    const KIND: &'static str;
    /// The exact bytes.
    fn encode(&self) -> Vec<u8>;
    /// Reads what [`encode`](Self::encode) wrote.
    fn decode(data: &[u8]) -> PyResult<Self>;
}

/// `#[pymethods] impl` of a [`Wire`] class with its methods and the three
/// that make it picklable: `to_bytes`, `from_bytes` and `__reduce__`
/// (`(scanfit.sums._restore, (kind, bytes))`).
macro_rules! pickled {
    ($ty:ty { $($methods:tt)* }) => {
        #[pymethods]
        impl $ty {
            $($methods)*

            /// The exact bytes (see ``from_bytes``).
            fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, pyo3::types::PyBytes> {
                pyo3::types::PyBytes::new(py, &$crate::sums::Wire::encode(self))
            }

            /// The object whose ``to_bytes`` gave ``data`` (refused, with the
            /// reason, when they are of another type or version).
            #[staticmethod]
            fn from_bytes(data: &[u8]) -> PyResult<Self> {
                <Self as $crate::sums::Wire>::decode(data)
            }

            fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
                $crate::sums::reduce(
                    py,
                    <Self as $crate::sums::Wire>::KIND,
                    &$crate::sums::Wire::encode(self),
                )
            }
        }
    };
}
pub(crate) use pickled;

/// [`Wire`] for a class that wraps a library accumulator `inner` with its
/// own exact bytes (`to_bytes`/`from_bytes`).
macro_rules! wire_inner {
    ($ty:ty, $inner:ty, $kind:literal) => {
        impl $crate::sums::Wire for $ty {
            const KIND: &'static str = $kind;

            fn encode(&self) -> Vec<u8> {
                self.inner.to_bytes()
            }

            fn decode(data: &[u8]) -> PyResult<Self> {
                Ok(Self {
                    inner: <$inner>::from_bytes(data).map_err($crate::convert::err)?,
                })
            }
        }
    };
}
pub(crate) use wire_inner;

/// The translation that moves the data's bounding box to the origin (as
/// the in-memory pipelines compute), from the box's corners.
///
/// Example::
///
///     >>> c = scanfit.sums.Centring((6e5, 5e6, 0.0), (6.1e5, 5.01e6, 30.0))
///     >>> c.centre
///     (605000.0, 5005000.0, 0.0)
#[pyclass(name = "Centring", module = "scanfit.sums", frozen)]
#[derive(Clone)]
pub struct PyCentring {
    lo: Vector3,
    hi: Vector3,
    pub(crate) inner: Centring,
}

impl PyCentring {
    fn of(lo: Vector3, hi: Vector3) -> Self {
        let inner = Centring::of(&[Point3::from(lo), Point3::from(hi)]);
        Self { lo, hi, inner }
    }

    pub(crate) fn write(&self, w: &mut Writer) {
        for x in self.lo.iter().chain(self.hi.iter()) {
            w.f64(*x);
        }
    }

    pub(crate) fn read(r: &mut Reader<'_>) -> scanfit::Result<Self> {
        let mut v = [0.0; 6];
        for x in &mut v {
            *x = r.f64()?;
        }
        Ok(Self::of(
            Vector3::new(v[0], v[1], v[2]),
            Vector3::new(v[3], v[4], v[5]),
        ))
    }

    /// `points` moved by `-centre`.
    pub(crate) fn apply(&self, points: Vec<Point3>) -> Vec<Point3> {
        if self.inner.is_identity() {
            points
        } else {
            self.inner.points(&points)
        }
    }
}

const CENTRING_TAG: &[u8; 8] = b"SFPYCEN1";

impl Wire for PyCentring {
    const KIND: &'static str = "Centring";

    fn encode(&self) -> Vec<u8> {
        let mut w = Writer::new(CENTRING_TAG);
        self.write(&mut w);
        w.finish()
    }

    fn decode(data: &[u8]) -> PyResult<Self> {
        read(data, CENTRING_TAG, "a centring", Self::read)
    }
}

pickled!(PyCentring {
    /// The centring of data whose bounding box has corners `lo` and `hi`.
    #[new]
    fn new(lo: &Bound<'_, PyAny>, hi: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (lo, hi) = (vec3(lo, "lo")?, vec3(hi, "hi")?);
        if !(lo.iter().chain(hi.iter()).all(|x| x.is_finite())) || (0..3).any(|k| lo[k] > hi[k]) {
            return Err(value_err(format!(
                "the bounding box ({}, {}, {}) - ({}, {}, {}) is not one: corners must be finite with lo <= hi",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            )));
        }
        Ok(Self::of(lo, hi))
    }

    /// The translation subtracted from every point (0 where none is needed).
    #[getter]
    fn centre(&self) -> (f64, f64, f64) {
        let c = self.inner.centre();
        (c.x, c.y, c.z)
    }

    fn __repr__(&self) -> String {
        let c = self.centre();
        format!("Centring(centre=({}, {}, {}))", c.0, c.1, c.2)
    }
});

/// The sums behind the MBA frame: bounding box in x and y and the sum of
/// the heights, of centred points.
///
/// Example::
///
///     >>> c = scanfit.sums.Centring(pts.min(axis=0), pts.max(axis=0))
///     >>> f = scanfit.sums.FrameSums()
///     >>> f.add(pts[:500], c); g = scanfit.sums.FrameSums(); g.add(pts[500:], c)
///     >>> f.merge(g); f.points == len(pts)
///     True
#[pyclass(name = "FrameSums", module = "scanfit.sums")]
#[derive(Clone, Default)]
pub struct PyFrameSums {
    inner: FrameSums,
}

wire_inner!(PyFrameSums, FrameSums, "FrameSums");

pickled!(PyFrameSums {
    /// Empty sums.
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// Adds an ``(N, 3)`` chunk (``N = 0`` allowed), moved by ``centring``.
    fn add(
        &mut self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        centring: &PyCentring,
    ) -> PyResult<()> {
        let p = centring.apply(chunk(points)?);
        py.detach(|| self.inner.add(&p)).map_err(err)
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Adds the sums of other points.
    fn merge(&mut self, other: &PyFrameSums) {
        self.inner.merge(&other.inner);
    }

    /// Points added.
    #[getter]
    fn points(&self) -> u64 {
        self.inner.points()
    }

    fn __repr__(&self) -> String {
        format!("FrameSums(points={})", self.inner.points())
    }
});

/// Mergeable statistics of absolute errors: count, mean, max (and the
/// index of the largest over all values, in merge order) and RMSE.
///
/// Example::
///
///     >>> s = scanfit.sums.ResidualSums(); s.add(np.array([0.5, 2.0]))
///     >>> s.stats()["max"]
///     2.0
#[pyclass(name = "ResidualSums", module = "scanfit.sums")]
#[derive(Clone, Default)]
pub struct PyResidualSums {
    pub(crate) inner: ResidualSums,
}

wire_inner!(PyResidualSums, ResidualSums, "ResidualSums");

pickled!(PyResidualSums {
    /// No values.
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// Adds the absolute values of a one-dimensional array.
    fn add(&mut self, values: &Bound<'_, PyAny>) -> PyResult<()> {
        let a = float_array(values, "values")?;
        if a.ndim() != 1 {
            return Err(value_err(format!(
                "values must be one-dimensional; got {} dimensions",
                a.ndim()
            )));
        }
        for x in a.as_array().iter() {
            if !x.is_finite() {
                return Err(value_err(format!("values holds {x}; give finite values")));
            }
            self.inner.push(x.abs());
        }
        Ok(())
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Adds the statistics of values that come after these.
    fn merge(&mut self, other: &PyResidualSums) {
        self.inner.merge(&other.inner);
    }

    /// Values added.
    #[getter]
    fn count(&self) -> u64 {
        self.inner.count
    }

    /// ``count``, ``mean``, ``max``, ``max_index``, ``rmse``.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        stats(py, &self.inner.stats())
    }

    fn __repr__(&self) -> String {
        let s = self.inner.stats();
        format!(
            "ResidualSums(count={}, rmse={}, max={})",
            s.count, s.rmse, s.max
        )
    }
});

/// What one MBA pass over a chunk measures besides a level's BA sums: the
/// residual statistics of the row it measures (``row``) and the sums behind
/// the fitted start (``start``: ``sum r c / sum c^2`` of the residuals after
/// the levels so far). Merged in chunk order like ``ResidualSums``.
///
/// Example::
///
///     >>> sums = acc.add(state, pts[:5000]); sums.merge(acc.add(state, pts[5000:]))
///     >>> run.record(sums)
#[pyclass(name = "PassSums", module = "scanfit.sums")]
#[derive(Clone, Default)]
pub struct PyPassSums {
    inner: PassSums,
}

wire_inner!(PyPassSums, PassSums, "PassSums");

pickled!(PyPassSums {
    /// No points.
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Adds the sums of the points after these.
    fn merge(&mut self, other: &PyPassSums) {
        self.inner.merge(&other.inner);
    }

    /// Points of the pass.
    #[getter]
    fn count(&self) -> u64 {
        self.inner.count
    }

    /// The statistics of the row measured (``count`` 0 when none).
    fn row<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        stats(py, &self.inner.row.stats())
    }

    /// The fitted start of the levels so far (0 for the mean start).
    #[getter]
    fn start(&self) -> f64 {
        self.inner.start()
    }

    fn __repr__(&self) -> String {
        format!(
            "PassSums(count={}, start={})",
            self.inner.count,
            self.inner.start()
        )
    }
});

/// What an MBA level broadcasts to the workers: the frame, the lattices of
/// the levels so far (the heights' and, for the fitted start, the
/// constant's), the row the pass measures and the centring (bytes: the
/// lattice sizes, never the point count).
#[pyclass(name = "MbaState", module = "scanfit.sums", frozen)]
#[derive(Clone)]
pub struct PyMbaState {
    centring: PyCentring,
    frame: Frame,
    levels: Vec<Lattice>,
    constant: Vec<Lattice>,
    start: Start,
    /// `LevelInputs::row`.
    row: Option<(usize, f64)>,
    /// Cells of the next level's lattice and its control formula.
    next: (usize, usize, ControlFormula),
}

/// Version 2: the constant's lattices, the start and the row.
const STATE_TAG: &[u8; 8] = b"SFPYMBS2";

impl PyMbaState {
    fn inputs(&self) -> LevelInputs<'_> {
        LevelInputs {
            frame: self.frame,
            heights: &self.levels,
            constant: &self.constant,
            start: self.start,
            row: self.row,
        }
    }
}

/// Writes lattices: their count, then each one's cells and values.
fn write_lattices(w: &mut Writer, lattices: &[Lattice]) {
    w.usize(lattices.len());
    for l in lattices {
        w.usize(l.m);
        w.usize(l.n);
        w.f64s(&l.phi);
    }
}

/// Reads what [`write_lattices`] wrote.
fn read_lattices(r: &mut Reader<'_>) -> scanfit::Result<Vec<Lattice>> {
    let count = r.usize()?;
    let mut levels = Vec::new();
    for _ in 0..count {
        let (m, n, phi) = (r.usize()?, r.usize()?, r.f64s()?);
        if m.checked_add(3)
            .zip(n.checked_add(3))
            .and_then(|(a, b)| a.checked_mul(b))
            != Some(phi.len())
        {
            return Err(r.corrupt(&format!("a {m} x {n} lattice of {} values", phi.len())));
        }
        levels.push(Lattice { m, n, phi });
    }
    Ok(levels)
}

impl Wire for PyMbaState {
    const KIND: &'static str = "MbaState";

    fn encode(&self) -> Vec<u8> {
        let mut w = Writer::new(STATE_TAG);
        self.centring.write(&mut w);
        let f = &self.frame;
        for x in [f.x0, f.y0, f.width, f.height, f.z0] {
            w.f64(x);
        }
        w.usize(self.next.0);
        w.usize(self.next.1);
        w.u64(u64::from(self.next.2 == ControlFormula::Hjelle));
        write_lattices(&mut w, &self.levels);
        write_lattices(&mut w, &self.constant);
        w.u64(u64::from(self.start == Start::Fitted));
        let (j, d) = self.row.unwrap_or((usize::MAX, 0.0));
        w.usize(j);
        w.f64(d);
        w.finish()
    }

    fn decode(data: &[u8]) -> PyResult<Self> {
        read(data, STATE_TAG, "an MBA level state", |r| {
            let centring = PyCentring::read(r)?;
            let frame = Frame {
                x0: r.f64()?,
                y0: r.f64()?,
                width: r.f64()?,
                height: r.f64()?,
                z0: r.f64()?,
            };
            let (m, n) = (r.usize()?, r.usize()?);
            let formula = match r.u64()? {
                0 => ControlFormula::LeeWolbergShin,
                1 => ControlFormula::Hjelle,
                x => return Err(r.corrupt(&format!("control formula {x}"))),
            };
            let levels = read_lattices(r)?;
            let constant = read_lattices(r)?;
            let start = match r.u64()? {
                0 => Start::Mean,
                1 => Start::Fitted,
                x => return Err(r.corrupt(&format!("start {x}"))),
            };
            let (j, d) = (r.usize()?, r.f64()?);
            Ok(Self {
                centring,
                frame,
                levels,
                constant,
                start,
                row: (j != usize::MAX).then_some((j, d)),
                next: (m, n, formula),
            })
        })
    }
}

pickled!(PyMbaState {
    /// The statistics of the vertical residuals ``|z - f(x, y)|`` of an
    /// ``(N, 3)`` chunk after the levels so far, started from the mean or
    /// (fitted start) from the start of the levels so far (an error while
    /// ``MbaLevels.needs_pass``).
    fn residuals(&self, py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<PyResidualSums> {
        let h = self.levels.len();
        let d = match (self.start, self.row) {
            (Start::Mean, _) => 0.0,
            (Start::Fitted, Some((j, d))) if j == h => d,
            (Start::Fitted, _) if h == 0 => 0.0,
            (Start::Fitted, _) => {
                return Err(value_err(
                    "the fitted start of the last level is not known yet: run the pass of MbaState.pass_sums while MbaLevels.needs_pass, record it, then take the state again".into(),
                ))
            }
        };
        let p = self.centring.apply(chunk(points)?);
        let inputs = LevelInputs {
            row: Some((h, d)),
            ..self.inputs()
        };
        let inner = py.detach(|| pass_sums(&inputs, &p)).map_err(err)?.row;
        Ok(PyResidualSums { inner })
    }

    /// The pass sums of an ``(N, 3)`` chunk after the levels so far,
    /// without a level's BA sums: the fitted start's pass after the last
    /// level (``MbaLevels.needs_pass``).
    fn pass_sums(&self, py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<PyPassSums> {
        let p = self.centring.apply(chunk(points)?);
        let inner = py
            .detach(|| pass_sums(&self.inputs(), &p))
            .map_err(err)?;
        Ok(PyPassSums { inner })
    }

    /// Empty BA sums of the next level (what each worker fills).
    fn accumulator(&self) -> PyResult<PyBaSums> {
        let (m, n, formula) = self.next;
        Ok(PyBaSums {
            inner: BaAccumulator::for_start(m, n, formula, self.start).map_err(err)?,
        })
    }

    /// Levels so far.
    #[getter]
    fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Bytes of the lattices (what is sent to each worker per level).
    #[getter]
    fn nbytes(&self) -> usize {
        self.levels
            .iter()
            .chain(&self.constant)
            .map(|l| 8 * l.phi.len())
            .sum()
    }

    fn __repr__(&self) -> String {
        format!(
            "MbaState(levels={}, nbytes={})",
            self.levels.len(),
            self.nbytes()
        )
    }
});

/// The BA sums of one MBA level ([LWS97] eqs. 3-4): per control value the
/// numerator and denominator of eq. 4. Made by ``MbaLevels.accumulator()``.
///
/// Example::
///
///     >>> acc = run.accumulator()
///     >>> stats = acc.add(run.state(), pts)   # the residuals of the level before
///     >>> run.push(acc)
#[pyclass(name = "BaSums", module = "scanfit.sums")]
#[derive(Clone)]
pub struct PyBaSums {
    inner: BaAccumulator,
}

wire_inner!(PyBaSums, BaAccumulator, "BaSums");

pickled!(PyBaSums {
    /// Adds the residuals of an ``(N, 3)`` chunk (``N = 0`` allowed) after
    /// the levels of ``state``; returns what the pass measures
    /// (``PassSums``: the statistics of a level before, for its report, and
    /// the fitted start's sums).
    fn add(
        &mut self,
        py: Python<'_>,
        state: &PyMbaState,
        points: &Bound<'_, PyAny>,
    ) -> PyResult<PyPassSums> {
        let p = state.centring.apply(chunk(points)?);
        let inner = py
            .detach(|| self.inner.add_levels(&state.inputs(), &p))
            .map_err(err)?;
        Ok(PyPassSums { inner })
    }

    /// An independent copy (tasks copy a broadcast value before changing it).
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Adds the sums of other points (the same level).
    fn merge(&mut self, other: &PyBaSums) -> PyResult<()> {
        self.inner.merge(other.inner.clone()).map_err(err)
    }

    /// Points added.
    #[getter]
    fn points(&self) -> u64 {
        self.inner.points()
    }

    /// Cells ``(m, n)`` of the level's lattice.
    #[getter]
    fn cells(&self) -> (usize, usize) {
        self.inner.cells()
    }

    /// Bytes of one set of sums (per control value a numerator per value
    /// set and the denominator).
    #[getter]
    fn nbytes(&self) -> usize {
        self.inner.bytes()
    }

    fn __repr__(&self) -> String {
        let (m, n) = self.inner.cells();
        format!("BaSums(cells=({m}, {n}), points={})", self.inner.points())
    }
});

/// The MBA level loop on the client (``scanfit.mba``'s keywords ``levels``,
/// ``base``, ``tolerance``, ``hjelle``, ``start``): per level, ``state()``
/// is broadcast, the workers return ``BaSums`` of their points and their
/// ``PassSums``, merged; the pass sums are ``record``-ed (which says
/// whether the tolerance is met) and the BA sums ``push``-ed. With the
/// fitted start (the default) one more pass of ``MbaState.pass_sums`` finds
/// the last level's start while ``needs_pass``; ``finish()`` gives the
/// surface, and ``record_last`` the last row from a measuring pass.
///
/// ``frame`` holds the sums of the centred points; ``domain=(x0, y0, x1,
/// y1)`` (data units) replaces their bounding box in x and y by that
/// rectangle (points outside it are clamped to its border).
///
/// Example::
///
///     >>> run = scanfit.sums.MbaLevels(frame, centring, levels=4)
///     >>> while not run.done:
///     ...     acc = run.accumulator(); sums = acc.add(run.state(), pts)
///     ...     if run.record(sums): break
///     ...     run.push(acc)
///     >>> while run.needs_pass:
///     ...     run.record(run.state().pass_sums(pts))
///     >>> run.finish()["surface"]
#[pyclass(name = "MbaLevels", module = "scanfit.sums")]
pub struct PyMbaLevels {
    run: Option<MbaLevels>,
    centring: PyCentring,
    formula: ControlFormula,
}

impl PyMbaLevels {
    fn run(&self) -> PyResult<&MbaLevels> {
        self.run
            .as_ref()
            .ok_or_else(|| value_err("this MbaLevels has finished; make a new one".into()))
    }

    fn run_mut(&mut self) -> PyResult<&mut MbaLevels> {
        self.run
            .as_mut()
            .ok_or_else(|| value_err("this MbaLevels has finished; make a new one".into()))
    }
}

#[pymethods]
impl PyMbaLevels {
    /// The loop over the data summed in ``frame`` (centred by ``centring``).
    #[new]
    #[pyo3(signature = (frame, centring, levels = 6, base = None, tolerance = None, hjelle = false, domain = None, start = "fitted"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        frame: &PyFrameSums,
        centring: &PyCentring,
        levels: usize,
        base: Option<Bound<'_, PyAny>>,
        tolerance: Option<f64>,
        hjelle: bool,
        domain: Option<(f64, f64, f64, f64)>,
        start: &str,
    ) -> PyResult<Self> {
        if levels == 0 {
            return Err(value_err("levels must be at least 1".into()));
        }
        let config = mba_config(levels, base.as_ref(), tolerance, hjelle, start)?;
        let f = match domain {
            None => frame.inner.finish().map_err(err)?,
            Some((x0, y0, x1, y1)) => {
                let c = centring.inner.centre();
                if !([x0, y0, x1, y1].iter().all(|v| v.is_finite()) && x1 > x0 && y1 > y0) {
                    return Err(value_err(format!(
                        "domain ({x0}, {y0}, {x1}, {y1}) is not a rectangle (x0, y0, x1, y1) with x0 < x1 and y0 < y1"
                    )));
                }
                let z0 = frame.inner.mean_z().ok_or_else(|| {
                    value_err("the frame sums hold no point; no point was read".into())
                })?;
                Frame {
                    x0: x0 - c.x,
                    y0: y0 - c.y,
                    width: x1 - x0,
                    height: y1 - y0,
                    z0,
                }
            }
        };
        Ok(Self {
            run: Some(MbaLevels::new(f, &config).map_err(err)?),
            centring: centring.clone(),
            formula: config.formula,
        })
    }

    /// Whether every level is done.
    #[getter]
    fn done(&self) -> PyResult<bool> {
        Ok(self.run()?.done())
    }

    /// Cells ``(m, n)`` of the next level.
    #[getter]
    fn next_cells(&self) -> PyResult<(usize, usize)> {
        Ok(self.run()?.next_cells())
    }

    /// What the workers need for the next level (frame, lattices so far,
    /// centring).
    fn state(&self) -> PyResult<PyMbaState> {
        let run = self.run()?;
        let (m, n) = run.next_cells();
        let inputs = run.inputs();
        Ok(PyMbaState {
            centring: self.centring.clone(),
            frame: inputs.frame,
            levels: inputs.heights.to_vec(),
            constant: inputs.constant.to_vec(),
            start: inputs.start,
            row: inputs.row,
            next: (m, n, self.formula),
        })
    }

    /// Empty BA sums of the next level.
    fn accumulator(&self) -> PyResult<PyBaSums> {
        Ok(PyBaSums {
            inner: self.run()?.accumulator().map_err(err)?,
        })
    }

    /// Finishes the next level from its merged sums.
    fn push(&mut self, sums: &PyBaSums) -> PyResult<()> {
        self.run_mut()?.push(sums.inner.clone()).map_err(err)
    }

    /// Records what a pass over all points measured (the ``PassSums`` of
    /// its chunks, merged in point order): a row of a level before and the
    /// fitted start so far; returns whether the tolerance is met (stop
    /// before pushing the level).
    fn record(&mut self, sums: &PyPassSums) -> PyResult<bool> {
        self.run_mut()?.record(&sums.inner).map_err(err)
    }

    /// Whether the fitted start of the last level is unknown: one more pass
    /// of ``MbaState.pass_sums``, ``record``-ed, before ``finish``.
    #[getter]
    fn needs_pass(&self) -> PyResult<bool> {
        Ok(self.run()?.needs_pass())
    }

    /// Records the last level's row from a measuring pass over the
    /// finished surface (``MbaState.residuals``), unless a pass recorded it.
    fn record_last(&mut self, sums: &PyResidualSums) -> PyResult<()> {
        self.run_mut()?.record_last(sums.inner.stats());
        Ok(())
    }

    /// The approximation: a dict with ``surface`` (in data coordinates, as
    /// ``scanfit.mba``'s), ``cells`` and ``levels`` (``level``,
    /// ``control_points``, ``vertical`` statistics as recorded, ``seconds``).
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let run = self
            .run
            .take()
            .ok_or_else(|| value_err("this MbaLevels has finished; make a new one".into()))?;
        let r = run.finish();
        let surface = lattice_surface(&r.frame, &r.lattice).map_err(err)?;
        let d = PyDict::new(py);
        d.set_item(
            "surface",
            PySurface::new(self.centring.inner.restore(surface)),
        )?;
        d.set_item("cells", (r.lattice.m, r.lattice.n))?;
        let rows = PyList::empty(py);
        for l in &r.reports {
            let e = PyDict::new(py);
            e.set_item("level", l.level)?;
            e.set_item("control_points", (l.cells.0 + 3, l.cells.1 + 3))?;
            e.set_item("vertical", stats(py, &l.residual)?)?;
            e.set_item("seconds", l.seconds)?;
            rows.append(e)?;
        }
        d.set_item("levels", rows)?;
        Ok(d)
    }
}

/// The normal equations of the least-squares surface ([NURBS97] eq. 9.63)
/// for ``fit_surface``'s keywords: made empty by ``FitSetup.equations()``
/// (uniform knots, or those of a finished ``KnotSearch``), fed chunks of
/// points with their parameters, merged, finished.
///
/// Example::
///
///     >>> eq = scanfit.sums.FitSetup(len(pts), centring, ctrl=(8, 8), params="uv", knots="uniform").equations()
///     >>> eq.add(pts, uv); eq.finish()
#[pyclass(name = "NormalEquations", module = "scanfit.sums")]
#[derive(Clone)]
pub struct PyNormalEquations {
    pub(crate) inner: NormalEquations,
    pub(crate) smoothing: f64,
    pub(crate) centring: PyCentring,
}

const NORMAL_TAG: &[u8; 8] = b"SFPYNEQ1";

impl PyNormalEquations {
    fn bytes(&self) -> Vec<u8> {
        let mut w = Writer::new(NORMAL_TAG);
        self.centring.write(&mut w);
        w.f64(self.smoothing);
        let inner = self.inner.to_bytes();
        w.usize(inner.len());
        let mut bytes = w.finish();
        bytes.extend_from_slice(&inner);
        bytes
    }
}

impl Wire for PyNormalEquations {
    const KIND: &'static str = "NormalEquations";

    fn encode(&self) -> Vec<u8> {
        self.bytes()
    }

    fn decode(data: &[u8]) -> PyResult<Self> {
        let mut r = Reader::new(data, NORMAL_TAG, "least-squares normal equations").map_err(err)?;
        let centring = PyCentring::read(&mut r).map_err(err)?;
        let smoothing = r.f64().map_err(err)?;
        let len = r.usize().map_err(err)?;
        let start = 8 + 6 * 8 + 8 + 8;
        if data.len() != start + len {
            return Err(err(r.corrupt(&format!("an inner record of {len} bytes"))));
        }
        Ok(Self {
            inner: NormalEquations::from_bytes(&data[start..]).map_err(err)?,
            smoothing,
            centring,
        })
    }
}

pickled!(PyNormalEquations {
    /// Adds an ``(N, 3)`` chunk (``N = 0`` allowed) with its ``(N, 2)``
    /// parameters.
    fn add(
        &mut self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        uv: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let p = self.centring.apply(chunk(points)?);
        if p.is_empty() {
            return Ok(());
        }
        let (u, v) = uv_columns(uv, p.len())?;
        let uv: Vec<[f64; 2]> = u.into_iter().zip(v).map(|(u, v)| [u, v]).collect();
        py.detach(|| self.inner.add(&p, &uv, None)).map_err(err)
    }

    /// An independent copy (tasks copy a broadcast value before changing it).
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Adds the equations of other points.
    fn merge(&mut self, other: &PyNormalEquations) -> PyResult<()> {
        self.inner.merge(other.inner.clone()).map_err(err)
    }

    /// Points added.
    #[getter]
    fn points(&self) -> u64 {
        self.inner.points()
    }

    /// The thin-plate weight ``finish`` uses (as ``fit_surface`` resolves it).
    #[getter]
    fn smoothing(&self) -> f64 {
        self.smoothing
    }

    /// Bytes of the equations (matrix band and right-hand sides).
    #[getter]
    fn nbytes(&self) -> usize {
        self.inner.bytes()
    }

    /// Solves for the surface (in data coordinates).
    fn finish(&self, py: Python<'_>) -> PyResult<PySurface> {
        let eq = self.inner.clone();
        let s = py.detach(|| eq.finish(self.smoothing)).map_err(err)?;
        Ok(PySurface::new(self.centring.inner.restore(s)))
    }

    fn __repr__(&self) -> String {
        format!(
            "NormalEquations(points={}, smoothing={})",
            self.inner.points(),
            self.smoothing
        )
    }
});

/// The errors ``|p - S(u, v)|`` of an ``(N, 3)`` chunk at its ``(N, 2)``
/// parameters on ``surface``, as mergeable statistics (``N = 0`` allowed).
#[pyfunction]
pub fn surface_errors(
    py: Python<'_>,
    surface: &PySurface,
    points: &Bound<'_, PyAny>,
    uv: &Bound<'_, PyAny>,
) -> PyResult<PyResidualSums> {
    let p = chunk(points)?;
    let mut inner = ResidualSums::default();
    if p.is_empty() {
        return Ok(PyResidualSums { inner });
    }
    let (u, v) = uv_columns(uv, p.len())?;
    let s = &surface.inner;
    let ((u0, u1), (v0, v1)) = s.domain();
    if let Some(i) =
        (0..p.len()).find(|&i| !(u0..=u1).contains(&u[i]) || !(v0..=v1).contains(&v[i]))
    {
        return Err(value_err(format!(
            "uv: row {i} is ({}, {}), outside the surface's domain [{u0}, {u1}] x [{v0}, {v1}]",
            u[i], v[i]
        )));
    }
    py.detach(|| {
        for (k, q) in p.iter().enumerate() {
            inner.push((q - s.point(u[k], v[k])).norm());
        }
    });
    Ok(PyResidualSums { inner })
}

/// Adds the classes and functions of `scanfit.sums` to the native module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyCentring>()?;
    m.add_class::<PyFrameSums>()?;
    m.add_class::<PyResidualSums>()?;
    m.add_class::<PyPassSums>()?;
    m.add_class::<PyMbaState>()?;
    m.add_class::<PyBaSums>()?;
    m.add_class::<PyMbaLevels>()?;
    m.add_class::<PyNormalEquations>()?;
    m.add_function(wrap_pyfunction!(surface_errors, m)?)?;
    Ok(())
}
