//! The B-spline kernel: knot vectors, basis functions, curves and surfaces,
//! and the operations on them ([`ops`]: Greville abscissae, knot union and
//! compatibility, refinement to given knots, reversal).

mod basis;
mod clamp;
mod curve;
mod knots;
pub mod ops;
mod surface;
mod tessellate;

pub use basis::{basis_funs, single_basis_ders, BasisWorkspace};
pub use curve::Curve;
pub use knots::KnotVector;
pub use surface::{Direction, Surface};
pub use tessellate::{tessellate, Mesh};
