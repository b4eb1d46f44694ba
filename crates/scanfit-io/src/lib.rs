//! # scanfit-io
//!
//! File formats for scanfit: point files in (PLY, PCD, LAS/LAZ, XYZ/CSV/TXT,
//! and meshes as clouds: STL, OBJ, PLY faces;
//! [`read_cloud`]) and out ([`write_cloud`]), curves and surfaces
//! out and back (JSON), points and meshes out (PLY, OBJ, XYZ), pictures out
//! (SVG, PNG). Every writer is atomic: it writes a temporary
//! file next to the target and renames it on success, so a failed run never
//! leaves a half-written file.

mod atomic;
mod binary;
pub mod chunks;
pub mod cloud;
mod error;
pub mod fuzz;
pub mod gltf;
pub mod iges;
pub mod json;
pub mod json_trim;
mod las;
pub mod laz14;
mod mesh;
pub mod model;
mod obj;
mod pcd;
pub mod ply;
mod ply_read;
pub mod render;
pub mod source;
pub mod step;
pub mod step_shell;
mod stl;
pub mod svg;
pub mod table;
pub mod units;
pub mod xyz;

pub use atomic::{check_paths, recover, write_all_atomic, write_atomic};
pub use cloud::{cloud_bytes, parse_cloud, read_cloud, write_cloud, WriteFormat};
pub use error::{Error, Result};
pub use table::{Format, NonFinite, Origin, PointTable, ReadOptions, DROP_ADVICE, FORMAT_ADVICE};
pub use xyz::read_points;
