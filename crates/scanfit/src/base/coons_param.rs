//! Parameters of points on a Coons base surface, by either paper's scheme:
//!
//! * [`CoonsProjection::GridIteration`], [COONS19] (§IV.B, eqs. 17-22):
//!   nearest vertex of a grid of step `h` (0.001) over the patch, found with a
//!   KD-tree over the grid, then the iterative refinement with `epsilon`
//!   (0.01) — [`crate::project::grid_iteration`];
//! * [`CoonsProjection::Inversion`], [PDE23] (§4.4): the exact closest
//!   point. The paper uses the geometric method of its ref. 42; we use the
//!   library's Newton point inversion ([`crate::project::SurfaceInverter`]),
//!   which finds the same closest point (to rounding) from grid starts.
//!
//! Both run on the exact B-spline form of the patch
//! ([`super::CoonsPatch::to_bspline`]). A point is *outside* the patch when
//! its foot lies on the patch's boundary and it is off the surface
//! sideways, i.e. its offset from the foot has a component tangent to the
//! surface above `outside_tolerance` (a point inside projects
//! orthogonally, with no tangential offset).

use rayon::prelude::*;

use crate::bspline::{BasisWorkspace, Surface};
use crate::project::{
    grid_iteration, GridIterationConfig, Inversion, InversionConfig, SurfaceInverter,
};
use crate::{Error, Point3, Result, Vector3};

/// Which projection gives the parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CoonsProjection {
    /// [COONS19]'s grid + iteration (eqs. 17-22; h = 0.001, epsilon = 0.01).
    GridIteration(GridIterationConfig),
    /// Exact closest point ([PDE23] §4.4).
    Inversion(InversionConfig),
}

/// Settings of [`coons_parameters`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoonsParamConfig {
    /// The projection (default: [COONS19]'s grid iteration).
    pub projection: CoonsProjection,
    /// Tangential offset beyond the boundary above which a point counts as
    /// outside the patch; `None` (default): `1e-3` x the diagonal of the
    /// patch's control-net bounding box.
    pub outside_tolerance: Option<f64>,
}

impl Default for CoonsParamConfig {
    fn default() -> Self {
        Self {
            projection: CoonsProjection::GridIteration(GridIterationConfig::default()),
            outside_tolerance: None,
        }
    }
}

/// Parameters of points on the base surface.
#[derive(Debug, Clone)]
pub struct CoonsParameters {
    /// `(u, v)` of every point, in `[0, 1]^2`.
    pub uv: Vec<[f64; 2]>,
    /// Distance from each point to its foot `S_c(u, v)`.
    pub distances: Vec<f64>,
    /// Whether each point lies outside the patch (see the module docs).
    pub outside: Vec<bool>,
    /// Number of points outside.
    pub outside_count: usize,
    /// Points whose iteration stopped without meeting its criterion.
    pub unconverged: usize,
    /// Mean iterations per point.
    pub mean_iterations: f64,
    /// The tolerance used for `outside`.
    pub outside_tolerance: f64,
}

/// Parameterizes `points` on `surface` (the B-spline form of a Coons patch,
/// domain `[0, 1]^2`) with the configured projection.
pub fn coons_parameters(
    surface: &Surface,
    points: &[Point3],
    cfg: &CoonsParamConfig,
) -> Result<CoonsParameters> {
    crate::validate_points(points)?;
    let inv: Vec<Inversion> = match cfg.projection {
        CoonsProjection::GridIteration(g) => grid_iteration(surface, points, &g)?,
        CoonsProjection::Inversion(c) => SurfaceInverter::new(surface, c)?.invert_all(points),
    };
    let tol = match cfg.outside_tolerance {
        Some(t) if t.is_finite() && t >= 0.0 => t,
        Some(t) => {
            return Err(Error::InvalidInput(format!(
                "outside tolerance {t} must be finite and non-negative"
            )))
        }
        None => {
            let (lo, hi) = surface.control_points().iter().fold(
                (
                    Vector3::repeat(f64::INFINITY),
                    Vector3::repeat(f64::NEG_INFINITY),
                ),
                |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
            );
            1e-3 * (hi - lo).norm()
        }
    };
    let ((u0, u1), (v0, v1)) = surface.domain();
    // a foot within half a grid step (or 1e-9) of an edge is on the boundary
    let edge = match cfg.projection {
        CoonsProjection::GridIteration(g) => 0.5 * g.h,
        CoonsProjection::Inversion(_) => 1e-9,
    };
    let (p, q) = surface.degrees();
    let outside: Vec<bool> = points
        .par_iter()
        .zip(&inv)
        .map_init(
            || (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1)),
            |(wu, wv), (pt, r)| {
                let [u, v] = r.uv;
                let on_edge = u - u0 <= edge || u1 - u <= edge || v - v0 <= edge || v1 - v <= edge;
                if !on_edge {
                    return false;
                }
                let d = pt - r.point;
                let n = surface.normal(u, v, wu, wv);
                let tangential = if n.norm() > 0.0 {
                    (d - n * d.dot(&n)).norm()
                } else {
                    d.norm() // a degenerate corner: no normal to be orthogonal to
                };
                tangential > tol
            },
        )
        .collect();
    let outside_count = outside.iter().filter(|&&o| o).count();
    Ok(CoonsParameters {
        uv: inv.iter().map(|r| r.uv).collect(),
        distances: inv.iter().map(|r| r.distance).collect(),
        outside,
        outside_count,
        unconverged: inv.iter().filter(|r| !r.converged).count(),
        mean_iterations: inv.iter().map(|r| r.iterations as f64).sum::<f64>()
            / inv.len().max(1) as f64,
        outside_tolerance: tol,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::CoonsPatch;
    use crate::bspline::{Curve, KnotVector};

    fn curve(pts: &[[f64; 3]]) -> Curve {
        let c: Vec<Point3> = pts.iter().map(|p| Point3::new(p[0], p[1], p[2])).collect();
        Curve::new(KnotVector::uniform_clamped(3, c.len()).unwrap(), c).unwrap()
    }

    #[test]
    fn grid_and_inversion_agree_and_outside_points_are_counted() {
        let patch = CoonsPatch::from_loop(&[
            curve(&[[0., 0., 0.], [0.3, 0., 0.2], [0.7, 0., 0.2], [1., 0., 0.]]),
            curve(&[[1., 0., 0.], [1., 0.3, 0.1], [1., 0.7, 0.1], [1., 1., 0.]]),
            curve(&[[1., 1., 0.], [0.7, 1., 0.2], [0.3, 1., 0.2], [0., 1., 0.]]),
            curve(&[[0., 1., 0.], [0., 0.7, 0.1], [0., 0.3, 0.1], [0., 0., 0.]]),
        ])
        .unwrap();
        let s = patch.to_bspline().unwrap();
        // points on normals above known feet, plus two beyond the edges
        let mut pts = Vec::new();
        let mut truth = Vec::new();
        for i in 1..10 {
            for j in 1..10 {
                let (u, v) = (i as f64 / 10.0, j as f64 / 10.0);
                let (p, su, sv) = patch.derivatives(u, v);
                let n = su.cross(&sv).normalize();
                pts.push(p + n * 0.01);
                truth.push([u, v]);
            }
        }
        pts.push(Point3::new(1.2, 0.5, 0.0));
        pts.push(Point3::new(0.5, -0.3, 0.0));
        let exact = coons_parameters(
            &s,
            &pts,
            &CoonsParamConfig {
                projection: CoonsProjection::Inversion(InversionConfig::default()),
                outside_tolerance: None,
            },
        )
        .unwrap();
        let grid = coons_parameters(&s, &pts, &CoonsParamConfig::default()).unwrap();
        for k in 0..truth.len() {
            for c in 0..2 {
                assert!((exact.uv[k][c] - truth[k][c]).abs() < 1e-9);
                // grid iteration stops at |Q' - Q| <= epsilon = 0.01 (data units)
                assert!((grid.uv[k][c] - truth[k][c]).abs() < 0.01);
            }
        }
        assert_eq!(exact.outside_count, 2);
        assert_eq!(grid.outside_count, 2);
        assert!(exact.outside[81] && exact.outside[82]);
        assert!((exact.uv[81][0] - 1.0).abs() < 1e-12 && (exact.uv[82][1]).abs() < 1e-12);
    }
}
