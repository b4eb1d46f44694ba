//! Maximum of a single B-spline basis function `N_{i,p}` over the domain.
//!
//! Used by the universal method (Lim 1999), the hybrid method (eq. 3.1) and the
//! paper's new method (step 3, eq. 3.2: `B_i = max N_{i,d}(u)`, found "by
//! solving N'_{i,d}(u) = 0 ... using numerical method such as Newton-Raphson").
//! A basis function is unimodal on its support, so its derivative changes sign
//! once: we find the span where it does and run Newton on `N' = 0` there,
//! safeguarded by bisection so it cannot leave the bracket.

use crate::bspline::{BasisWorkspace, KnotVector};

/// `(theta_i, B_i)`: the parameter where `N_{i,p}` takes its maximum over the
/// domain and that maximum. When the maximum sits at a knot where `N'` jumps
/// (multiple knots, degree 1), the knot is returned.
pub fn basis_maximum(kv: &KnotVector, i: usize, ws: &mut BasisWorkspace) -> (f64, f64) {
    let t = kv.as_slice();
    let p = kv.degree();
    let n = kv.basis_count() - 1;
    let (dlo, dhi) = kv.domain();
    let lo = t[i].max(dlo);
    let hi = t[i + p + 1].min(dhi);
    // value and derivatives of N_i evaluated with the polynomial of span s
    let mut eval = |s: usize, u: f64, order: usize| -> [f64; 3] {
        let mut out = [0.0; 3];
        if i + p < s || i > s {
            return out;
        }
        let d = ws.ders(t, s, u, order);
        let q = p + 1;
        for (k, o) in out
            .iter_mut()
            .enumerate()
            .take(order.min(d.len() / q - 1) + 1)
        {
            *o = d[k * q + i + p - s];
        }
        out
    };
    let mut last = (lo, 0.0);
    // only the p + 1 spans of the support [t_i, t_{i+p+1}) (O(p) per function)
    for s in i.max(p)..=(i + p).min(n) {
        let (a, b) = (t[s], t[s + 1]);
        if b <= a || a < lo || b > hi {
            continue;
        }
        let [na, da, _] = eval(s, a, 1);
        let [nb, db, _] = eval(s, b, 1);
        let tol = 1e-13 * na.max(nb).max(1e-300) / (b - a);
        // falling already at the start of this span: the maximum is at `a`
        if na > 0.0 && da <= tol {
            return (a, na);
        }
        if db <= 0.0 {
            // N' changes sign in (a, b], safeguarded Newton on N' = 0. `db` can be
            // exactly 0 where the support ends at a clamped domain end (N_{n-2}
            // of a clamped cubic), so `<=`: the bracket still converges to the
            // interior root, or to `b` if N rises all the way.
            let (mut l, mut r) = (a, b);
            let mut x = 0.5 * (a + b);
            for _ in 0..100 {
                let [_, f, fp] = eval(s, x, 2);
                if f > 0.0 {
                    l = x;
                } else {
                    r = x;
                }
                let newton = if fp < 0.0 { x - f / fp } else { f64::NAN };
                let next = if newton > l && newton < r {
                    newton
                } else {
                    0.5 * (l + r)
                };
                let step = (next - x).abs();
                x = next;
                if step <= 4.0 * f64::EPSILON * (b - a).max(x.abs())
                    || r - l <= f64::EPSILON * x.abs()
                {
                    break;
                }
            }
            let [nx, _, _] = eval(s, x, 0);
            return (x, nx);
        }
        last = (b, nb);
    }
    last
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_cubic_interior_maximum_is_two_thirds_at_centre() {
        // uniform knots: interior cubic B-spline peaks at the middle knot with 2/3
        let kv = KnotVector::uniform_clamped(3, 10).unwrap();
        let mut ws = BasisWorkspace::new(3, 2);
        let (theta, b) = basis_maximum(&kv, 5, &mut ws);
        let t = kv.as_slice();
        assert!((theta - t[7]).abs() < 1e-14, "{theta} vs {}", t[7]);
        assert!((b - 2.0 / 3.0).abs() < 1e-14);
        // ends of a clamped vector peak at the domain ends with value 1
        assert_eq!(basis_maximum(&kv, 0, &mut ws), (0.0, 1.0));
        assert_eq!(basis_maximum(&kv, 9, &mut ws), (1.0, 1.0));
    }

    #[test]
    fn maximum_is_a_true_maximum() {
        let kv =
            KnotVector::new(vec![0., 0., 0., 0., 0.1, 0.15, 0.6, 0.9, 1., 1., 1., 1.], 3).unwrap();
        let mut ws = BasisWorkspace::new(3, 2);
        let mut ws2 = BasisWorkspace::new(3, 0);
        for i in 0..kv.basis_count() {
            let (theta, b) = basis_maximum(&kv, i, &mut ws);
            let mut best = 0.0f64;
            for k in 0..=20000 {
                let u = k as f64 / 20000.0;
                let mut v = [0.0];
                crate::bspline::single_basis_ders(kv.as_slice(), 3, i, u, &mut ws2, &mut v);
                best = best.max(v[0]);
            }
            assert!(b >= best - 1e-12, "i={i}: {b} < sampled {best}");
            assert!((0.0..=1.0).contains(&theta));
        }
    }

    #[test]
    fn support_ending_at_clamped_end() {
        // N_7 of a clamped cubic with 10 functions: N'(1) = 0 and N(1) = 0, the
        // maximum is inside the last span (regression: was reported at u = 1)
        let t = vec![
            0., 0., 0., 0., 0.24, 0.356, 0.468, 0.5675, 0.6688, 0.7804, 1., 1., 1., 1.,
        ];
        let kv = KnotVector::new(t, 3).unwrap();
        let mut ws = BasisWorkspace::new(3, 2);
        let (theta, b) = basis_maximum(&kv, 7, &mut ws);
        assert!(theta > 0.6688 && theta < 1.0, "{theta}");
        assert!(b > 0.5, "{b}");
    }

    #[test]
    fn degree_one_peaks_at_knots() {
        let kv = KnotVector::new(vec![0., 0., 0.3, 0.7, 1., 1.], 1).unwrap();
        let mut ws = BasisWorkspace::new(1, 2);
        for (i, knot) in [(1, 0.3), (2, 0.7)] {
            let (theta, b) = basis_maximum(&kv, i, &mut ws);
            assert_eq!(theta, knot);
            assert!((b - 1.0).abs() < 1e-15);
        }
    }
}
