//! Knot placement for curve fitting ([NURBS97], chapter 9).

use crate::bspline::KnotVector;
use crate::{Error, Result};

/// Averaging knots for interpolation (de Boor; NURBS Book eq. 9.8):
/// `t_{j+p} = (1/p) sum_{i=j}^{j+p-1} u_i`, `j = 1..n-p`, clamped on `[0, 1]`.
pub fn averaging(params: &[f64], p: usize) -> Result<KnotVector> {
    let n = params.len() - 1;
    if n < p {
        return Err(Error::TooFewPoints {
            got: params.len(),
            needed: p + 1,
            what: format!("degree {p} interpolation"),
        });
    }
    let interior: Vec<f64> = (1..=n - p)
        .map(|j| params[j..j + p].iter().sum::<f64>() / p as f64)
        .collect();
    KnotVector::clamped(p, params[0], params[n], &interior)
}

/// Knots for least-squares approximation with `ctrl_count` control points
/// (NURBS Book eqs. 9.68-9.69): `d = (m+1)/(n-p+1)`, and for `j = 1..n-p`,
/// `i = floor(j d)`, `alpha = j d - i`, `t_{j+p} = (1-alpha) u_{i-1} + alpha u_i`.
/// Every knot span then holds at least one parameter, which keeps the normal
/// equations positive definite.
pub fn least_squares(params: &[f64], p: usize, ctrl_count: usize) -> Result<KnotVector> {
    let m = params.len() - 1;
    if ctrl_count < p + 1 {
        return Err(Error::InvalidInput(format!(
            "{ctrl_count} control points are too few for degree {p} (need at least {})",
            p + 1
        )));
    }
    if ctrl_count > params.len() {
        return Err(Error::InvalidInput(format!(
            "{ctrl_count} control points requested but only {} data points; use at most {} or interpolate",
            params.len(),
            params.len()
        )));
    }
    let interior = eq_9_69_interior(params, p, ctrl_count);
    KnotVector::clamped(p, params[0], params[m], &interior)
}

/// The interior knots of eqs. 9.68-9.69 for `ctrl_count` control points over the
/// sorted `params` (needs `p + 1 <= ctrl_count <= params.len()`).
pub fn eq_9_69_interior(params: &[f64], p: usize, ctrl_count: usize) -> Vec<f64> {
    eq_9_69_ranks(params.len(), p, ctrl_count)
        .into_iter()
        .map(|(i, alpha)| eq_9_69_knot(params[i - 1], params[i], alpha))
        .collect()
}

/// The ranks behind eq. 9.69 for `len` sorted parameters: per interior knot
/// `(i, alpha)`, the knot being [`eq_9_69_knot`] of the parameters of ranks
/// `i - 1` and `i` (0-based). What a chunked fit looks up when it cannot sort
/// all parameters at once (`scanfit::fit::knot_ranks`). Needs `p + 1 <=
/// ctrl_count <= len`.
pub fn eq_9_69_ranks(len: usize, p: usize, ctrl_count: usize) -> Vec<(usize, f64)> {
    let m = len - 1;
    let n = ctrl_count - 1;
    let d = (m + 1) as f64 / (n - p + 1) as f64;
    (1..=n.saturating_sub(p))
        .map(|j| {
            let jd = j as f64 * d;
            let i = (jd.floor() as usize).clamp(1, m);
            (i, jd - i as f64)
        })
        .collect()
}

/// Eq. 9.69's knot between the parameters `a` (rank `i - 1`) and `b` (rank `i`).
#[inline]
pub fn eq_9_69_knot(a: f64, b: f64, alpha: f64) -> f64 {
    (1.0 - alpha) * a + alpha * b
}

/// Knots for interpolation with prescribed first derivatives at both ends
/// (`n + 3` control points). Cubic: NURBS Book eq. 9.22 (interior knots at the
/// interior parameters); other degrees: eq. 9.21,
/// `t_{j+p+1} = (1/p) sum_{i=j}^{j+p-1} u_i`, `j = 0..n-p+1`.
pub fn with_end_derivatives(params: &[f64], p: usize) -> Result<KnotVector> {
    let n = params.len() - 1;
    if p < 2 {
        return Err(Error::InvalidInput(format!(
            "end derivatives need degree 2 or more (a degree-{p} curve has fixed end tangents)"
        )));
    }
    // n + 3 control points must be at least p + 1
    if n + 2 < p || n < 1 {
        return Err(Error::TooFewPoints {
            got: params.len(),
            needed: p.max(2),
            what: format!("degree {p} interpolation with end derivatives"),
        });
    }
    let interior: Vec<f64> = if p == 3 {
        params[1..n].to_vec()
    } else {
        (0..(n + 2 - p))
            .map(|j| params[j..j + p].iter().sum::<f64>() / p as f64)
            .collect()
    };
    KnotVector::clamped(p, params[0], params[n], &interior)
}

/// Periodic knots for closed interpolation. `params` holds `n + 1` values, the
/// last (1.0) being the closing copy of the first point. Inside the domain
/// `[0, 1]` the knots are the parameters for odd degrees and, for even degrees,
/// 0, the midpoints `(u_{i-1} + u_i)/2` for `i = 1..n-1`, and 1 (interpolating at
/// knots with an even degree can be singular). `p` knots are added at each end
/// continuing the spacing with period 1. This is also scipy's construction for
/// `make_interp_spline(..., bc_type="periodic")`.
pub fn periodic(params: &[f64], p: usize) -> Result<KnotVector> {
    let n = params.len() - 1;
    let inner: Vec<f64> = if p % 2 == 1 {
        params.to_vec()
    } else {
        let mut v = vec![params[0]];
        v.extend((1..n).map(|i| 0.5 * (params[i - 1] + params[i])));
        v.push(params[n]);
        v
    };
    let k = inner.len() - 1; // number of spans = distinct control points
    let period = inner[k] - inner[0];
    let mut t = Vec::with_capacity(k + 1 + 2 * p);
    for j in (1..=p).rev() {
        t.push(inner[k - j] - period);
    }
    t.extend_from_slice(&inner);
    for j in 1..=p {
        t.push(inner[j] + period);
    }
    KnotVector::new(t, p)
}

/// Periodic knots for closed least squares with `count` distinct control
/// points: the periodic analogue of eqs. 9.68-9.69. `params` holds the closed
/// parameters (`u_0 = 0, ..., u_n = 1`, the last for the repeated first point);
/// the domain knot `k_j` (`j = 0..=count`) is the parameter found a fraction
/// `j / count` of the way along the point sequence, interpolated linearly, so
/// every span holds about the same number of points. `p` knots continue the
/// spacing at each end with period 1.
pub fn periodic_least_squares(params: &[f64], p: usize, count: usize) -> Result<KnotVector> {
    let n = params.len() - 1; // number of distinct points
    if count < p + 1 || count > n {
        return Err(Error::InvalidInput(format!(
            "a closed curve of degree {p} through {n} points takes {} to {n} control points, {count} requested",
            p + 1
        )));
    }
    let inner: Vec<f64> = (0..=count)
        .map(|j| {
            let x = j as f64 * n as f64 / count as f64;
            let i = (x.floor() as usize).min(n - 1);
            let a = x - i as f64;
            (1.0 - a) * params[i] + a * params[i + 1]
        })
        .collect();
    let period = inner[count] - inner[0];
    let mut t = Vec::with_capacity(count + 1 + 2 * p);
    for j in (1..=p).rev() {
        t.push(inner[count - j] - period);
    }
    t.extend_from_slice(&inner);
    for j in 1..=p {
        t.push(inner[j] + period);
    }
    KnotVector::new(t, p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn averaging_matches_definition() {
        let u = [0.0, 0.1, 0.4, 0.5, 0.8, 1.0];
        let kv = averaging(&u, 3).unwrap();
        let t = kv.as_slice();
        assert_eq!(t.len(), 10);
        assert!((t[4] - (0.1 + 0.4 + 0.5) / 3.0).abs() < 1e-15);
        assert!((t[5] - (0.4 + 0.5 + 0.8) / 3.0).abs() < 1e-15);
    }

    #[test]
    fn least_squares_knots_eq_9_69() {
        let u: Vec<f64> = (0..=10).map(|k| (k as f64 / 10.0).powi(2)).collect();
        let kv = least_squares(&u, 3, 6).unwrap();
        // m = 10, n = 5, d = 11/3; j = 1: i = 3, alpha = 2/3
        let t = kv.as_slice();
        assert!((t[4] - (u[2] / 3.0 + 2.0 * u[3] / 3.0)).abs() < 1e-15);
        assert_eq!(kv.basis_count(), 6);
        assert!(least_squares(&u, 3, 12).is_err());
    }

    #[test]
    fn periodic_least_squares_knots_follow_the_points() {
        // 8 points crowded at the start: the knots follow them
        let u = [0.0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.5, 0.9, 1.0];
        let kv = periodic_least_squares(&u, 3, 4).unwrap();
        assert_eq!(kv.domain(), (0.0, 1.0));
        let t = kv.as_slice();
        assert!(
            (t[4] - 0.02).abs() < 1e-15 && (t[5] - 0.04).abs() < 1e-15,
            "{t:?}"
        );
        assert!(periodic_least_squares(&u, 3, 9).is_err());
    }

    #[test]
    fn end_derivative_knots_reject_bad_degrees() {
        assert!(with_end_derivatives(&[0.0, 0.5, 1.0], 1).is_err());
        assert!(with_end_derivatives(&[0.0, 0.5, 1.0], 4).is_ok());
        assert!(with_end_derivatives(&[0.0, 1.0], 5).is_err());
    }

    #[test]
    fn periodic_knots_have_period_one() {
        let u = [0.0, 0.2, 0.35, 0.7, 1.0];
        for p in [2, 3] {
            let kv = periodic(&u, p).unwrap();
            assert_eq!(kv.domain(), (0.0, 1.0));
            let t = kv.as_slice();
            let m = t.len() - 1;
            for j in 0..2 * p {
                let a = t[j + 1] - t[j];
                let b = t[m - 2 * p + j + 1] - t[m - 2 * p + j];
                assert!((a - b).abs() < 1e-15);
            }
        }
    }
}
