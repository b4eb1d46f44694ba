//! Projection of points onto surfaces: orthogonal projection (point inversion)
//! and the Coons paper's grid iteration.

mod grid_iteration;
mod inversion;

pub use grid_iteration::{grid_iteration, GridIterationConfig};
pub use inversion::{Inversion, InversionConfig, InversionWorkspace, SurfaceInverter};
