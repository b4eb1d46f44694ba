//! The border of each patch and what lies across it (issue 15, item 2).
//!
//! Each patch's boundary is the outer loop of its alpha shape (PDE paper
//! §4.1, [`boundary_loops`]). Every loop point is then asked, through the
//! KD-tree of all labelled points, which other patch has a point within the
//! contact radius (a few spacings): the nearest one is the patch across the
//! border there, none means the cloud's free boundary. Points of patch A with
//! a neighbour of patch B within the radius are the A-B interface points;
//! A and B are adjacent when there are any.

use rayon::prelude::*;

use crate::cloud::boundary::{boundary_loops, BoundaryConfig};
use crate::{Error, Point3, PointCloud, Result};

/// A patch's outer boundary loop, with the patch across each loop point.
#[derive(Debug, Clone, PartialEq)]
pub struct Border {
    /// Indices (into the labelled cloud) of the loop points, in loop order
    /// (counter-clockwise in the patch's best-fit plane), first not repeated.
    pub points: Vec<usize>,
    /// For each loop point, the nearest other patch within the contact
    /// radius (`None`: free boundary).
    pub across: Vec<Option<usize>>,
    /// The patch's point spacing (median Delaunay edge of its projection).
    pub spacing: f64,
}

/// Loops of a patch whose area is below this fraction of the outer loop's
/// are alpha-shape noise (a missing point or two), not holes.
const HOLE_AREA_FRACTION: f64 = 1e-3;

/// The outer boundary loop of every patch (in parallel). `members[k]` are
/// the indices into `points` of patch `k`, `ids[k]` its label (for errors).
///
/// Errors name the patch: a patch whose alpha shape has more than one loop
/// of real size (a hole, or pieces apart) is not a topological disk.
pub fn patch_loops(
    points: &[Point3],
    members: &[Vec<usize>],
    ids: &[i64],
    cfg: &BoundaryConfig,
) -> Result<Vec<(Vec<usize>, f64)>> {
    members
        .par_iter()
        .zip(ids)
        .map(|(m, &id)| {
            let pts: Vec<Point3> = m.iter().map(|&i| points[i]).collect();
            let b = boundary_loops(&pts, cfg).map_err(|e| {
                Error::InvalidInput(format!("patch {id}: its boundary loop: {e}"))
            })?;
            let outer = b.areas.get(b.outer).copied().unwrap_or(0.0).abs();
            let real = b
                .areas
                .iter()
                .filter(|a| a.abs() > HOLE_AREA_FRACTION * outer)
                .count();
            if real != 1 {
                let holes = b.areas.iter().filter(|&&a| a < 0.0 && a.abs() > HOLE_AREA_FRACTION * outer).count();
                let what = if holes > 0 {
                    format!("{holes} hole(s) inside it")
                } else {
                    format!("{real} separate pieces")
                };
                return Err(Error::InvalidInput(format!(
                    "patch {id} is not a topological disk: its alpha shape has {} boundary loops ({what}); every patch must be one piece without holes: relabel it as separate patches, or fill the hole",
                    real
                )));
            }
            let lp: Vec<usize> = b.outer_loop().iter().map(|&i| m[i]).collect();
            Ok((lp, b.spacing))
        })
        .collect()
}

/// For every loop point of every patch, the nearest point of another patch
/// within `radius` (through the KD-tree of `cloud`, whose point `i` belongs
/// to patch `patch_of[i]`).
pub fn across(
    cloud: &PointCloud,
    patch_of: &[usize],
    loops: &[(Vec<usize>, f64)],
    radius: f64,
) -> Result<Vec<Border>> {
    loops
        .par_iter()
        .enumerate()
        .map(|(k, (lp, spacing))| {
            let across = lp
                .iter()
                .map(|&i| {
                    let near = cloud.within(&cloud.points()[i], radius)?;
                    Ok(near
                        .iter()
                        .find(|n| patch_of[n.index] != k)
                        .map(|n| patch_of[n.index]))
                })
                .collect::<Result<Vec<_>>>()?;
            Ok(Border {
                points: lp.clone(),
                across,
                spacing: *spacing,
            })
        })
        .collect()
}
