//! The virtual turntable parameterization of cylindrical point clouds
//! (`cylindrical-turntable-parameterization.txt`).

pub mod axis;
pub mod views;

pub use axis::{principal_axis, AxisChoice, CylinderFrame};
pub use views::{layer_polygon, turntable_views, View, ViewConfig};
