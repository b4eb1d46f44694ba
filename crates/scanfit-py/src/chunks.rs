//! Point files read a bounded number of rows at a time (`scanfit.PointChunks`),
//! over the io crate's chunked reader ([`scanfit_io::chunks::PointChunks`],
//! the reader of `scanfit fit/mba --chunk-points`), and the automatic up
//! axis of a sample (`scanfit.up_axis`).
//!
//! `scanfit.dask` reads its tiles through these: a task sums one range of
//! rows of one tile, a chunk at a time, so a worker's memory is bounded by
//! the chunk size, not the tile size, and a big tile is split into several
//! tasks. The rows are counted as the reader serves them (after the
//! non-finite policy), in file order: the same rows `scanfit.read_cloud`
//! gives, in the same order.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, Receiver};
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::PyTuple;
use scanfit::up_axis::UpAxis;
use scanfit::Point3;
use scanfit_io::chunks::PointChunks;
use scanfit_io::{PointTable, ReadOptions};

use crate::convert::{array, io_err, points as point_rows, points_array, value_err};

/// The rows ``start`` to ``stop`` (``stop`` excluded; ``None``: to the end) of
/// a point file (PLY, LAS/LAZ, XYZ/CSV/TXT, PCD), served ``chunk_points``
/// rows at a time as ``(points, uv)``: ``points`` an ``(n, 3)`` float64 array,
/// ``uv`` an ``(n, 2)`` array of the columns ``u`` and ``v`` with ``uv=True``,
/// else ``None``. Rows are numbered as ``scanfit.read_cloud`` orders them.
///
/// Memory is bounded by ``chunk_points`` for text files, PLY files (ascii,
/// or binary with fixed-size vertex records) and LAS/LAZ files (``bounded``
/// says so); other files are read whole and served in chunks. The readers
/// cannot seek to a row: the rows before ``start`` are read (a chunk at a
/// time) and dropped, so reading a file in ``k`` ranges costs about
/// ``(k + 1) / 2`` reads of it. The file is read on a thread of its own, one
/// chunk ahead, with the GIL released (so at most about three chunks are in
/// memory). Read errors raise ``ScanfitError`` with the file (and its line
/// or byte offset) in the message.
///
/// Example::
///
///     >>> rows = scanfit.PointChunks("examples/data/terrain_50k.xyz", 20_000, start=10_000)
///     >>> [len(p) for p, uv in rows]
///     [10000, 20000, 10000]
#[pyclass(name = "PointChunks", module = "scanfit")]
pub struct PyPointChunks {
    /// The reader's chunks, from its own thread (`None` once ended).
    chunks: Option<Mutex<Receiver<Read>>>,
    path: PathBuf,
    uv: bool,
    start: u64,
    stop: Option<u64>,
    at: u64,
    bounded: bool,
}

/// A chunk from the reader thread, the end (`None`) or its error.
type Read = scanfit_io::Result<Option<PointTable>>;

/// Starts the reader of `path` on a thread of its own (the LAS/LAZ readers
/// cannot move between threads, so they stay on one, and the GIL is free
/// while a chunk is read); it reads one chunk ahead. Returns whether its
/// memory is bounded and the channel of its chunks.
fn spawn_reader(path: &Path, chunk: usize) -> scanfit_io::Result<(bool, Receiver<Read>)> {
    let (opened_tx, opened_rx) = sync_channel(1);
    let (tx, rx) = sync_channel::<Read>(1);
    let path_shown = path.to_path_buf();
    let path = path.to_path_buf();
    std::thread::spawn(move || {
        let mut reader = match PointChunks::open(&path, &ReadOptions::default(), chunk) {
            Ok(r) => r,
            Err(e) => {
                let _ = opened_tx.send(Err(e));
                return;
            }
        };
        if opened_tx.send(Ok(reader.bounded())).is_err() {
            return;
        }
        loop {
            let got = reader.next_chunk();
            let more = matches!(got, Ok(Some(_)));
            // a dropped receiver (the iterator closed) ends the thread
            if tx.send(got).is_err() || !more {
                return;
            }
        }
    });
    let bounded = opened_rx.recv().map_err(|_| stopped(&path_shown))??;
    Ok((bounded, rx))
}

/// The reader thread ended without a last word (it cannot, short of a bug).
fn stopped(path: &Path) -> scanfit_io::Error {
    scanfit_io::Error::Invalid {
        path: path.to_path_buf(),
        message: "the reader stopped before the end of the file".into(),
    }
}

#[pymethods]
impl PyPointChunks {
    /// Opens ``path`` (see the class documentation).
    #[new]
    #[pyo3(signature = (path, chunk_points = 1_000_000, uv = false, start = 0, stop = None))]
    fn new(
        py: Python<'_>,
        path: PathBuf,
        chunk_points: usize,
        uv: bool,
        start: u64,
        stop: Option<u64>,
    ) -> PyResult<Self> {
        if chunk_points == 0 {
            return Err(value_err(
                "chunk_points must be at least 1 (the rows read at a time)".into(),
            ));
        }
        if stop.is_some_and(|s| s < start) {
            return Err(value_err(format!(
                "stop ({}) is before start ({start}); give start <= stop",
                stop.unwrap_or_default()
            )));
        }
        let (bounded, chunks) = py
            .detach(|| spawn_reader(&path, chunk_points))
            .map_err(io_err)?;
        Ok(Self {
            chunks: Some(Mutex::new(chunks)),
            bounded,
            path,
            uv,
            start,
            stop,
            at: 0,
        })
    }

    /// Whether memory is bounded by ``chunk_points`` (rather than the file
    /// being read whole).
    #[getter]
    fn bounded(&self) -> bool {
        self.bounded
    }

    /// Rows read so far (dropped ones before ``start`` included).
    #[getter]
    fn rows_read(&self) -> u64 {
        self.at
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyTuple>>> {
        loop {
            if self.stop.is_some_and(|s| self.at >= s) {
                self.chunks = None;
                return Ok(None);
            }
            let Some(chunks) = self.chunks.as_ref() else {
                return Ok(None);
            };
            let got = py.detach(|| match chunks.lock() {
                Ok(rx) => rx.recv().unwrap_or_else(|_| Err(stopped(&self.path))),
                Err(_) => Err(stopped(&self.path)),
            });
            let Some(table) = got.map_err(|e| {
                self.chunks = None;
                io_err(e)
            })?
            else {
                self.chunks = None;
                return Ok(None);
            };
            let first = self.at;
            self.at += table.points.len() as u64;
            // the part of this chunk inside [start, stop)
            let lo = self
                .start
                .saturating_sub(first)
                .min(table.points.len() as u64) as usize;
            let hi = self
                .stop
                .map_or(table.points.len() as u64, |s| s.saturating_sub(first))
                .min(table.points.len() as u64) as usize;
            if lo >= hi {
                continue;
            }
            let uv = if self.uv {
                uv_rows(py, &self.path, &table, lo, hi)?
            } else {
                py.None().into_bound(py)
            };
            let pts = points_array(py, &table.points[lo..hi])?;
            return Ok(Some(PyTuple::new(py, [pts, uv])?));
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "PointChunks({:?}, rows {}..{}, read {})",
            self.path.display().to_string(),
            self.start,
            self.stop.map_or(String::new(), |s| s.to_string()),
            self.at
        )
    }
}

/// The ``u``, ``v`` columns of rows `lo..hi` of `table` as an `(n, 2)` array.
fn uv_rows<'py>(
    py: Python<'py>,
    path: &Path,
    table: &PointTable,
    lo: usize,
    hi: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let (Some(u), Some(v)) = (table.column("u"), table.column("v")) else {
        let has = if table.columns.is_empty() {
            "none".to_string()
        } else {
            table.columns.join(", ")
        };
        return Err(value_err(format!(
            "{}: no columns named u and v (its columns: {has}); the parameters come from such columns",
            path.display()
        )));
    };
    let flat: Vec<f64> = u[lo..hi]
        .iter()
        .zip(&v[lo..hi])
        .flat_map(|(&u, &v)| [u, v])
        .collect();
    array(py, flat, &[hi - lo, 2])
}

/// The up axis ``"x"``, ``"y"`` or ``"z"`` of ``points`` by the rule of
/// ``up="auto"`` (``scanfit mba --up auto``): the axis along which the points
/// are thinnest when they form a sheet (their 1st-99th percentile extent
/// under half the next smaller one), else ``"z"``.
///
/// Example::
///
///     >>> g = np.mgrid[0:10, 0:10].reshape(2, -1).T.astype(float)
///     >>> scanfit.up_axis(np.column_stack([g[:, 0], 0.1 * g[:, 1] % 0.3, g[:, 1]]))
///     'y'
#[pyfunction]
pub fn up_axis(py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    let p: Vec<Point3> = point_rows(points, "points")?;
    Ok(py.detach(|| UpAxis::automatic(&p)).name())
}

/// Registers `PointChunks` and `up_axis` in the native module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPointChunks>()?;
    m.add_function(wrap_pyfunction!(up_axis, m)?)?;
    Ok(())
}
