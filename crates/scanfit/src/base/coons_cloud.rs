//! From a patch of points to its Coons base surface: boundary loop (alpha
//! shape, [PDE23] §4.1), corners ([COONS19] eqs. 10-12 or [PDE23]'s
//! three-point curvature), the loop split into 4 (or 3) sides, one B-spline
//! per side ([PDE23] §4.2), and the bilinearly blended Coons patch (eq. 16 /
//! eq. 1) on them.
//!
//! The sides run along the outer loop, which is counter-clockwise about the
//! plane normal of the points, so `S_u x S_v` of the patch points the same way
//! as that normal.

use super::coons::{fit_boundary_curves, BoundaryCurve, BoundaryCurveConfig, CoonsPatch};
use crate::cloud::boundary::{boundary_loops, Boundary, BoundaryConfig};
use crate::cloud::corners::{
    corner_values, find_corners, split_at_corners, CornerConfig, CornerCriterion, Corners,
};
use crate::{Error, Point3, Result};

/// Settings of [`coons_from_cloud`].
#[derive(Debug, Clone, PartialEq)]
pub struct CoonsFromCloudConfig {
    /// Alpha shape of the boundary (default: alpha = 2.5 x median Delaunay edge).
    pub boundary: BoundaryConfig,
    /// Corner detection; `count` is the number of sides, 4 (default) or 3.
    pub corners: CornerConfig,
    /// Loop positions of the corners, in loop order, instead of detecting them.
    pub corner_positions: Option<Vec<usize>>,
    /// Boundary curves (default: cubic, end-pinned least squares).
    pub curves: BoundaryCurveConfig,
    /// A detected corner whose turning angle (eq. 12, at the corner
    /// criterion's neighbour offset) exceeds this is not a corner: the loop
    /// has fewer corners than asked and the run stops with an error.
    /// Radians; default 160 degrees (a straight run is 180).
    pub max_corner_angle: f64,
}

impl Default for CoonsFromCloudConfig {
    fn default() -> Self {
        Self {
            boundary: BoundaryConfig::default(),
            corners: CornerConfig::default(),
            corner_positions: None,
            curves: BoundaryCurveConfig::default(),
            max_corner_angle: 160f64.to_radians(),
        }
    }
}

/// The Coons base surface of a patch and everything found on the way.
#[derive(Debug, Clone)]
pub struct CoonsFromCloud {
    /// The patch.
    pub patch: CoonsPatch,
    /// Boundary loops of the points.
    pub boundary: Boundary,
    /// Corners (positions in the outer loop) and sides.
    pub corners: Corners,
    /// Turning angle (eq. 12, radians) at each corner.
    pub corner_angles: Vec<f64>,
    /// The points of each side, in loop order, corner to corner.
    pub side_points: Vec<Vec<Point3>>,
    /// The fitted curve of each side (in loop order, before orientation).
    pub curves: Vec<BoundaryCurve>,
}

/// Builds the Coons base surface of `points` (see the module documentation).
///
/// Errors: everything [`boundary_loops`] and [`find_corners`] refuse; corner
/// count other than 3 or 4; a detected corner flatter than
/// `max_corner_angle` (the boundary has fewer corners than asked: give the
/// corners, ask for 3 sides, or raise the limit).
pub fn coons_from_cloud(points: &[Point3], cfg: &CoonsFromCloudConfig) -> Result<CoonsFromCloud> {
    let count = cfg
        .corner_positions
        .as_ref()
        .map_or(cfg.corners.count, Vec::len);
    if !(3..=4).contains(&count) {
        return Err(Error::InvalidInput(format!(
            "{count} corners asked for; a Coons patch has 4 sides (or 3, one degenerate)"
        )));
    }
    let boundary = boundary_loops(points, &cfg.boundary)?;
    let outer = boundary.outer_loop().to_vec();
    let loop_points: Vec<Point3> = outer.iter().map(|&i| points[i]).collect();
    let offset_default = ((loop_points.len() as f64 / 100.0).round() as usize).max(1);
    let corners = match &cfg.corner_positions {
        Some(c) => {
            if let Some(&bad) = c.iter().find(|&&k| k >= outer.len()) {
                return Err(Error::InvalidInput(format!(
                    "corner position {bad} is beyond the outer loop, which has {} points (positions 0..{})",
                    outer.len(),
                    outer.len().saturating_sub(1)
                )));
            }
            let sides = split_at_corners(outer.len(), c)?;
            let offset = cfg.corners.offset.unwrap_or(offset_default);
            let values = corner_values(&loop_points, cfg.corners.criterion, offset)?;
            Corners {
                corners: c.clone(),
                sides,
                values,
                offset,
            }
        }
        None => find_corners(
            &loop_points,
            &CornerConfig {
                count,
                ..cfg.corners
            },
        )?,
    };
    let angles = match cfg.corners.criterion {
        CornerCriterion::TurningAngle => corners.values.clone(),
        CornerCriterion::ThreePointCurvature => {
            corner_values(&loop_points, CornerCriterion::TurningAngle, corners.offset)?
        }
    };
    let corner_angles: Vec<f64> = corners.corners.iter().map(|&k| angles[k]).collect();
    if cfg.corner_positions.is_none() {
        let sharp = corner_angles
            .iter()
            .filter(|&&a| a <= cfg.max_corner_angle)
            .count();
        if sharp < count {
            let flat = corner_angles
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            return Err(Error::InvalidInput(format!(
                "the boundary ({} points) has only {sharp} corner(s) sharper than {:.0} degrees but {count} were asked for (the flattest pick turns by only {:.1} degrees); give the corners' loop positions, ask for 3 sides, or raise the angle limit",
                outer.len(),
                cfg.max_corner_angle.to_degrees(),
                180.0 - flat.to_degrees()
            )));
        }
    }
    let side_points: Vec<Vec<Point3>> = corners
        .sides
        .iter()
        .map(|s| s.iter().map(|&k| loop_points[k]).collect())
        .collect();
    let curves = fit_boundary_curves(&side_points, &cfg.curves)?;
    let loop_curves: Vec<_> = curves.iter().map(|c| c.curve.clone()).collect();
    let patch = CoonsPatch::from_loop(&loop_curves)?;
    Ok(CoonsFromCloud {
        patch,
        boundary,
        corners,
        corner_angles,
        side_points,
        curves,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bent 2 x 1 panel sampled on a jittered grid.
    fn panel(n: usize) -> Vec<Point3> {
        let mut pts = Vec::new();
        for i in 0..=2 * n {
            for j in 0..=n {
                let jit = 0.2 * (((i * 31 + j * 17) % 13) as f64 / 13.0 - 0.5);
                let (x, y) = (
                    (i as f64 + if i > 0 && i < 2 * n { jit } else { 0.0 }) / n as f64,
                    (j as f64 + if j > 0 && j < n { jit } else { 0.0 }) / n as f64,
                );
                pts.push(Point3::new(x, y, 0.2 * (x * 1.5).sin() * y));
            }
        }
        pts
    }

    #[test]
    fn panel_corners_and_patch() {
        let pts = panel(30);
        let r = coons_from_cloud(&pts, &CoonsFromCloudConfig::default()).unwrap();
        let mut got: Vec<[i64; 2]> = r
            .patch
            .corners()
            .iter()
            .map(|p| [(p.x * 10.0).round() as i64, (p.y * 10.0).round() as i64])
            .collect();
        got.sort();
        assert_eq!(got, vec![[0, 0], [0, 10], [20, 0], [20, 10]]);
        for a in &r.corner_angles {
            assert!((a.to_degrees() - 90.0).abs() < 15.0, "{}", a.to_degrees());
        }
        // the patch normal agrees with the boundary plane's normal
        let (_, su, sv) = r.patch.derivatives(0.5, 0.5);
        assert!(su.cross(&sv).dot(&r.boundary.plane.normal) > 0.0);
        // the interior is close to the points (the bend is linear in y)
        let c = r.patch.point(0.5, 0.5);
        assert!((c.z - 0.2 * (1.5f64).sin() * 0.5).abs() < 0.02, "{c}");
    }

    #[test]
    fn a_disk_has_no_four_corners() {
        let mut pts = Vec::new();
        for r in 1..=20 {
            let k = 6 * r;
            for a in 0..k {
                let t = a as f64 / k as f64 * std::f64::consts::TAU;
                pts.push(Point3::new(r as f64 * t.cos(), r as f64 * t.sin(), 0.0));
            }
        }
        pts.push(Point3::origin());
        let e = coons_from_cloud(&pts, &CoonsFromCloudConfig::default()).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("sharper than 160 degrees") && m.contains("4 were asked"),
            "{m}"
        );
    }
}
