//! Projection of points onto surfaces: orthogonal projection (point inversion)
//! and [COONS19]'s grid iteration; and of points onto point clouds:
//! directed projection ([Aza04]).

mod directed;
mod grid_iteration;
mod inversion;
pub(crate) mod power_form;

pub use directed::{
    project_directed, project_directed_batch, DirectedConfig, Neighbourhood, Projected,
    WeightFactor,
};
pub use grid_iteration::{grid_iteration, GridIterationConfig};
pub use inversion::{
    Inversion, InversionConfig, InversionWorkspace, NearInversion, SurfaceInverter,
};
