//! [COONS19]'s parameterization by nearest grid vertex and iteration
//! ([COONS19] section IV, eqs. 17-22):
//!
//! 1. the surface is sampled on a grid of step `h` (default 0.001) in both
//!    parameters and each point takes the parameters of its nearest vertex
//!    (found with a KD-tree over the vertices rather than by brute force);
//! 2. tangents by forward differences, `Q_u = (Q(u+h, w) - Q(u, w)) / h` (17),
//!    `Q_w` likewise (18);
//! 3. `n = Q_u x Q_w / (|Q_u| |Q_w|)` (19), oriented from the point to the surface;
//! 4. `Q' = P + |Q - P| n` (20);
//! 5. while `|Q' - Q| > epsilon` (default 0.01, data units): move the parameters
//!    by the tangential components of `Q' - Q` (21, 22) and repeat from 2.
//!
//! Eqs. 21-22 are printed as `u' = u + (Q' - Q) . (Q_u / |Q_u|)`, which adds a
//! length to a parameter; the parameter change of a displacement `d` along the
//! tangent is `d . Q_u / |Q_u|^2` (first-order Taylor), which is what we use.
//! This method is offered for comparison with Newton point inversion
//! ([`super::SurfaceInverter`]), which is exact to rounding.

use rayon::prelude::*;

use super::Inversion;
use crate::spatial::KdTree;
use crate::surface::ParametricSurface;
use crate::{Error, Point3, Result};

/// Settings of [`grid_iteration`] (the paper's defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridIterationConfig {
    /// Grid step in both parameters (paper: 0.001).
    pub h: f64,
    /// Convergence threshold on `|Q' - Q|` in data units (paper: 0.01).
    pub epsilon: f64,
    /// Iteration cap per point (default 50).
    pub max_iterations: usize,
}

impl Default for GridIterationConfig {
    fn default() -> Self {
        Self {
            h: 0.001,
            epsilon: 0.01,
            max_iterations: 50,
        }
    }
}

/// Parameterizes `points` on `surface` (any [`ParametricSurface`]: a
/// B-spline, or the Coons patch itself) by the grid scheme.
///
/// ```
/// use scanfit::bspline::{KnotVector, Surface};
/// use scanfit::project::{grid_iteration, GridIterationConfig};
/// use scanfit::Point3;
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let ctrl = vec![Point3::new(0., 0., 0.), Point3::new(0., 1., 0.), Point3::new(1., 0., 0.), Point3::new(1., 1., 0.)];
/// let s = Surface::new(k.clone(), k, ctrl).unwrap();
/// let cfg = GridIterationConfig { h: 0.01, ..Default::default() };
/// let r = grid_iteration(&s, &[Point3::new(0.333, 0.5, 0.1)], &cfg).unwrap();
/// // within the grid step of the foot point (0.333, 0.5)
/// assert!((r[0].uv[0] - 0.333).abs() <= 0.01 && (r[0].uv[1] - 0.5).abs() <= 0.01);
/// ```
pub fn grid_iteration<S: ParametricSurface + ?Sized>(
    surface: &S,
    points: &[Point3],
    cfg: &GridIterationConfig,
) -> Result<Vec<Inversion>> {
    let valid = cfg.h > 0.0 && cfg.h <= 0.5 && cfg.epsilon > 0.0; // false for NaN too
    if !valid {
        return Err(Error::InvalidInput(format!(
            "grid step h = {} must be in (0, 0.5] and epsilon = {} positive",
            cfg.h, cfg.epsilon
        )));
    }
    let ((u0, u1), (v0, v1)) = surface.domain();
    let (nu, nv) = (
        ((u1 - u0) / cfg.h).round() as usize,
        ((v1 - v0) / cfg.h).round() as usize,
    );
    let (nu, nv) = (nu.max(1), nv.max(1));
    if (nu + 1).saturating_mul(nv + 1) > 10_000_000 {
        return Err(Error::InvalidInput(format!(
            "grid step h = {} makes a {} x {} grid, more than 10^7 vertices; use a larger h (the Coons paper: 0.001)",
            cfg.h,
            nu + 1,
            nv + 1
        )));
    }
    let uv: Vec<[f64; 2]> = (0..=nu)
        .flat_map(|i| {
            (0..=nv).map(move |j| {
                [
                    u0 + (u1 - u0) * i as f64 / nu as f64,
                    v0 + (v1 - v0) * j as f64 / nv as f64,
                ]
            })
        })
        .collect();
    let verts: Vec<Point3> = uv.par_iter().map(|t| surface.point(t[0], t[1])).collect();
    let tree = KdTree::new(&verts, "the grid vertices")?;
    let (hu, hv) = ((u1 - u0) / nu as f64, (v1 - v0) / nv as f64);
    Ok(points
        .par_iter()
        .map(|p| {
            let [mut u, mut w] = uv[tree.nearest(p).index];
            let mut converged = false;
            let mut it = 0;
            while it < cfg.max_iterations {
                it += 1;
                // forward differences, stepping backwards at the far edges
                let (su, sw) = (
                    if u + hu <= u1 { hu } else { -hu },
                    if w + hv <= v1 { hv } else { -hv },
                );
                let q = surface.point(u, w);
                let qu = (surface.point(u + su, w) - q) / su; // (17)
                let qw = (surface.point(u, w + sw) - q) / sw; // (18)
                let (lu, lw) = (qu.norm(), qw.norm());
                if lu == 0.0 || lw == 0.0 {
                    break;
                }
                // (19) divides by |Q_u| |Q_w|, a unit vector only when the
                // tangents are orthogonal (then |Q' - Q| would not vanish at
                // the foot point, and skewed patches would never converge);
                // the unit normal it intends is Q_u x Q_w / |Q_u x Q_w|
                let c = qu.cross(&qw);
                let lc = c.norm();
                if lc <= 1e-300 * lu * lw {
                    break;
                }
                let mut n = c / lc; // (19), normalised
                if (q - p).dot(&n) < 0.0 {
                    n = -n;
                }
                let q_next = p + n * (q - p).norm(); // (20)
                let dq = q_next - q;
                if dq.norm() <= cfg.epsilon {
                    converged = true;
                    break;
                }
                u = (u + dq.dot(&qu) / (lu * lu)).clamp(u0, u1); // (21)
                w = (w + dq.dot(&qw) / (lw * lw)).clamp(v0, v1); // (22)
            }
            let foot = surface.point(u, w);
            Inversion {
                uv: [u, w],
                point: foot,
                distance: (foot - p).norm(),
                iterations: it,
                converged,
            }
        })
        .collect())
}
