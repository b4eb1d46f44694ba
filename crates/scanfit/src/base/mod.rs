//! Base surfaces: the surfaces whose parameterization is transferred to the
//! points before the final fit.

mod plane;

pub use plane::{plane_parameters, PlaneParameterization};
pub mod turntable;
