//! The base surface (turntable paper sections 3.6-3.7).
//!
//! Initial base surface (3.6): every final layer curve is sampled with the
//! same count, the largest layer's; a grid of `M` samples around by `L`
//! layers is interpolated by a bicubic surface closed (periodic) in `u`
//! around the axis and clamped along it (*The NURBS Book* A9.4 with a
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
//! (Azariadis 2004) and prints no formula; we relax as a tangential
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
