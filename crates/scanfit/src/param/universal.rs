//! Universal parameterization (Lim 1999; [CURVE12] Table 1 and Fig. 9(b)).
//!
//! The knot vector is uniform and clamped for `n + 1` control points, and each
//! parameter `u_i` is where the basis function `N_{i,p}` attains its maximum.
//! The method is affine invariant (it ignores the point positions entirely).

use super::basis_maximum;
use crate::bspline::{BasisWorkspace, KnotVector};
use crate::Result;

/// Parameters and the uniform clamped knots for `count` points and degree `p`.
pub fn params(count: usize, p: usize) -> Result<(Vec<f64>, KnotVector)> {
    let kv = KnotVector::uniform_clamped(p, count)?;
    let mut ws = BasisWorkspace::new(p, 2);
    let mut u: Vec<f64> = (0..count)
        .map(|i| basis_maximum(&kv, i, &mut ws).0)
        .collect();
    u[0] = 0.0;
    u[count - 1] = 1.0;
    Ok((u, kv))
}

#[cfg(test)]
mod tests {
    #[test]
    fn symmetric_and_at_knots_for_uniform_cubic() {
        let (u, kv) = super::params(8, 3).unwrap();
        for i in 0..8 {
            assert!((u[i] + u[7 - i] - 1.0).abs() < 1e-14);
        }
        // interior cubic functions on uniform knots peak at their middle knot
        let t = kv.as_slice();
        for i in 3..5 {
            assert!((u[i] - t[i + 2]).abs() < 1e-14);
        }
    }
}
