//! Gram matrices of B-spline basis derivatives, `G^(k)_ij = ∫ N_i^(k)(u) N_j^(k)(u) du`
//! over the domain, integrated exactly by Gauss-Legendre quadrature on each
//! knot span (`N^(k)` has degree `p-k`, so `p - k + 1` nodes integrate the
//! product of degree `2(p-k)` exactly).
//!
//! They make the smoothing terms: the curve's bending energy `∫ |C''|^2 du` is
//! `G^(2)` (NURBS Book / de Boor's smoothing spline), and the surface's
//! thin-plate energy `∫∫ |S_uu|^2 + 2|S_uv|^2 + |S_vv|^2` is
//! `G^(2)_u ⊗ G^(0)_v + 2 G^(1)_u ⊗ G^(1)_v + G^(0)_u ⊗ G^(2)_v`.

use crate::bspline::{BasisWorkspace, KnotVector};

/// `(P_k(z), P_k'(z))` by the three-term recurrence (k >= 1, |z| < 1).
fn legendre(k: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    for j in 2..=k {
        let p2 = ((2 * j - 1) as f64 * z * p1 - (j - 1) as f64 * p0) / j as f64;
        p0 = p1;
        p1 = p2;
    }
    (p1, k as f64 * (z * p1 - p0) / (z * z - 1.0))
}

/// Gauss-Legendre nodes and weights on `[-1, 1]` (Newton on the Legendre
/// polynomial from the Chebyshev-like initial guess; accurate to rounding).
pub fn gauss_legendre(k: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; k];
    let mut w = vec![0.0; k];
    for i in 0..k {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (k as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (pk, dp) = legendre(k, z);
            let dz = pk / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let (_, dp) = legendre(k, z);
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// Calls `add(i, j, G^(order)_ij)` for every non-zero contribution (pairs within
/// one knot span, once per span: entries accumulate). Orders above the degree
/// give nothing (the derivative vanishes).
pub fn for_each_entry(kv: &KnotVector, order: usize, mut add: impl FnMut(usize, usize, f64)) {
    let p = kv.degree();
    if order > p {
        return;
    }
    let t = kv.as_slice();
    let (nodes, weights) = gauss_legendre(p - order + 1);
    let mut ws = BasisWorkspace::new(p, order);
    let q = p + 1;
    let (a, b) = kv.domain();
    for s in p..kv.basis_count() {
        let (lo, hi) = (t[s], t[s + 1]);
        if hi <= lo || lo < a || hi > b {
            continue;
        }
        let half = 0.5 * (hi - lo);
        let mid = 0.5 * (hi + lo);
        for (x, w) in nodes.iter().zip(&weights) {
            let u = mid + half * x;
            let d = ws.ders(t, s, u, order);
            let dk = &d[order * q..(order + 1) * q];
            for r in 0..q {
                for c in 0..q {
                    add(s - p + r, s - p + c, w * half * dk[r] * dk[c]);
                }
            }
        }
    }
}

/// The Gram matrix `G^(order)` as a dense band: `g[i * (2p+1) + (j - i + p)]`
/// (entries with `|i - j| > p` are zero). Used for the tensor-product energies.
pub fn band(kv: &KnotVector, order: usize) -> Vec<f64> {
    let p = kv.degree();
    let w = 2 * p + 1;
    let mut g = vec![0.0; kv.basis_count() * w];
    for_each_entry(kv, order, |i, j, v| g[i * w + j + p - i] += v);
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_rules_integrate_polynomials() {
        for k in 1..=6 {
            let (x, w) = gauss_legendre(k);
            for deg in 0..2 * k {
                let approx: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                assert!((approx - exact).abs() < 1e-14, "k={k} deg={deg}");
            }
        }
    }

    #[test]
    fn energy_of_a_parabola() {
        // C(u) = (u, u^2) as a clamped quadratic on [0,1]: C'' = (0, 2), energy = 4
        let kv = KnotVector::new(vec![0., 0., 0., 0.5, 1., 1., 1.], 2).unwrap();
        // control points of (u, u^2) on these knots (blossoming): y: 0, 0, 0.5, 1
        let cx = [0.0, 0.25, 0.75, 1.0];
        let cy = [0.0, 0.0, 0.5, 1.0];
        let mut e = 0.0;
        for_each_entry(&kv, 2, |i, j, g| e += g * (cx[i] * cx[j] + cy[i] * cy[j]));
        assert!((e - 4.0).abs() < 1e-13, "{e}");
    }

    #[test]
    fn order_zero_gram_integrates_partition_of_unity() {
        // sum_ij G0_ij = ∫ (sum_i N_i)^2 = domain length; order 1 sums to 0
        let kv = KnotVector::new(vec![0., 0., 0., 0., 0.3, 0.45, 1., 1., 1., 1.], 3).unwrap();
        for (order, want) in [(0, 1.0), (1, 0.0), (2, 0.0)] {
            let mut total = 0.0;
            for_each_entry(&kv, order, |_, _, g| total += g);
            assert!((total - want).abs() < 1e-13, "order {order}: {total}");
        }
        // and the band layout holds the same entries
        let g = band(&kv, 0);
        assert!((g.iter().sum::<f64>() - 1.0).abs() < 1e-13);
    }
}
