//! Global curve interpolation ([NURBS97] section 9.2.1, A9.1), with end
//! derivatives (section 9.2.2) and closed (periodic) interpolation.

use super::banded::BandMatrix;
use super::cyclic::CyclicBandMatrix;
use super::{CurveFit, CONDITION_LIMIT};
use crate::bspline::{BasisWorkspace, Curve, KnotVector};
use crate::param::{self, Method};
use crate::{Error, Point3, Result, Vector3};

/// Configuration of [`interpolate`].
#[derive(Debug, Clone, PartialEq)]
pub struct InterpolationConfig {
    /// Degree (default 3).
    pub degree: usize,
    /// Parameterization (default: [CURVE12]'s new method, a = 0.8).
    pub method: Method,
    /// Prescribed first derivatives `C'(0)` and `C'(1)` (open curves only).
    pub end_derivatives: Option<(Vector3, Vector3)>,
    /// Closed loop: periodic interpolation, `C^{p-1}` at the seam (default false).
    pub closed: bool,
}

impl Default for InterpolationConfig {
    fn default() -> Self {
        Self {
            degree: 3,
            method: Method::Proposed(param::DEFAULT_EXPONENT),
            end_derivatives: None,
            closed: false,
        }
    }
}

/// Interpolates `points` with the configured degree and parameterization.
pub fn interpolate(points: &[Point3], cfg: &InterpolationConfig) -> Result<CurveFit> {
    let p = cfg.degree;
    let what = format!(
        "{}interpolation of degree {p}",
        if cfg.closed { "closed " } else { "" }
    );
    let pts = super::prepare_points(points, p, cfg.closed, &what)?;
    let par = param::parameterize(pts, cfg.method, p, cfg.closed)?;
    if cfg.closed {
        if cfg.end_derivatives.is_some() {
            return Err(Error::InvalidInput(
                "end derivatives cannot be prescribed for a closed curve".into(),
            ));
        }
        let kv = param::knots::periodic(&par.params, p)?;
        let (curve, condition) = interpolate_closed_with(pts, &par.params[..pts.len()], kv)?;
        let mut params = par.params;
        params.pop();
        return Ok(CurveFit {
            curve,
            params,
            method: cfg.method,
            condition,
        });
    }
    let kv = match (&cfg.end_derivatives, par.knots) {
        (Some(_), _) => param::knots::with_end_derivatives(&par.params, p)?,
        (None, Some(k)) => k,
        (None, None) => param::knots::averaging(&par.params, p)?,
    };
    let (curve, condition) = interpolate_with(pts, &par.params, kv, cfg.end_derivatives)?;
    Ok(CurveFit {
        curve,
        params: par.params,
        method: cfg.method,
        condition,
    })
}

/// Interpolation with given parameters and clamped knots. Without end
/// derivatives the knot vector must carry `points.len()` basis functions, with
/// them `points.len() + 2` (rows `C'(u_0) = D_0` and `C'(u_n) = D_n` are added
/// next to the end rows). Returns the curve and the condition estimate.
pub fn interpolate_with(
    points: &[Point3],
    params: &[f64],
    kv: KnotVector,
    end_derivatives: Option<(Vector3, Vector3)>,
) -> Result<(Curve, f64)> {
    let n = points.len();
    let extra = if end_derivatives.is_some() { 2 } else { 0 };
    let count = kv.basis_count();
    if count != n + extra || params.len() != n || n < 2 {
        return Err(Error::InvalidInput(format!(
            "interpolation of {n} points{} needs {} basis functions and {n} parameters; got {count} and {}",
            if extra > 0 { " with end derivatives" } else { "" },
            n + extra,
            params.len()
        )));
    }
    // rows: (parameter, derivative order) and their right-hand sides
    let mut rows: Vec<(f64, usize)> = Vec::with_capacity(count);
    let mut values: Vec<f64> = Vec::with_capacity(count * 3);
    for (k, (&u, q)) in params.iter().zip(points).enumerate() {
        if let (Some((d0, _)), 1) = (end_derivatives, k) {
            rows.push((params[0], 1));
            values.extend_from_slice(d0.as_slice());
        }
        if let (Some((_, dn)), true) = (end_derivatives, k + 1 == n) {
            rows.push((params[n - 1], 1));
            values.extend_from_slice(dn.as_slice());
        }
        rows.push((u, 0));
        values.extend_from_slice(q.coords.as_slice());
    }
    let (ctrl, cond) = collocate(&rows, &values, 3, &kv, params)?;
    let ctrl = ctrl
        .chunks(3)
        .map(|c| Point3::new(c[0], c[1], c[2]))
        .collect();
    Ok((Curve::new(kv, ctrl)?, cond))
}

/// Solves the collocation system `sum_j N_j^(order_i)(u_i) X_j = V_i` for
/// `ncols` value columns (row-major, one row per collocation row) on a clamped
/// knot vector: banded LU without pivoting, condition check, iterative
/// refinement and a residual check (an accepted result reproduces the values to
/// 1e-9 relative). Returns the control values (row-major) and the condition.
pub(crate) fn collocate(
    rows: &[(f64, usize)],
    values: &[f64],
    ncols: usize,
    kv: &KnotVector,
    params: &[f64],
) -> Result<(Vec<f64>, f64)> {
    let p = kv.degree();
    let count = kv.basis_count();
    let t = kv.as_slice();
    let mut ws = BasisWorkspace::new(p, 1);
    // band widths from the actual structure
    let spans: Vec<usize> = rows.iter().map(|r| kv.find_span(r.0)).collect();
    let (mut kl, mut ku) = (0usize, 0usize);
    for (i, &s) in spans.iter().enumerate() {
        kl = kl.max(i.saturating_sub(s - p));
        ku = ku.max(s.saturating_sub(i));
    }
    let mut a = BandMatrix::zeros(count, kl, ku);
    for (i, ((u, order), &s)) in rows.iter().zip(&spans).enumerate() {
        let d = ws.ders(t, s, *u, *order);
        for j in 0..=p {
            a.set(i, s - p + j, d[order * (p + 1) + j]);
        }
    }
    let a0 = a.clone();
    let lu = a
        .factor("curve interpolation")
        .map_err(|e| with_hint(e, params))?;
    lu.check_condition(
        "curve interpolation",
        CONDITION_LIMIT,
        "the parameters crowd together; try centripetal or the proposed method",
    )?;
    let mut x = values.to_vec();
    lu.solve_in_place(&mut x, ncols);
    // Iterative refinement: on ill-conditioned (but accepted) systems the first
    // solution can miss the data by more than 1e-9; correcting with the residual
    // of the kept matrix restores a small residual, i.e. an exact interpolant.
    let scale = values.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let mut residual = f64::INFINITY;
    for _ in 0..3 {
        let mut r = values.to_vec();
        for i in 0..count {
            for j in i.saturating_sub(kl)..(i + ku + 1).min(count) {
                let v = a0.get(i, j);
                for c in 0..ncols {
                    r[i * ncols + c] -= v * x[j * ncols + c];
                }
            }
        }
        residual = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if residual <= 1e-14 * scale {
            break;
        }
        lu.solve_in_place(&mut r, ncols);
        x.iter_mut().zip(&r).for_each(|(x, d)| *x += d);
    }
    if residual > 1e-9 * scale {
        return Err(Error::Singular {
            what: "curve interpolation".into(),
            condition: lu.condition(),
            hint: format!(
                "the curve would miss the data by {residual:e}; try centripetal or a lower degree"
            ),
        });
    }
    Ok((x, lu.condition()))
}

/// Closed (periodic) interpolation: `points.len()` distinct points with
/// parameters in `[0, 1)` on a periodic knot vector (see
/// [`param::knots::periodic`]). The result is a periodic curve with
/// `points.len()` distinct control points.
pub fn interpolate_closed_with(
    points: &[Point3],
    params: &[f64],
    kv: KnotVector,
) -> Result<(Curve, f64)> {
    let n = points.len();
    let p = kv.degree();
    if params.len() != n {
        return Err(Error::InvalidInput(format!(
            "{} parameters for {n} points",
            params.len()
        )));
    }
    let values: Vec<f64> = points.iter().flat_map(|q| [q.x, q.y, q.z]).collect();
    let (x, cond) = collocate_closed(params, &values, 3, &kv)?;
    let mut ctrl: Vec<Point3> = x.chunks(3).map(|c| Point3::new(c[0], c[1], c[2])).collect();
    for j in 0..p {
        ctrl.push(ctrl[j]);
    }
    Ok((Curve::new_periodic(kv, ctrl, None)?, cond))
}

/// Periodic collocation for `ncols` value columns: `params.len()` rows in
/// `[0, 1)`, a periodic knot vector with `params.len() + p` basis functions.
/// Returns the `params.len()` distinct control values (row-major) and the
/// condition estimate.
pub(crate) fn collocate_closed(
    params: &[f64],
    values: &[f64],
    ncols: usize,
    kv: &KnotVector,
) -> Result<(Vec<f64>, f64)> {
    let n = params.len();
    let p = kv.degree();
    if kv.basis_count() != n + p {
        return Err(Error::InvalidInput(format!(
            "closed interpolation of {n} points needs {} basis functions; got {}",
            n + p,
            kv.basis_count()
        )));
    }
    if p > 31 {
        return Err(Error::InvalidInput(format!(
            "closed interpolation supports degrees up to 31, got {p}"
        )));
    }
    if n < 2 * p + 1 {
        return Err(Error::TooFewPoints {
            got: n,
            needed: 2 * p + 1,
            what: format!("closed interpolation of degree {p}"),
        });
    }
    let t = kv.as_slice();
    let mut ws = BasisWorkspace::new(p, 0);
    // Row k's largest entry belongs to control point k + shift (shift = p/2
    // rounded down for the standard knots). Unknowns are rotated by `shift` so
    // that it sits on the diagonal: otherwise the band block of the cyclic
    // solver is nearly triangular with small pivots and grows exponentially
    // ill-conditioned with n.
    let rows: Vec<(usize, [f64; 32])> = params
        .iter()
        .map(|&u| {
            let s = kv.find_span(u);
            let mut vals = [0.0; 32];
            vals[..=p].copy_from_slice(&ws.values(t, s, u)[..=p]);
            (s, vals)
        })
        .collect();
    let mut votes = vec![0usize; n];
    for (k, (s, vals)) in rows.iter().enumerate() {
        let jmax = (0..=p)
            .max_by(|&a, &b| vals[a].total_cmp(&vals[b]))
            .unwrap_or(0);
        votes[(s - p + jmax + n - k) % n] += 1;
    }
    let shift = (0..n).max_by_key(|&d| votes[d]).unwrap_or(0);
    let mut a = CyclicBandMatrix::zeros(n, p)?;
    for (k, (s, vals)) in rows.iter().enumerate() {
        for (j, &v) in vals[..=p].iter().enumerate() {
            a.add(k, (s - p + j + n - shift) % n, v);
        }
    }
    let mut x = values.to_vec();
    let cond = a.solve(&mut x, ncols, "closed curve interpolation")?;
    if cond > CONDITION_LIMIT {
        return Err(Error::Singular {
            what: "closed curve interpolation".into(),
            condition: cond,
            hint: "the parameters crowd together; try centripetal".into(),
        });
    }
    // undo the rotation: unknown c is control point (c + shift) mod n
    x.rotate_right(ncols * shift);
    Ok((x, cond))
}

/// Adds the parameter values to a singular-system error, since crowded or
/// coincident parameters are its usual cause.
fn with_hint(e: Error, params: &[f64]) -> Error {
    match e {
        Error::Singular {
            what,
            condition,
            hint,
        } => {
            let closest = params
                .windows(2)
                .enumerate()
                .min_by(|a, b| (a.1[1] - a.1[0]).total_cmp(&(b.1[1] - b.1[0])));
            let extra = closest.map_or(String::new(), |(i, w)| {
                format!(
                    "; closest parameters: points {i} and {} (u = {} and {})",
                    i + 1,
                    w[0],
                    w[1]
                )
            });
            Error::Singular {
                what,
                condition,
                hint: format!("{hint}{extra}"),
            }
        }
        other => other,
    }
}
