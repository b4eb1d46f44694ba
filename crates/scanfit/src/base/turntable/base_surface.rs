//! The base surface ([TURN17] sections 3.6-3.7).
//!
//! Initial base surface (3.6): every final layer curve is sampled with the
//! same count, the largest layer's; a grid of `M` samples around by `L`
//! layers is interpolated by a bicubic surface closed (periodic) in `u`
//! around the axis and clamped along it ([NURBS97] A9.4 with a
//! periodic `u` direction, [`crate::fit::grid::fit_grid`]). The paper
//! samples and parameterizes uniformly; the samples here are uniform in each
//! curve's chord-length parameter and the grid fit averages chord lengths
//! over the rows, which for uniform samples is uniform up to the variation of
//! the spacing between layers. So that the rows do not twist, every layer's
//! samples start where its curve crosses the half-plane of angle 0 (the
//! first view's direction).
//!
//! Refinement and relaxation (3.7): the surface's grid (at the grid fit's
//! parameters) is projected onto the cloud along the surface normal by
//! directed projection, then relaxed and re-interpolated. The paper says
//! only that the relaxation "is the method used in the DBS approach"
//! ([Aza04]) and prints no formula; we relax as a tangential
//! umbrella (Laplacian) step: each grid point moves by `lambda` times the
//! part of `(mean of its grid neighbours) - point` in the tangent plane of
//! the base surface, neighbours around the axis and, inside, along it. The
//! tangential move evens out the spacing the projection disturbed and undoes
//! small fold-overs without pulling the points off the cloud to first order.

use rayon::prelude::*;

use crate::bspline::{BasisWorkspace, Curve};
use crate::cloud::PointCloud;
use crate::fit::grid::{fit_grid, GridFit, GridFitConfig};
use crate::project::{project_directed_batch, DirectedConfig};
use crate::{Error, Point3, Result, Vector3};

use super::axis::CylinderFrame;
use super::views::wrap_angle;

/// Settings of the refinement and relaxation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineConfig {
    /// Refinement rounds (projection, relaxation, re-interpolation; default 2).
    pub rounds: usize,
    /// Directed projection along the surface normal (default: eq. 19,
    /// 32 nearest points, iterated to convergence).
    pub projection: DirectedConfig,
    /// Relaxation factor `lambda` in `[0, 1]` (default 0.5).
    pub relaxation: f64,
    /// Relaxation sweeps per round (default 5).
    pub sweeps: usize,
}

impl Default for RefineConfig {
    fn default() -> Self {
        Self {
            rounds: 2,
            projection: DirectedConfig::default(),
            relaxation: 0.5,
            sweeps: 5,
        }
    }
}

/// `m` samples of a closed layer curve, uniform in its parameter, starting
/// where the curve crosses angle 0 around the axis.
pub fn aligned_samples(curve: &Curve, frame: &CylinderFrame, m: usize) -> Result<Vec<Point3>> {
    let (a, b) = curve.domain();
    let dense = 8 * m.max(16);
    let at = |j: usize| a + (b - a) * j as f64 / dense as f64;
    let ang = |u: f64| frame.angle(&curve.point(u));
    // the crossing of angle 0 from negative to positive angles
    let mut start = None;
    for j in 0..dense {
        let (u0, u1) = (at(j), at(j + 1));
        let (f0, f1) = (ang(u0), ang(u1));
        if f0 <= 0.0 && f1 > 0.0 && (f1 - f0) < std::f64::consts::PI {
            // bisection on the angle
            let (mut lo, mut hi) = (u0, u1);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if ang(mid) <= 0.0 {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            start = Some(0.5 * (lo + hi));
            break;
        }
    }
    let s = start.ok_or_else(|| {
        Error::InvalidInput(
            "a layer curve does not go round the axis (it never crosses the first view's direction); check the axis".into(),
        )
    })?;
    // it must go round once, with growing angle
    let mut turn = 0.0;
    let mut prev = ang(s);
    for j in 1..=dense {
        let f = ang(s + (b - a) * j as f64 / dense as f64);
        turn += wrap_angle(f - prev);
        prev = f;
    }
    if (turn - 2.0 * std::f64::consts::PI).abs() > 1e-6 {
        return Err(Error::InvalidInput(format!(
            "a layer curve winds {:.2} times around the axis instead of once; the section is not star-shaped around the axis there (check the axis or the layer range)",
            turn / (2.0 * std::f64::consts::PI)
        )));
    }
    Ok((0..m)
        .map(|i| curve.point(curve.wrap(s + (b - a) * i as f64 / m as f64)))
        .collect())
}

/// Section 3.6: the grid of aligned samples (`M` around, the largest layer
/// count, by `L` layers) and its periodic interpolating surface.
pub fn initial_base_surface(
    curves: &[Curve],
    counts: &[usize],
    frame: &CylinderFrame,
) -> Result<(GridFit, usize)> {
    let m = counts.iter().copied().max().unwrap_or(0);
    let rows: Vec<Vec<Point3>> = curves
        .par_iter()
        .map(|c| aligned_samples(c, frame, m))
        .collect::<Result<_>>()?;
    let grid = transpose(&rows, m);
    let fit = fit_grid(
        &grid,
        m,
        curves.len(),
        &GridFitConfig {
            periodic_u: true,
            ..Default::default()
        },
    )?;
    Ok((fit, m))
}

/// `rows[l][k]` (layer l, sample k) to the grid `Q[k * L + l]`.
fn transpose(rows: &[Vec<Point3>], m: usize) -> Vec<Point3> {
    let l = rows.len();
    let mut g = vec![Point3::origin(); m * l];
    for (j, row) in rows.iter().enumerate() {
        for (k, p) in row.iter().enumerate() {
            g[k * l + j] = *p;
        }
    }
    g
}

/// One round of section 3.7 on `fit`: returns the new grid fit and the RMSE
/// of the projected grid's nearest-point distances to the cloud.
pub fn refine_round(
    cloud: &PointCloud,
    fit: &GridFit,
    cfg: &RefineConfig,
) -> Result<(GridFit, f64)> {
    if !(0.0..=1.0).contains(&cfg.relaxation) {
        return Err(Error::InvalidInput(format!(
            "relaxation factor {} must be in [0, 1]",
            cfg.relaxation
        )));
    }
    let s = &fit.surface;
    let (m, l) = (fit.params_u.len(), fit.params_v.len());
    let (p, q) = s.degrees();
    let (points, normals): (Vec<Point3>, Vec<Vector3>) = (0..m * l)
        .into_par_iter()
        .map_init(
            || (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1)),
            |(wu, wv), idx| {
                let (u, v) = (fit.params_u[idx / l], fit.params_v[idx % l]);
                (s.point(u, v), s.normal(u, v, wu, wv))
            },
        )
        .unzip();
    if let Some(i) = normals.iter().position(|n| n.norm() < 0.5) {
        return Err(Error::InvalidInput(format!(
            "the base surface is degenerate at grid point {i} (no normal); use fewer layers or a larger margin"
        )));
    }
    let mut grid: Vec<Point3> = project_directed_batch(cloud, &points, &normals, &cfg.projection)?
        .into_iter()
        .map(|r| r.point)
        .collect();
    for _ in 0..cfg.sweeps {
        grid = relax(&grid, &normals, m, l, cfg.relaxation);
    }
    let rmse = crate::metrics::rmse_to_cloud(cloud, &grid)?;
    let next = fit_grid(
        &grid,
        m,
        l,
        &GridFitConfig {
            periodic_u: true,
            ..Default::default()
        },
    )?;
    Ok((next, rmse))
}

/// Tangential umbrella step on the `m x l` grid (closed in the first index).
fn relax(grid: &[Point3], normals: &[Vector3], m: usize, l: usize, lambda: f64) -> Vec<Point3> {
    (0..m * l)
        .into_par_iter()
        .map(|idx| {
            let (k, j) = (idx / l, idx % l);
            let at = |k: usize, j: usize| grid[k * l + j].coords;
            let mut sum = at((k + m - 1) % m, j) + at((k + 1) % m, j);
            let mut count = 2.0;
            if j > 0 && j + 1 < l {
                sum += at(k, j - 1) + at(k, j + 1);
                count += 2.0;
            }
            let d = sum / count - at(k, j);
            let n = normals[idx];
            Point3::from(at(k, j) + lambda * (d - d.dot(&n) * n))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::axis::AxisChoice;
    use super::super::layers::closed_curve;
    use super::*;
    use std::f64::consts::PI;

    fn frame() -> CylinderFrame {
        let pts: Vec<Point3> = (0..64)
            .map(|i| {
                let t = 2.0 * PI * i as f64 / 32.0;
                Point3::new(t.sin(), if i < 32 { -1.0 } else { 1.0 }, t.cos())
            })
            .collect();
        CylinderFrame::of(&pts, AxisChoice::Given(Vector3::y())).unwrap()
    }

    fn ring(cx: f64, r: f64, phase: f64, n: usize) -> Vec<Point3> {
        (0..n)
            .map(|i| {
                let t = phase + 2.0 * PI * i as f64 / n as f64;
                Point3::new(cx + r * t.sin(), 0.0, r * t.cos())
            })
            .collect()
    }

    #[test]
    fn samples_start_at_angle_zero_and_go_round_once() {
        let f = frame();
        // the polygon starts at 100 degrees: the samples still start at angle 0
        let c = closed_curve(&ring(0.0, 1.0, 100f64.to_radians(), 30)).unwrap();
        let s = aligned_samples(&c, &f, 16).unwrap();
        assert!(f.angle(&s[0]).abs() < 1e-9, "{}", f.angle(&s[0]));
        for (i, p) in s.iter().enumerate() {
            let expect = wrap_angle(2.0 * PI * i as f64 / 16.0);
            assert!(wrap_angle(f.angle(p) - expect).abs() < 0.01, "{i}");
        }
    }

    #[test]
    fn a_curve_beside_the_axis_is_refused() {
        let f = frame();
        let c = closed_curve(&ring(3.0, 1.0, 0.0, 30)).unwrap();
        let e = aligned_samples(&c, &f, 16).unwrap_err().to_string();
        assert!(e.contains("axis"), "{e}");
    }

    #[test]
    fn relaxation_leaves_an_even_cylinder_grid_alone_and_evens_a_bunched_one() {
        let (m, l) = (24, 6);
        let grid_at = |shift: &dyn Fn(usize) -> f64| -> (Vec<Point3>, Vec<Vector3>) {
            let mut g = Vec::new();
            let mut n = Vec::new();
            for k in 0..m {
                for j in 0..l {
                    let t = 2.0 * PI * k as f64 / m as f64 + shift(k);
                    g.push(Point3::new(t.sin(), j as f64, t.cos()));
                    n.push(Vector3::new(t.sin(), 0.0, t.cos()));
                }
            }
            (g, n)
        };
        let (g, n) = grid_at(&|_| 0.0);
        let r = relax(&g, &n, m, l, 0.5);
        for (a, b) in g.iter().zip(&r) {
            assert!((a - b).norm() < 1e-12);
        }
        // one row pushed a third of a step sideways: an inside point's mean of
        // four neighbours is half the push back, lambda 0.5 takes a quarter
        // (0.0872 -> 0.0662, ratio 0.76 with the chord)
        let step = 2.0 * PI / m as f64;
        let (g, n) = grid_at(&|k| if k == 5 { step / 3.0 } else { 0.0 });
        let r = relax(&g, &n, m, l, 0.5);
        let before =
            (g[5 * l + 2] - Point3::new((5.0 * step).sin(), 2.0, (5.0 * step).cos())).norm();
        let after =
            (r[5 * l + 2] - Point3::new((5.0 * step).sin(), 2.0, (5.0 * step).cos())).norm();
        assert!(
            after > 0.7 * before && after < 0.8 * before,
            "{before} -> {after}"
        );
    }
}
