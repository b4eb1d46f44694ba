//! # scanfit
//!
//! B-spline curve and surface fitting for measured points (reverse engineering).
//!
//! The library holds geometry and algorithms only: no file formats, no printing.
//! Every algorithm is a config struct with documented defaults (citing the paper
//! equation it follows) and a function that takes data + config and returns a
//! result struct with diagnostics.
//!
//! Citations are by key, `[PDE23] eq. 14`: the keys are listed with full
//! references in `docs/references.md` of the repository.
//!
//! * [`bspline`]: knot vectors, basis functions and derivatives, curves and
//!   tensor-product surfaces (rational weights carried), knot insertion/refinement.
//! * [`base`]: base surfaces that give points their parameters (best-fit plane,
//!   bilinearly blended Coons patches from boundary curves).
//! * [`pde`]: thin-plate PDE deformation surfaces on a Coons patch ([PDE23]).
//! * [`param`]: the seven curve parameterization methods of [CURVE12] and
//!   knot placement.
//! * [`fit`]: curve interpolation (open, with end tangents, closed/periodic) and
//!   least-squares approximation with optional bending-energy smoothing, on banded
//!   solvers.
//! * [`cloud`]: point clouds with named attributes and KD-tree neighbour
//!   queries, normals, hidden point removal, boundary loops, corners.
//! * [`mba`]: multilevel B-spline approximation of 2.5D data (Lee, Wolberg &
//!   Shin 1997) and [MBA18]'s projection adjustment of control points.
//! * [`metrics`]: surface error measures and parameterization quality;
//!   [`distribution`]: percentiles and histograms of such measures.
//! * [`project`]: point inversion (orthogonal projection onto surfaces).
//! * [`pipeline`]: every pipeline of the command line as one call (config,
//!   progress, report), e.g. [`pipeline::reconstruct`] (a segmented cloud to
//!   patches that share their edge curves), and the one surface assessment
//!   [`pipeline::SurfaceQuality`].
//! * [`quality`]: per-curve quality report (deviation, curvature, loops, length).
//! * [`network`]: the patch network of a segmented cloud (labels, shared
//!   corners and edges, edge curves, per-patch surfaces with exact boundaries).
//! * [`topology`]: multi-patch models: vertices, shared edge curves, faces
//!   and their checks (gaps along edges, enclosed volume).
//! * [`surface`]: capability traits, [`surface::ParametricSurface`] (B-spline,
//!   Coons, PDE) and [`surface::ParametricCurve`].
//! * [`spatial`]: the one KD-tree every neighbour query uses.
//! * [`eigen3`]: the closed-form symmetric 3 x 3 eigen solver of the normals.
//! * [`par`]: the thread-count knob and the deterministic parallel sums.

pub mod base;
pub mod bspline;
pub mod centring;
pub mod cloud;
pub mod distribution;
pub mod eigen3;
mod error;
pub mod fit;
mod geom;
pub mod mba;
pub mod metrics;
pub mod network;
pub mod par;
pub mod param;
pub mod pde;
pub mod pipeline;
pub mod progress;
pub mod project;
pub mod quality;
pub mod sampling;
pub mod spatial;
pub mod surface;
pub mod testdata;
pub mod topology;
pub mod trim;
pub mod up_axis;
pub mod wire;

pub use cloud::PointCloud;
pub use error::{Error, Result};
pub use geom::{pca, validate_points, CovarianceSums, Pca, Point3, Vector3};
