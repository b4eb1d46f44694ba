//! Base surfaces: the surfaces whose parameterization is transferred to the
//! points before the final fit.

pub mod coons;
pub mod coons_cloud;
pub mod coons_param;
mod plane;
mod projection;

pub use coons::{
    fit_boundary_curve, fit_boundary_curves, BoundaryCurve, BoundaryCurveConfig, BoundaryFit,
    CoonsPatch, Sides,
};
pub use coons_cloud::{coons_from_cloud, CoonsFromCloud, CoonsFromCloudConfig};
pub use coons_param::{coons_parameters, CoonsParamConfig, CoonsParameters, CoonsProjection};
pub use plane::{
    plane_frame, plane_parameters, FlatHull, PlaneAxes, PlaneExtents, PlaneFrame, PlaneMap,
    PlaneParameterization,
};
pub use projection::{
    choose_projection, choose_projection_from, fold_sample, PlaneMoments, Projection,
    ProjectionAxis, FOLD_MARGIN, FOLD_MIN_POINTS, FOLD_SAMPLE, FOLD_SEED,
};
pub mod turntable;
