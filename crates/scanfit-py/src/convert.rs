//! numpy in, numpy out: the checks and conversions every binding shares,
//! and the mapping of the library's errors to `scanfit.ScanfitError`.
//!
//! Input arrays: any array-like of real numbers. `float64` arrays are read
//! in place (a C-contiguous one without an intermediate copy); `float32`
//! and integer arrays (and lists) are converted to `float64` by numpy,
//! which is exact. Complex, boolean, object and string arrays are refused
//! with a `TypeError`. A wrong shape, an empty array or a non-finite value
//! is a `ScanfitError` that says which argument and which row.

use numpy::ndarray::{Array, ArrayD, IxDyn};
use numpy::{
    AllowTypeChange, IntoPyArray, PyArrayDescrMethods, PyArrayLikeDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use scanfit::{Point3, Vector3};

pyo3::create_exception!(
    scanfit,
    ScanfitError,
    PyValueError,
    "An error of the scanfit library: bad input, a setting it refuses or a fit it cannot do.\n\n\
     A subclass of ValueError; the message says what is wrong, where (point index, file and line,\n\
     setting) and what to change."
);

/// The library's error as a Python `ScanfitError`.
pub fn err(e: scanfit::Error) -> PyErr {
    ScanfitError::new_err(e.to_string())
}

/// The io crate's error as a Python `ScanfitError`.
pub fn io_err(e: scanfit_io::Error) -> PyErr {
    ScanfitError::new_err(e.to_string())
}

/// A `ScanfitError` with `message`.
pub fn value_err(message: String) -> PyErr {
    ScanfitError::new_err(message)
}

/// Refuses arrays whose dtype is not a real number (numpy would turn
/// complex into real with a warning, and strings or objects into whatever
/// they parse to).
fn check_dtype(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<()> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        let kind = a.dtype().kind();
        if !matches!(kind, b'f' | b'i' | b'u') {
            let name = a.dtype().str().map(|s| s.to_string()).unwrap_or_default();
            return Err(PyTypeError::new_err(format!(
                "{what} must hold real numbers (float64, float32 or integers); got an array of dtype {name}"
            )));
        }
    }
    Ok(())
}

/// `obj` as a float64 array (see the module documentation).
pub fn float_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<PyArrayLikeDyn<'py, f64, AllowTypeChange>> {
    check_dtype(obj, what)?;
    obj.extract::<PyArrayLikeDyn<'py, f64, AllowTypeChange>>()
        .map_err(|e| {
            PyTypeError::new_err(format!(
                "{what} must be an array of real numbers: {}",
                e.value(obj.py())
            ))
        })
}

/// The shape of `a` as `(a, b, ...)` for messages.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Rows of an `(N, 3)` array of real numbers as points; an empty array, a
/// wrong shape or a NaN/infinite coordinate is a `ScanfitError` naming the
/// row (0-based).
pub fn points(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Point3>> {
    let a = float_array(obj, what)?;
    let shape = a.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(value_err(format!(
            "{what} must have shape (N, 3), one point per row; got shape {}",
            shape_text(&shape)
        )));
    }
    if shape[0] == 0 {
        return Err(value_err(format!(
            "{what} is empty (shape (0, 3)); give at least one point"
        )));
    }
    let view = a.as_array();
    // numpy's "contiguous" includes Fortran order; ndarray's slice is row-major only
    let pts: Vec<Point3> = match view.as_slice() {
        Some(s) => s
            .chunks_exact(3)
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect(),
        // not row-major (a slice with a step, Fortran order, a transposed view): read through the strides
        None => view
            .rows()
            .into_iter()
            .map(|r| Point3::new(r[0], r[1], r[2]))
            .collect(),
    };
    if let Some((i, p)) = pts
        .iter()
        .enumerate()
        .find(|(_, p)| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
    {
        return Err(value_err(format!(
            "{what}: row {i} has a non-finite coordinate ({}, {}, {}); remove or fix it (e.g. points[np.isfinite(points).all(axis=1)])",
            p.x, p.y, p.z
        )));
    }
    Ok(pts)
}

/// A one-dimensional array of `n` finite numbers (`n = None`: any length).
pub fn values(obj: &Bound<'_, PyAny>, what: &str, n: Option<usize>) -> PyResult<Vec<f64>> {
    let a = float_array(obj, what)?;
    let shape = a.shape().to_vec();
    if shape.len() != 1 {
        return Err(value_err(format!(
            "{what} must be one-dimensional; got shape {}",
            shape_text(&shape)
        )));
    }
    if let Some(n) = n {
        if shape[0] != n {
            return Err(value_err(format!(
                "{what} has {} values for {n} points; give one per point",
                shape[0]
            )));
        }
    }
    let v: Vec<f64> = a.as_array().iter().copied().collect();
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(value_err(format!(
            "{what}: value {i} is {}; give finite numbers",
            v[i]
        )));
    }
    Ok(v)
}

/// The columns of an `(n, 2)` array of finite parameters `(u, v)`.
pub fn uv_columns(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<(Vec<f64>, Vec<f64>)> {
    let a = float_array(obj, "uv")?;
    let shape = a.shape().to_vec();
    if shape != [n, 2] {
        return Err(value_err(format!(
            "uv must have shape ({n}, 2), one (u, v) per point; got shape {}",
            shape_text(&shape)
        )));
    }
    let view = a.as_array();
    let (mut u, mut v) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for (i, r) in view.rows().into_iter().enumerate() {
        if !(r[0].is_finite() && r[1].is_finite()) {
            return Err(value_err(format!(
                "uv: row {i} is ({}, {}); give finite parameters",
                r[0], r[1]
            )));
        }
        u.push(r[0]);
        v.push(r[1]);
    }
    Ok((u, v))
}

/// Parameter arrays of any (equal) shape, flattened, with their shape; a
/// scalar is shape `()`.
pub fn parameters(args: &[(&Bound<'_, PyAny>, &str)]) -> PyResult<(Vec<Vec<f64>>, Vec<usize>)> {
    let mut out = Vec::with_capacity(args.len());
    let mut shape: Option<Vec<usize>> = None;
    for (obj, what) in args {
        let a = float_array(obj, what)?;
        let s = a.shape().to_vec();
        match &shape {
            Some(first) if *first != s => {
                return Err(value_err(format!(
                    "{} has shape {} but {what} has shape {}; give arrays of the same shape (np.meshgrid makes a grid)",
                    args[0].1,
                    shape_text(first),
                    shape_text(&s)
                )))
            }
            _ => shape = Some(s),
        }
        let v: Vec<f64> = a.as_array().iter().copied().collect();
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(value_err(format!(
                "{what}: value {i} (flat index) is {}; give finite parameters",
                v[i]
            )));
        }
        out.push(v);
    }
    Ok((out, shape.unwrap_or_default()))
}

/// A `(len, 3)` float64 array of points (one copy into numpy's memory).
pub fn points_array<'py>(py: Python<'py>, pts: &[Point3]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = pts.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    rows3(py, flat, &[pts.len()])
}

/// A `(len, 3)` float64 array of vectors.
pub fn vectors_array<'py>(py: Python<'py>, vs: &[Vector3]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = vs.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    rows3(py, flat, &[vs.len()])
}

/// `flat` (3 numbers per item) as an array of shape `lead + (3,)`: the
/// vector moves into numpy without a copy.
pub fn rows3<'py>(py: Python<'py>, flat: Vec<f64>, lead: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    let mut shape = lead.to_vec();
    shape.push(3);
    array(py, flat, &shape)
}

/// `flat` as an array of `shape` (moved, not copied).
pub fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    flat: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let a: ArrayD<T> = Array::from_shape_vec(IxDyn(shape), flat)
        .map_err(|e| value_err(format!("internal: array of shape {shape:?}: {e}")))?;
    Ok(a.into_pyarray(py).into_any())
}

/// A one-dimensional array (moved, not copied).
pub fn vec1<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyAny> {
    v.into_pyarray(py).into_any()
}

/// `(u, v)` pairs as two arrays.
pub fn uv_arrays<'py>(py: Python<'py>, uv: &[[f64; 2]]) -> (Bound<'py, PyAny>, Bound<'py, PyAny>) {
    (
        vec1(py, uv.iter().map(|t| t[0]).collect::<Vec<_>>()),
        vec1(py, uv.iter().map(|t| t[1]).collect::<Vec<_>>()),
    )
}

/// A pair of positive counts from an int or a 2-sequence.
pub fn pair(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(usize, usize)> {
    if let Ok(n) = obj.extract::<usize>() {
        return Ok((n, n));
    }
    obj.extract::<(usize, usize)>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what} must be a non-negative int or a pair of them, e.g. (16, 16)"
        ))
    })
}

/// A 3-vector from a 3-sequence of numbers (a tuple, list or numpy array).
pub fn vec3(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector3> {
    let three = obj
        .extract::<(f64, f64, f64)>()
        .ok()
        .or_else(|| match obj.extract::<Vec<f64>>() {
            Ok(v) if v.len() == 3 => Some((v[0], v[1], v[2])),
            _ => None,
        });
    let (x, y, z) = three.ok_or_else(|| {
        PyTypeError::new_err(format!("{what} must be three numbers, e.g. (0, 0, 1)"))
    })?;
    if !(x.is_finite() && y.is_finite() && z.is_finite()) {
        return Err(value_err(format!(
            "{what} = ({x}, {y}, {z}) has a non-finite value"
        )));
    }
    Ok(Vector3::new(x, y, z))
}

/// An error for an unknown choice of a string option.
pub fn bad_choice(what: &str, got: &str, allowed: &[&str]) -> PyErr {
    value_err(format!(
        "{what} = {got:?} is not one of {}",
        allowed
            .iter()
            .map(|a| format!("{a:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// `x` with `digits` significant digits, like Python's `%g` (for reprs).
pub fn g(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let digits = digits.max(1);
    let mag = x.abs().log10().floor() as i32;
    if (-4..digits as i32).contains(&mag) {
        let decimals = (digits as i32 - 1 - mag).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.prec$e}", prec = digits - 1)
    }
}
