//! Least-squares curve approximation ([NURBS97] section 9.4.1, A9.6
//! without weights in the constraints), with optional point weights and an
//! optional smoothing term:
//!
//! ```text
//! minimise  sum_k w_k |Q_k - C(u_k)|^2 + lambda * ∫ |C''(u)|^2 du
//! ```
//!
//! The normal equations `(N^T W N + lambda G) P = N^T W Q` are assembled point by
//! point into a band matrix (half-bandwidth `p`; `G` from [`super::gram`]) and
//! solved without pivoting (SPD). With `fix_ends` the first and last control
//! points are the first and last data points and drop out of the system
//! (eq. 9.63-9.67). Closed curves use periodic knots and the cyclic solver.

use super::banded::BandMatrix;
use super::cyclic::CyclicBandMatrix;
use super::gram;
use super::{CurveFit, CONDITION_LIMIT};
use crate::bspline::{BasisWorkspace, Curve, KnotVector};
use crate::param::{self, Method};
use crate::{Error, Point3, Result};

/// Configuration of [`approximate`].
#[derive(Debug, Clone, PartialEq)]
pub struct ApproximationConfig {
    /// Degree (default 3).
    pub degree: usize,
    /// Number of control points (distinct ones for a closed curve).
    pub ctrl_count: usize,
    /// Parameterization (default: [CURVE12]'s new method, a = 0.8).
    pub method: Method,
    /// Pin the curve's ends to the first and last points (default true; open only).
    pub fix_ends: bool,
    /// Smoothing weight `lambda` on the bending energy (default 0). It multiplies
    /// `∫|C''(u)|^2 du` over the parameter domain `[0, 1]`, so its scale is
    /// (data length)^2 relative to the squared residuals.
    pub smoothing: f64,
    /// Optional positive weight per point.
    pub weights: Option<Vec<f64>>,
    /// Closed loop: periodic curve (default false).
    pub closed: bool,
}

impl Default for ApproximationConfig {
    fn default() -> Self {
        Self {
            degree: 3,
            ctrl_count: 10,
            method: Method::Proposed(param::DEFAULT_EXPONENT),
            fix_ends: true,
            smoothing: 0.0,
            weights: None,
            closed: false,
        }
    }
}

/// Options of the low-level least-squares solvers.
#[derive(Debug, Clone, Copy, Default)]
pub struct LeastSquaresOptions<'a> {
    /// Pin the first and last control points to the first and last data points.
    pub fix_ends: bool,
    /// Bending-energy weight `lambda` (0 = none).
    pub smoothing: f64,
    /// Optional positive weight per point.
    pub weights: Option<&'a [f64]>,
}

/// Approximates `points` by a curve with `cfg.ctrl_count` control points.
pub fn approximate(points: &[Point3], cfg: &ApproximationConfig) -> Result<CurveFit> {
    let p = cfg.degree;
    let pts = super::prepare_points(
        points,
        p,
        cfg.closed,
        &format!("least squares of degree {p}"),
    )?;
    if cfg.ctrl_count > pts.len() {
        return Err(Error::InvalidInput(format!(
            "{} control points requested but only {} data points; use --ctrl {} or fewer, or --interpolate",
            cfg.ctrl_count,
            pts.len(),
            pts.len()
        )));
    }
    if cfg.closed && cfg.ctrl_count < 2 * p + 1 {
        return Err(Error::InvalidInput(format!(
            "a closed curve of degree {p} needs at least {} control points, {} requested",
            2 * p + 1,
            cfg.ctrl_count
        )));
    }
    let par = param::parameterize(pts, cfg.method, p, cfg.closed)?;
    let opts = LeastSquaresOptions {
        fix_ends: cfg.fix_ends,
        smoothing: cfg.smoothing,
        weights: cfg.weights.as_deref(),
    };
    let (curve, condition, params) = if cfg.closed {
        let kv = param::knots::periodic_least_squares(&par.params, p, cfg.ctrl_count)?;
        let u = &par.params[..pts.len()];
        let (c, k) = least_squares_closed_with(pts, u, kv, opts)?;
        (c, k, u.to_vec())
    } else {
        let kv = param::knots::least_squares(&par.params, p, cfg.ctrl_count)?;
        let (c, k) = least_squares_with(pts, &par.params, kv, opts)?;
        (c, k, par.params)
    };
    Ok(CurveFit {
        curve,
        params,
        method: cfg.method,
        condition,
    })
}

fn check_inputs(points: &[Point3], params: &[f64], opts: &LeastSquaresOptions) -> Result<()> {
    if params.len() != points.len() {
        return Err(Error::InvalidInput(format!(
            "{} parameters for {} points",
            params.len(),
            points.len()
        )));
    }
    super::validate_weights_and_smoothing(opts.weights, points.len(), opts.smoothing)?;
    Ok(())
}

/// Least squares with given parameters and a clamped knot vector.
/// Returns the curve and the condition estimate of the normal equations.
pub fn least_squares_with(
    points: &[Point3],
    params: &[f64],
    kv: KnotVector,
    opts: LeastSquaresOptions,
) -> Result<(Curve, f64)> {
    check_inputs(points, params, &opts)?;
    let values: Vec<f64> = points.iter().flat_map(|q| [q.x, q.y, q.z]).collect();
    let (x, cond) = lsq_values(params, &values, 3, &kv, &opts, false)?;
    let ctrl = x.chunks(3).map(|c| Point3::new(c[0], c[1], c[2])).collect();
    Ok((Curve::new(kv, ctrl)?, cond))
}

/// Least squares for a closed (periodic) curve: parameters in `[0, 1)`, a
/// periodic knot vector with `count + p` basis functions (`count` distinct
/// control points).
pub fn least_squares_closed_with(
    points: &[Point3],
    params: &[f64],
    kv: KnotVector,
    opts: LeastSquaresOptions,
) -> Result<(Curve, f64)> {
    check_inputs(points, params, &opts)?;
    let p = kv.degree();
    let values: Vec<f64> = points.iter().flat_map(|q| [q.x, q.y, q.z]).collect();
    let (x, cond) = lsq_values(params, &values, 3, &kv, &opts, true)?;
    let mut ctrl: Vec<Point3> = x.chunks(3).map(|c| Point3::new(c[0], c[1], c[2])).collect();
    for j in 0..p {
        ctrl.push(ctrl[j]);
    }
    Ok((Curve::new_periodic(kv, ctrl, None)?, cond))
}

/// The least-squares kernel for `ncols` value columns (row-major, one row per
/// parameter): normal equations assembled per row into a band (or, periodic, a
/// cyclic band) matrix, optional weights and bending-energy smoothing, fixed
/// ends (open only: the first and last control rows equal the first and last
/// value rows). Returns the control values (distinct ones when periodic) and
/// the condition estimate.
pub(crate) fn lsq_values(
    params: &[f64],
    values: &[f64],
    ncols: usize,
    kv: &KnotVector,
    opts: &LeastSquaresOptions,
    periodic: bool,
) -> Result<(Vec<f64>, f64)> {
    let p = kv.degree();
    let count = if periodic {
        kv.basis_count() - p
    } else {
        kv.basis_count()
    };
    let fix = opts.fix_ends && !periodic;
    if fix && count < 3 {
        return Err(Error::InvalidInput(format!(
            "{count} control points leave nothing to fit with fixed ends"
        )));
    }
    let t = kv.as_slice();
    // band storage: entry (i, j) with j = i + d, d in -p..=p (cyclic when periodic)
    let w = 2 * p + 1;
    let mut m = vec![0.0; count * w];
    let mut rhs = vec![0.0; count * ncols];
    let fold = |i: usize| if periodic { i % count } else { i };
    let mut ws = BasisWorkspace::new(p, 0);
    let mut s = p;
    let last = kv.basis_count() - 1;
    for (k, &u) in params.iter().enumerate() {
        if !(t[s] <= u && (u < t[s + 1] || (s == last && u <= t[s + 1]))) {
            s = kv.find_span(u);
        }
        let wk = opts.weights.map_or(1.0, |w| w[k]);
        let n = ws.values(t, s, u);
        for a in 0..=p {
            let wa = wk * n[a];
            let row = fold(s - p + a);
            for b in 0..=p {
                m[row * w + b + p - a] += wa * n[b];
            }
            for c in 0..ncols {
                rhs[row * ncols + c] += wa * values[k * ncols + c];
            }
        }
    }
    if opts.smoothing > 0.0 {
        gram::for_each_entry(kv, 2, |i, j, g| {
            m[fold(i) * w + j + p - i] += opts.smoothing * g
        });
    }
    let what = if periodic {
        "closed least-squares curve"
    } else {
        "least-squares curve"
    };
    if periodic {
        let mut a = CyclicBandMatrix::zeros(count, p)?;
        for i in 0..count {
            for d in 0..w {
                let v = m[i * w + d];
                if v != 0.0 {
                    a.add(i, (i + count + d - p) % count, v);
                }
            }
        }
        let cond = a
            .solve(&mut rhs, ncols, what)
            .map_err(|e| empty_span_hint(e, kv, params))?;
        if cond > CONDITION_LIMIT {
            return Err(empty_span_hint(
                Error::Singular {
                    what: what.into(),
                    condition: cond,
                    hint: String::new(),
                },
                kv,
                params,
            ));
        }
        return Ok((rhs, cond));
    }
    let get = |i: usize, j: usize| {
        if j + p < i || j > i + p {
            0.0
        } else {
            m[i * w + j + p - i]
        }
    };
    if fix {
        let (first, lastrow) = (&values[..ncols], &values[values.len() - ncols..]);
        let r = count - 2;
        let mut red = BandMatrix::zeros(r, p, p);
        let mut f = vec![0.0; r * ncols];
        for i in 1..=r {
            for j in i.saturating_sub(p).max(1)..=(i + p).min(r) {
                red.set(i - 1, j - 1, get(i, j));
            }
            let (a0, an) = (get(i, 0), get(i, count - 1));
            for c in 0..ncols {
                f[(i - 1) * ncols + c] = rhs[i * ncols + c] - a0 * first[c] - an * lastrow[c];
            }
        }
        let cond = solve_normal(red, &mut f, ncols, kv, params)?;
        let mut x = first.to_vec();
        x.extend_from_slice(&f);
        x.extend_from_slice(lastrow);
        return Ok((x, cond));
    }
    let mut band = BandMatrix::zeros(count, p, p);
    for i in 0..count {
        for j in i.saturating_sub(p)..(i + p + 1).min(count) {
            band.set(i, j, get(i, j));
        }
    }
    let cond = solve_normal(band, &mut rhs, ncols, kv, params)?;
    Ok((rhs, cond))
}

fn solve_normal(
    m: BandMatrix,
    rhs: &mut [f64],
    ncols: usize,
    kv: &KnotVector,
    params: &[f64],
) -> Result<f64> {
    let lu = m
        .factor("least-squares curve")
        .map_err(|e| empty_span_hint(e, kv, params))?;
    if lu.condition() > CONDITION_LIMIT {
        return Err(empty_span_hint(
            Error::Singular {
                what: "least-squares curve".into(),
                condition: lu.condition(),
                hint: String::new(),
            },
            kv,
            params,
        ));
    }
    lu.solve_in_place(rhs, ncols);
    Ok(lu.condition())
}

/// Names the first knot span without data (the usual cause of a singular
/// normal matrix) and what to change.
fn empty_span_hint(e: Error, kv: &KnotVector, params: &[f64]) -> Error {
    let Error::Singular {
        what, condition, ..
    } = e
    else {
        return e;
    };
    let bps = kv.breakpoints();
    let empty = bps.windows(2).find(|w| {
        !params
            .iter()
            .any(|&u| u >= w[0] && (u < w[1] || (w[1] == bps[bps.len() - 1] && u <= w[1])))
    });
    let hint = match empty {
        Some(w) => format!(
            "knot span [{}, {}] holds no data point; use fewer control points or add smoothing (--smooth)",
            w[0], w[1]
        ),
        None => "use fewer control points or add smoothing (--smooth)".to_string(),
    };
    Error::Singular {
        what,
        condition,
        hint,
    }
}
