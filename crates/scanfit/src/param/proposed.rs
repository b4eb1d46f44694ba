//! [CURVE12]'s new parameterization method (section 3.2, Algorithm 1,
//! eqs. 3.2-3.4):
//!
//! 1. `u_i` from the exponential method with `a = 0.8`;
//! 2. the averaging knot vector `U` of those parameters;
//! 3. `theta_i`, the parameter of the maximum `B_i = max N_{i,d}(u)` of each basis
//!    function on `U`, found by Newton-Raphson on `N'_{i,d}(u) = 0` (eq. 3.2);
//! 4. pairwise median shift: for the pairs `(2i-1, 2i)`, `i = 1..n/2` (n even) or
//!    `i = 1..(n-1)/2` (n odd), with `m_theta = (theta_{2i-1} + theta_{2i})/2`,
//!    `m_u = (u_{2i-1} + u_{2i})/2` and `s_i = m_theta - m_u`, both parameters of
//!    the pair move by `s_i` (eqs. 3.3-3.4); then `u_0 = 0`, `u_n = 1`;
//! 5. the shifted `u_i` and the knot vector `U` of step 2 are the result.
//!
//! Points are `P_0..P_n` (n + 1 points), as section 3.2 states ("Assume P_i
//! are n + 1 number of given data points"); Algorithm 1's "n: Number of data
//! points" would shift the pairing by one, and we follow the section's text.
//! The shift does not guarantee increasing parameters (it fails on some
//! random data and on data set 6 at degree >= 16); that is reported as an
//! error naming the points, never returned. The pseudocode's `mu_i <- (u_{2i} +
//! u_{2i})/2` is a typo for `(u_{2i-1} + u_{2i})/2`, as eqs. 3.3-3.4 and the
//! symmetric role of the pair show.

use super::{basis_maximum, exponential, knots::averaging};
use crate::bspline::{BasisWorkspace, KnotVector};
use crate::{Point3, Result};

/// Parameters and knot vector of the new method with exponent `a` (paper: 0.8).
pub fn params(points: &[Point3], p: usize, a: f64) -> Result<(Vec<f64>, KnotVector)> {
    let mut u = exponential::params(points, a, false)?;
    super::check_increasing(&u, "exponential (the new method's first step)")?;
    let kv = averaging(&u, p)?;
    let mut ws = BasisWorkspace::new(p, 2);
    let theta: Vec<f64> = (0..points.len())
        .map(|i| basis_maximum(&kv, i, &mut ws).0)
        .collect();
    let n = points.len() - 1;
    let pairs = if n % 2 == 0 { n / 2 } else { (n - 1) / 2 };
    for i in 1..=pairs {
        let (j, k) = (2 * i - 1, 2 * i);
        let m_theta = 0.5 * (theta[j] + theta[k]);
        let m_u = 0.5 * (u[j] + u[k]);
        let s = m_theta - m_u;
        u[j] += s;
        u[k] += s;
    }
    u[0] = 0.0;
    u[n] = 1.0;
    Ok((u, kv))
}
