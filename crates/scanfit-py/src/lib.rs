//! # scanfit-py
//!
//! The Python package `scanfit`: PyO3 + numpy bindings over the scanfit
//! library's pipelines (`scanfit::pipeline`) and the scanfit-io readers and
//! writers, built by maturin (`pip install ./crates/scanfit-py`).
//!
//! The layer converts and documents; every computation is the library's.
//! numpy arrays come in as `(N, 3)` float64 (float32 and integers are
//! converted exactly; other dtypes are a `TypeError`) and go out without a
//! copy where the library hands over a vector; the GIL is released while
//! the library computes. Errors are `scanfit.ScanfitError` (a `ValueError`)
//! with the library's message.
//!
//! Modules: [`convert`] (arrays, errors), [`cloud`] (`Cloud`, reading and
//! writing, the cloud tools), [`geometry`] (`Surface`, `Curve`),
//! [`surfaces`] (`fit_surface`, `mba`, `coons`, `turntable`), [`curves`]
//! (`fit_curve`, `compare_curves`), [`reconstruct`] (`reconstruct`,
//! `Model`), [`report`] (reports as dicts).

use pyo3::prelude::*;

pub mod chunks;
pub mod cloud;
pub mod convert;
pub mod curves;
pub mod fit_sums;
pub mod geometry;
pub mod reconstruct;
pub mod report;
pub mod sums;
pub mod surfaces;

/// The native module `scanfit._scanfit`; the package `scanfit` re-exports it.
#[pymodule]
fn _scanfit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ScanfitError", py.get_type::<convert::ScanfitError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<cloud::PyCloud>()?;
    m.add_class::<geometry::PySurface>()?;
    m.add_class::<geometry::PyCurve>()?;
    m.add_class::<reconstruct::PyModel>()?;
    m.add_function(wrap_pyfunction!(cloud::read_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(cloud::write_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(cloud::normals, m)?)?;
    m.add_function(wrap_pyfunction!(cloud::hpr, m)?)?;
    m.add_function(wrap_pyfunction!(cloud::boundary, m)?)?;
    m.add_function(wrap_pyfunction!(surfaces::fit_surface, m)?)?;
    m.add_function(wrap_pyfunction!(surfaces::mba, m)?)?;
    m.add_function(wrap_pyfunction!(surfaces::coons, m)?)?;
    m.add_function(wrap_pyfunction!(surfaces::turntable, m)?)?;
    m.add_function(wrap_pyfunction!(curves::fit_curve, m)?)?;
    m.add_function(wrap_pyfunction!(curves::compare_curves, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct::reconstruct, m)?)?;
    sums::register(m)?;
    fit_sums::register(m)?;
    chunks::register(m)?;
    Ok(())
}
