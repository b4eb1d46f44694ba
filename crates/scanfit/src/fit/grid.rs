//! Surfaces through or near data on a regular grid ([NURBS97] section
//! 9.2.5, Algorithm A9.4, and the least-squares analogue of section 9.4.3):
//! parameters by chord length along every grid line, averaged over the lines
//! (eqs. 9.5 and 9.10-9.11); knots by averaging (interpolation) or eqs.
//! 9.68-9.69 (approximation), periodic in a closed `u` direction; then curve
//! fits along `u` for all lines at once (one factorization, many right-hand
//! sides) and along `v` through the results.
//!
//! Used by the turntable and dynamic base surface methods, whose layer curves
//! form such grids (closed around the axis in `u`).

use super::interpolate::{collocate, collocate_closed};
use super::least_squares::lsq_values;
use super::LeastSquaresOptions;
use crate::bspline::{KnotVector, Surface};
use crate::param::knots;
use crate::{Error, Point3, Result};

/// Configuration of [`fit_grid`].
#[derive(Debug, Clone, PartialEq)]
pub struct GridFitConfig {
    /// Degrees `(p, q)` (default bicubic).
    pub degree: (usize, usize),
    /// `None`: interpolate every grid point (default); `Some((nu, nv))`: least
    /// squares with that control net (`nu` distinct rows when periodic).
    pub ctrl: Option<(usize, usize)>,
    /// The grid closes around in `u` (row `rows - 1` is followed by row 0).
    pub periodic_u: bool,
}

impl Default for GridFitConfig {
    fn default() -> Self {
        Self {
            degree: (3, 3),
            ctrl: None,
            periodic_u: false,
        }
    }
}

/// A surface fitted to a grid, with the grid's parameters.
#[derive(Debug, Clone)]
pub struct GridFit {
    /// The surface.
    pub surface: Surface,
    /// Parameter of each grid row (`u`).
    pub params_u: Vec<f64>,
    /// Parameter of each grid column (`v`).
    pub params_v: Vec<f64>,
}

/// Fits a surface to `points` on a `rows x cols` grid, `Q_kl = points[k * cols + l]`
/// (`k` along `u`, `l` along `v`).
pub fn fit_grid(
    points: &[Point3],
    rows: usize,
    cols: usize,
    cfg: &GridFitConfig,
) -> Result<GridFit> {
    let (p, q) = cfg.degree;
    if points.len() != rows * cols {
        return Err(Error::InvalidInput(format!(
            "{} points do not form a {rows} x {cols} grid",
            points.len()
        )));
    }
    crate::validate_points(points)?;
    let need_u = if cfg.periodic_u { 2 * p + 1 } else { p + 1 };
    if rows < need_u || cols < q + 1 || p == 0 || q == 0 {
        return Err(Error::TooFewPoints {
            got: rows.min(cols),
            needed: need_u.max(q + 1),
            what: format!("a {rows} x {cols} grid fit of degrees {p} x {q}"),
        });
    }
    let at = |k: usize, l: usize| points[k * cols + l];
    // averaged chord-length parameters; a closed u direction includes the closing chord
    let params_u = averaged(rows, cols, cfg.periodic_u, at)?;
    let params_v = averaged(cols, rows, false, |l, k| at(k, l))?;
    let (ku, kv) = match cfg.ctrl {
        None => (
            if cfg.periodic_u {
                knots::periodic(&params_u, p)?
            } else {
                knots::averaging(&params_u, p)?
            },
            knots::averaging(&params_v, q)?,
        ),
        Some((nu, nv)) => (
            if cfg.periodic_u {
                knots::periodic_least_squares(&params_u, p, nu)?
            } else {
                knots::least_squares(&params_u, p, nu)?
            },
            knots::least_squares(&params_v, q, nv)?,
        ),
    };
    let us = &params_u[..rows]; // without the closing parameter
                                // pass 1 along u: one row per grid row k, columns (l, xyz)
    let mut values = Vec::with_capacity(rows * cols * 3);
    for k in 0..rows {
        for l in 0..cols {
            values.extend_from_slice(at(k, l).coords.as_slice());
        }
    }
    let r = solve_dir(
        us,
        &values,
        3 * cols,
        &ku,
        cfg.ctrl.is_some(),
        cfg.periodic_u,
    )?;
    let nu = r.len() / (3 * cols);
    // pass 2 along v: transpose to one row per grid column l, columns (i, xyz)
    let mut t = vec![0.0; cols * nu * 3];
    for i in 0..nu {
        for l in 0..cols {
            for c in 0..3 {
                t[(l * nu + i) * 3 + c] = r[(i * cols + l) * 3 + c];
            }
        }
    }
    let s = solve_dir(&params_v, &t, 3 * nu, &kv, cfg.ctrl.is_some(), false)?;
    let nv = s.len() / (3 * nu);
    // control net P_ij (u slow); periodic: repeat the first p rows
    let total_u = ku.basis_count();
    let mut ctrl = Vec::with_capacity(total_u * nv);
    for i in 0..total_u {
        let fi = i % nu;
        for j in 0..nv {
            let b = (j * nu + fi) * 3;
            ctrl.push(Point3::new(s[b], s[b + 1], s[b + 2]));
        }
    }
    let surface = Surface::with_options(ku, kv, ctrl, None, cfg.periodic_u, false)?;
    Ok(GridFit {
        surface,
        params_u: us.to_vec(),
        params_v,
    })
}

/// Interpolates (`lsq == false`) or approximates the value rows at `params`.
fn solve_dir(
    params: &[f64],
    values: &[f64],
    ncols: usize,
    kv: &KnotVector,
    lsq: bool,
    periodic: bool,
) -> Result<Vec<f64>> {
    let out = match (lsq, periodic) {
        (false, false) => {
            let rows: Vec<(f64, usize)> = params.iter().map(|&u| (u, 0)).collect();
            collocate(&rows, values, ncols, kv, params)?.0
        }
        (false, true) => collocate_closed(params, values, ncols, kv)?.0,
        (true, _) => {
            let opts = LeastSquaresOptions {
                fix_ends: true,
                ..Default::default()
            };
            lsq_values(params, values, ncols, kv, &opts, periodic)?.0
        }
    };
    Ok(out)
}

/// Chord-length parameters of `n` samples along each of `m` lines, averaged
/// over the lines (NURBS Book eqs. 9.10-9.11); a line of zero length is left
/// out of the average. With `closed`, the chord back to the first sample is
/// included and `n + 1` parameters are returned (the last is 1).
fn averaged(
    n: usize,
    m: usize,
    closed: bool,
    at: impl Fn(usize, usize) -> Point3,
) -> Result<Vec<f64>> {
    let segs = if closed { n } else { n - 1 };
    let mut acc = vec![0.0; segs + 1];
    let mut used = 0usize;
    for l in 0..m {
        let d: Vec<f64> = (0..segs)
            .map(|k| (at((k + 1) % n, l) - at(k, l)).norm())
            .collect();
        let total: f64 = d.iter().sum();
        if total <= 0.0 {
            continue;
        }
        used += 1;
        let mut run = 0.0;
        for (k, dk) in d.iter().enumerate() {
            run += dk;
            acc[k + 1] += run / total;
        }
    }
    if used == 0 {
        return Err(Error::InvalidInput(
            "every grid line has zero length".into(),
        ));
    }
    for v in acc.iter_mut() {
        *v /= used as f64;
    }
    acc[segs] = 1.0;
    crate::param::check_increasing(&acc, "averaged chord-length (grid)")?;
    Ok(acc)
}
