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
    /// Whether each corner turns outward (convex, as a patch corner must):
    /// the loop's signed area over the corner's neighbourhood (the
    /// criterion's offset either side) is positive about the plane normal.
    /// `false` marks a notch the outline bites inward.
    pub corner_convex: Vec<bool>,
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
    if let Some((a, b)) = pinch(&outer) {
        return Err(ragged(
            &boundary,
            format!(
                "the outer boundary loop ({} points) touches itself at input point {} (loop positions {a} and {b}): two parts of the cloud meet at one point",
                outer.len(),
                outer[a]
            ),
        ));
    }
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
    let normal = boundary.plane.normal;
    let corner_convex: Vec<bool> = corners
        .corners
        .iter()
        .map(|&k| turns_outward(&loop_points, k, corners.offset, &normal))
        .collect();
    if cfg.corner_positions.is_none() && !cfg.force_corners {
        let found = Found {
            loop_len: outer.len(),
            positions: &corners.corners,
            strengths: &corner_strengths,
            convex: &corner_convex,
            shares: &side_shares,
            alpha: (boundary.alpha, boundary.spacing),
        };
        check_corners(cfg, &found)?;
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
        corner_convex,
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

/// Whether the closed loop turns outward (counter-clockwise about
/// `normal`) at position `k`: the signed area of the polygon
/// `P[k-m] .. P[k+m]` (closed by the chord) is positive. A convex corner of
/// a counter-clockwise outer loop turns outward; a notch turns inward.
fn turns_outward(points: &[Point3], k: usize, m: usize, normal: &crate::Vector3) -> bool {
    let n = points.len();
    let m = m.clamp(1, (n.saturating_sub(1) / 2).max(1));
    let at = |j: isize| points[(k as isize + j).rem_euclid(n as isize) as usize];
    let apex = at(0);
    let (first, last) = (at(-(m as isize)) - apex, at(m as isize) - apex);
    let arc: f64 = (-(m as isize)..m as isize)
        .map(|j| (at(j) - apex).cross(&(at(j + 1) - apex)).dot(normal))
        .sum();
    // the chord from P[k+m] back to P[k-m] closes the polygon
    arc + last.cross(&first).dot(normal) > 0.0
}

/// The first pair of loop positions that hold the same input point (a
/// pinch: the loop touches itself), if any.
fn pinch(outer: &[usize]) -> Option<(usize, usize)> {
    let mut seen = std::collections::HashMap::with_capacity(outer.len());
    outer
        .iter()
        .enumerate()
        .find_map(|(k, &i)| seen.insert(i, k).map(|first| (first, k)))
}

/// [`ragged_error`] for `boundary`.
fn ragged(boundary: &Boundary, what: String) -> Error {
    ragged_error((boundary.alpha, boundary.spacing), what)
}

/// The refusal of a ragged boundary (`what` it did), with alpha and the
/// median spacing: notches or pinches are where sparse points' gaps exceed
/// alpha, or a true outline that is not four-sided.
fn ragged_error((alpha, spacing): (f64, f64), what: String) -> Error {
    let factor = alpha / spacing.max(f64::MIN_POSITIVE);
    Error::InvalidSetting {
        setting: "alpha_factor",
        value: format!("{factor:.2} (alpha {alpha:.4}, median spacing {spacing:.4})"),
        hint: format!(
            "{what}. Either the boundary is ragged (where the points thin out, their gaps are wider than the alpha radius and the loop runs into the cloud: give an alpha factor about twice as large) or the outline is not four-sided (give the corners' loop positions, or split the cloud into four-sided patches, a layout)"
        ),
    }
}

/// The detected corners [`check_corners`] judges.
struct Found<'a> {
    loop_len: usize,
    positions: &'a [usize],
    strengths: &'a [f64],
    convex: &'a [bool],
    shares: &'a [f64],
    /// The alpha radius and the median spacing of the boundary.
    alpha: (f64, f64),
}

/// Refuses detected corners that are not clearly corners: notches (the
/// outline turns inward there, which a patch corner cannot: the patch would
/// fold), too flat (turning by less than `pi - max_corner_angle`) or crowded
/// (one side longer than `max_side_share` of the loop).
fn check_corners(cfg: &CoonsFromCloudConfig, f: &Found) -> Result<()> {
    let min_turn = PI - cfg.max_corner_angle;
    let weak = f.strengths.iter().filter(|&&s| s < min_turn).count();
    let longest = f.shares.iter().copied().fold(0.0, f64::max);
    let notches: Vec<String> = f
        .positions
        .iter()
        .zip(f.convex)
        .filter(|(_, &c)| !c)
        .map(|(p, _)| p.to_string())
        .collect();
    if notches.is_empty() && weak == 0 && longest <= cfg.max_side_share {
        return Ok(());
    }
    let turns: Vec<String> = f
        .strengths
        .iter()
        .map(|s| format!("{:.0}", s.to_degrees()))
        .collect();
    let count = f.strengths.len();
    let loop_len = f.loop_len;
    if !notches.is_empty() {
        return Err(ragged_error(
            f.alpha,
            format!(
                "the {count} strongest corners of the boundary ({loop_len} points, turning by {} degrees) include notches where the outline turns inward (loop positions {}), which no patch corner does",
                turns.join(", "),
                notches.join(", "),
            ),
        ));
    }
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
            "the {count} strongest corners of the boundary ({loop_len} points) are not clearly corners: {why}. The outline looks rounded, and a patch on these corners would fold; give the corners' loop positions, or split the cloud into four-sided patches (a layout), or force the detected corners"
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

    #[test]
    fn a_notch_in_the_outline_is_no_corner() {
        // the panel with a deep V bitten into its long lower side: the notch
        // tip turns sharply (inward) and would be picked as a corner
        let pts: Vec<Point3> = panel(30)
            .into_iter()
            .filter(|p| p.y > 0.9 - 4.0 * (p.x - 1.0).abs())
            .collect();
        let e = coons_from_cloud(&pts, &CoonsFromCloudConfig::default()).unwrap_err();
        let m = e.to_string();
        assert!(
            m.starts_with("alpha_factor = 2.50")
                && m.contains("notches where the outline turns inward"),
            "{m}"
        );
        // forced, the picks are reported, the notch tip among them and not convex
        let forced = CoonsFromCloudConfig {
            force_corners: true,
            ..Default::default()
        };
        let r = coons_from_cloud(&pts, &forced).unwrap();
        let loop_pts: Vec<Point3> = r.boundary.outer_loop().iter().map(|&i| pts[i]).collect();
        let tip = r
            .corners
            .corners
            .iter()
            .position(|&k| (loop_pts[k].x - 1.0).abs() < 0.1 && loop_pts[k].y > 0.6)
            .expect("the notch tip is a pick");
        assert!(!r.corner_convex[tip], "{:?}", r.corner_convex);
        assert_eq!(r.corner_convex.iter().filter(|c| !**c).count(), 1);
    }

    #[test]
    fn a_rectangle_s_corners_all_turn_outward() {
        let r = coons_from_cloud(&panel(30), &CoonsFromCloudConfig::default()).unwrap();
        assert_eq!(r.corner_convex, vec![true; 4]);
    }
}
