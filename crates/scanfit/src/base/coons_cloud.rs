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
    find_corners, split_at_corners, values_for, CornerConfig, CornerCriterion, Corners,
};
use std::f64::consts::PI;

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
    /// A detected corner whose angle (eq. 12, at the corner criterion's
    /// neighbours) exceeds this is not clearly a corner. Radians; default
    /// 150 degrees, i.e. the outline must turn by at least 30 degrees there
    /// (a straight run is 180; the four best picks on a face's rounded
    /// outline turn by 3 to 23 degrees, a rectangle's corners by 90).
    pub max_corner_angle: f64,
    /// Detected corners crowd into one part of the loop when one side spans
    /// more than this share of the loop's length (default 0.6; a 15:1
    /// rectangle's long sides span 47%, four picks within 8% of a rounded
    /// outline leave one side of 92%).
    pub max_side_share: f64,
    /// Build the patch on detected corners that are not clearly corners
    /// (flat or crowded) instead of stopping with an error (default false).
    pub force_corners: bool,
}

impl Default for CoonsFromCloudConfig {
    fn default() -> Self {
        Self {
            boundary: BoundaryConfig::default(),
            corners: CornerConfig::default(),
            corner_positions: None,
            curves: BoundaryCurveConfig::default(),
            max_corner_angle: 150f64.to_radians(),
            max_side_share: 0.6,
            force_corners: false,
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
    /// The angle of eq. 12 (radians) at each corner: `pi` on a straight run.
    pub corner_angles: Vec<f64>,
    /// The strength of each corner: how far the outline turns there, `pi -`
    /// its angle (radians; `pi / 2` at a rectangle's corner).
    pub corner_strengths: Vec<f64>,
    /// Each side's share of the loop's length.
    pub side_shares: Vec<f64>,
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
            let (values, offset) = values_for(&loop_points, &cfg.corners)?;
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
            let turning = CornerConfig {
                criterion: CornerCriterion::TurningAngle,
                ..cfg.corners
            };
            values_for(&loop_points, &turning)?.0
        }
    };
    let corner_angles: Vec<f64> = corners.corners.iter().map(|&k| angles[k]).collect();
    let corner_strengths: Vec<f64> = corner_angles.iter().map(|a| PI - a).collect();
    let side_shares = side_shares(&loop_points, &corners.sides);
    if cfg.corner_positions.is_none() && !cfg.force_corners {
        check_corners(cfg, outer.len(), &corner_strengths, &side_shares)?;
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
        corner_strengths,
        side_shares,
        side_points,
        curves,
    })
}

/// Each side's share of the closed loop's length.
fn side_shares(loop_points: &[Point3], sides: &[Vec<usize>]) -> Vec<f64> {
    let n = loop_points.len();
    let len = |s: &[usize]| -> f64 {
        s.windows(2)
            .map(|w| (loop_points[w[1]] - loop_points[w[0]]).norm())
            .sum()
    };
    let total: f64 = (0..n)
        .map(|i| (loop_points[(i + 1) % n] - loop_points[i]).norm())
        .sum();
    sides
        .iter()
        .map(|s| len(s) / total.max(f64::MIN_POSITIVE))
        .collect()
}

/// Refuses detected corners that are not clearly corners: too flat (turning
/// by less than `pi - max_corner_angle`) or crowded (one side longer than
/// `max_side_share` of the loop).
fn check_corners(
    cfg: &CoonsFromCloudConfig,
    loop_len: usize,
    strengths: &[f64],
    shares: &[f64],
) -> Result<()> {
    let min_turn = PI - cfg.max_corner_angle;
    let weak = strengths.iter().filter(|&&s| s < min_turn).count();
    let longest = shares.iter().copied().fold(0.0, f64::max);
    if weak == 0 && longest <= cfg.max_side_share {
        return Ok(());
    }
    let turns: Vec<String> = strengths
        .iter()
        .map(|s| format!("{:.0}", s.to_degrees()))
        .collect();
    let why = if weak > 0 {
        format!(
            "{weak} of them turn by less than {:.0} degrees",
            min_turn.to_degrees()
        )
    } else {
        format!(
            "they crowd into {:.0}% of the loop (one side spans {:.0}% of it, more than {:.0}%)",
            100.0 * (1.0 - longest),
            100.0 * longest,
            100.0 * cfg.max_side_share
        )
    };
    Err(Error::InvalidSetting {
        setting: "corners",
        value: format!("turning angles {} degrees", turns.join(", ")),
        hint: format!(
            "the {} strongest corners of the boundary ({loop_len} points) are not clearly corners: {why}. The outline looks rounded, and a patch on these corners would fold; give the corners' loop positions, or split the cloud into four-sided patches (a layout), or force the detected corners",
            strengths.len()
        ),
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
            m.contains("not clearly corners") && m.contains("turn by less than 30 degrees"),
            "{m}"
        );
    }
}
