//! Every pipeline of the command line as one library call.
//!
//! The CLI, the Python package and any other front (a multi-patch driver, a
//! distributed run) call these functions and only parse, read, print and
//! write around them. Each pipeline module follows the same conventions:
//!
//! * **`XxxConfig`**: a `#[non_exhaustive]` struct with `Default`, every field
//!   documented with its default and the paper equation or section it comes
//!   from. Build one with `XxxConfig::default()` and set the fields you need
//!   (`#[non_exhaustive]` forbids struct literals outside the crate, so new
//!   settings can be added without breaking callers).
//! * **`run(input, &config, &dyn Progress) -> Result<XxxReport>`**: the one
//!   entry point. `input` is the data (a [`PointCloud`](crate::PointCloud),
//!   points, or points with attributes); the function validates it and the
//!   config and returns a typed [`Error`](crate::Error) that says what is
//!   wrong and where, never panics. It reports its stages and steps to a
//!   [`Progress`](crate::progress::Progress) (pass
//!   [`NoProgress`](crate::progress::NoProgress) when nobody watches) and
//!   never prints.
//! * **`XxxReport`**: a `#[non_exhaustive]` struct holding the surface or
//!   curve, the parameters of the points, the quality assessment (for
//!   surfaces the one [`SurfaceQuality`](assess::SurfaceQuality) of
//!   [`assess`], measured in both directions) and the pipeline's
//!   diagnostics (per-level tables, correction rounds, timings, notes).
//!
//! Modules:
//!
//! * [`assess`]: the surface assessment every surface pipeline ends with.
//! * [`assess_trimmed`]: its surface-to-points half again over a trimmed
//!   face.
//! * [`cloud`]: the point-cloud tools (info, normals, hidden point removal,
//!   boundary and corners).
//! * [`coons`]: one patch to a surface by the Coons paper (B-spline) or the
//!   PDE paper (thin-plate deformation).
//! * [`curve`]: curve interpolation / least squares and the comparison of
//!   the curve paper's parameterizations (`scanfit curve fit|compare`).
//! * [`mba`]: multilevel B-spline approximation (`scanfit mba`), optionally
//!   with the MBA paper's projection adjustment, with its per-level table.
//! * [`measure`]: what `scanfit report` measures for a surface and points
//!   (the assessment of their projections, percentiles, histogram).
//! * [`measure_model`]: what `scanfit report` measures for a multi-patch
//!   model and points (per patch eq. 15 and orthogonal errors, per edge gap
//!   and normal angle, totals).
//! * [`reconstruct`]: a segmented cloud to a whole object, patches that
//!   share their edge curves (`scanfit reconstruct`, PDE paper section 4).
//! * [`regularize`]: the safe defaults of the least-squares fits (net from
//!   the point density, thin-plate weight scaled to the data).
//! * [`surface_fit`]: least-squares surface through scattered points
//!   (`scanfit fit`): parameters from the best-fit plane or given
//!   attributes, optional Hoschek parameter correction.
//! * [`trim`]: the trimmed face of a fitted surface: its boundary loops
//!   (in the plane the parameters were made in), the fallback to the
//!   rectangle, and the face measured again.
//! * [`turntable`]: cylinder-like clouds by the virtual turntable.

pub mod assess;
pub mod assess_trimmed;
pub mod cloud;
pub mod coons;
pub mod curve;
pub mod mba;
pub mod measure;
pub mod measure_model;
pub mod reconstruct;
pub mod regularize;
pub mod segment;
pub mod stream;
pub mod surface_fit;
pub mod trim;
pub mod turntable;

pub use assess::{
    assess_projected, assess_surface, AssessConfig, Assessment, Extent, SampleDistances,
    SurfaceQuality,
};
