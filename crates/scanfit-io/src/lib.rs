//! # scanfit-io
//!
//! File formats for scanfit: point files in (XYZ/CSV/TXT), curves and surfaces
//! out and back (JSON), points and meshes out (PLY, OBJ, XYZ), pictures out
//! (SVG, PNG). Every writer is atomic: it writes a temporary
//! file next to the target and renames it on success, so a failed run never
//! leaves a half-written file.

mod atomic;
mod error;
pub mod gltf;
pub mod iges;
pub mod json;
pub mod ply;
pub mod render;
pub mod step;
pub mod svg;
pub mod xyz;

pub use atomic::{write_all_atomic, write_atomic};
pub use error::{Error, Result};
pub use xyz::{read_points, PointTable};
