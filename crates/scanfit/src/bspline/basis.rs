//! B-spline basis functions and their derivatives (Cox–de Boor recursion).
//!
//! [`basis_funs`] is the NURBS Book's algorithm A2.2 (the `p+1` non-zero
//! functions `N_{s-p,p}(u) .. N_{s,p}(u)` on span `s`), [`BasisWorkspace::ders`]
//! is A2.3 (their derivatives up to order `n`). Both write into caller-provided
//! memory, so evaluation loops do not allocate.

/// Non-zero basis functions of degree `p` at `u` on span `span` (A2.2).
///
/// `out`, `left`, `right` must each hold at least `p + 1` values.
#[inline]
pub fn basis_funs(
    knots: &[f64],
    p: usize,
    span: usize,
    u: f64,
    out: &mut [f64],
    left: &mut [f64],
    right: &mut [f64],
) {
    out[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
}

/// Reusable scratch memory for basis functions and derivatives of one degree.
#[derive(Debug, Clone)]
pub struct BasisWorkspace {
    p: usize,
    left: Vec<f64>,
    right: Vec<f64>,
    ndu: Vec<f64>,
    a: Vec<f64>,
    /// Values `N_{s-p+j,p}` (`j = 0..=p`) after [`BasisWorkspace::values`].
    pub n: Vec<f64>,
    /// Derivatives after [`BasisWorkspace::ders`]: `ders[k * (p+1) + j]` is the
    /// `k`-th derivative of `N_{s-p+j,p}`.
    pub ders: Vec<f64>,
}

impl BasisWorkspace {
    /// Scratch memory for degree `p` and derivatives up to order `max_order`.
    pub fn new(p: usize, max_order: usize) -> Self {
        let q = p + 1;
        Self {
            p,
            left: vec![0.0; q],
            right: vec![0.0; q],
            ndu: vec![0.0; q * q],
            a: vec![0.0; 2 * q],
            n: vec![0.0; q],
            ders: vec![0.0; (max_order + 1) * q],
        }
    }

    /// Degree this workspace was made for.
    pub fn degree(&self) -> usize {
        self.p
    }

    /// Largest derivative order this workspace holds.
    pub fn max_order(&self) -> usize {
        self.ders.len() / (self.p + 1) - 1
    }

    /// Fills [`Self::n`] with the non-zero basis values at `u` on `span`.
    #[inline]
    pub fn values(&mut self, knots: &[f64], span: usize, u: f64) -> &[f64] {
        basis_funs(
            knots,
            self.p,
            span,
            u,
            &mut self.n,
            &mut self.left,
            &mut self.right,
        );
        &self.n
    }

    /// Fills [`Self::ders`] with derivatives of order `0..=order` of the non-zero
    /// basis functions at `u` on `span` (NURBS Book A2.3). Derivatives above the
    /// degree are zero. `order` is capped at [`Self::max_order`].
    pub fn ders(&mut self, knots: &[f64], span: usize, u: f64, order: usize) -> &[f64] {
        let p = self.p;
        let q = p + 1;
        let order = order.min(self.max_order());
        let ndu = &mut self.ndu;
        let (left, right) = (&mut self.left, &mut self.right);
        // ndu[j][r] (row j, column r) stored as ndu[j * q + r]: basis values in the
        // upper triangle (column = function, row = degree), and below it the
        // reciprocals of the knot differences of A2.3 (each difference is only
        // ever divided by, so storing 1/x turns ~4p^2 divisions into p(p+1)/2).
        ndu[0] = 1.0;
        for j in 1..=p {
            left[j] = u - knots[span + 1 - j];
            right[j] = knots[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j * q + r] = 1.0 / (right[r + 1] + left[j - r]);
                let temp = ndu[r * q + j - 1] * ndu[j * q + r];
                ndu[r * q + j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j * q + j] = saved;
        }
        let ders = &mut self.ders;
        ders.iter_mut().for_each(|d| *d = 0.0);
        for j in 0..=p {
            ders[j] = ndu[j * q + p];
        }
        let a = &mut self.a; // two rows of length q
        for r in 0..=p {
            let (mut s1, mut s2) = (0usize, 1usize);
            a[0] = 1.0;
            for k in 1..=order.min(p) {
                let mut d = 0.0;
                let rk = r as isize - k as isize;
                let pk = p - k;
                if r >= k {
                    let rk = rk as usize;
                    a[s2 * q] = a[s1 * q] * ndu[(pk + 1) * q + rk];
                    d = a[s2 * q] * ndu[rk * q + pk];
                }
                let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2 = if (r as isize - 1) <= pk as isize {
                    k - 1
                } else {
                    p - r
                };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    a[s2 * q + j] = (a[s1 * q + j] - a[s1 * q + j - 1]) * ndu[(pk + 1) * q + idx];
                    d += a[s2 * q + j] * ndu[idx * q + pk];
                }
                if r <= pk {
                    a[s2 * q + k] = -a[s1 * q + k - 1] * ndu[(pk + 1) * q + r];
                    d += a[s2 * q + k] * ndu[r * q + pk];
                }
                ders[k * q + r] = d;
                std::mem::swap(&mut s1, &mut s2);
            }
        }
        // multiply by p!/(p-k)!
        let mut fac = p as f64;
        for k in 1..=order.min(p) {
            for j in 0..=p {
                ders[k * q + j] *= fac;
            }
            fac *= (p - k) as f64;
        }
        &self.ders[..(order + 1) * q]
    }
}

/// Value and derivatives `0..=order` of the single basis function `N_{i,p}` at `u`
/// (zero outside its support `[t_i, t_{i+p+1})`; the right end of the domain
/// belongs to the last span). Written into `out[0..=order]`.
pub fn single_basis_ders(
    knots: &[f64],
    p: usize,
    i: usize,
    u: f64,
    ws: &mut BasisWorkspace,
    out: &mut [f64],
) {
    let order = out.len() - 1;
    out.iter_mut().for_each(|v| *v = 0.0);
    let span = super::knots::find_span(knots, p, u);
    if i + p < span || i > span {
        return;
    }
    let j = i + p - span;
    let q = p + 1;
    let d = ws.ders(knots, span, u, order);
    for (k, o) in out
        .iter_mut()
        .enumerate()
        .take(order.min(d.len() / q - 1) + 1)
    {
        *o = d[k * q + j];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::KnotVector;

    fn knots() -> KnotVector {
        KnotVector::new(vec![0., 0., 0., 0., 0.2, 0.5, 0.55, 0.8, 1., 1., 1., 1.], 3).unwrap()
    }

    #[test]
    fn partition_of_unity_and_nonnegativity() {
        for p in 1..=5 {
            let kv = KnotVector::uniform_clamped(p, p + 6).unwrap();
            let mut ws = BasisWorkspace::new(p, 0);
            for k in 0..=200 {
                let u = k as f64 / 200.0;
                let s = kv.find_span(u);
                let n = ws.values(kv.as_slice(), s, u);
                let sum: f64 = n.iter().sum();
                assert!((sum - 1.0).abs() < 1e-14, "p={p} u={u} sum={sum}");
                assert!(n.iter().all(|&v| v >= -1e-15));
            }
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let kv = knots();
        let t = kv.as_slice();
        let p = 3;
        let mut ws = BasisWorkspace::new(p, 3);
        let mut ws2 = BasisWorkspace::new(p, 3);
        let h = 1e-6;
        for &u in &[0.1, 0.3, 0.52, 0.7, 0.9] {
            let s = kv.find_span(u);
            let d: Vec<f64> = ws.ders(t, s, u, 3).to_vec();
            // order 0 equals A2.2
            let n = ws2.values(t, s, u).to_vec();
            for j in 0..=p {
                assert!((d[j] - n[j]).abs() < 1e-15);
            }
            // derivatives: central differences of order k-1 (same span)
            for k in 1..=3 {
                let dp = ws2.ders(t, s, u + h, 3)[(k - 1) * 4..k * 4].to_vec();
                let dm = ws2.ders(t, s, u - h, 3)[(k - 1) * 4..k * 4].to_vec();
                for j in 0..=p {
                    let fd = (dp[j] - dm[j]) / (2.0 * h);
                    let tol = 1e-6 * (1.0 + fd.abs()) * if k == 3 { 10.0 } else { 1.0 };
                    assert!(
                        (d[k * 4 + j] - fd).abs() < tol,
                        "k={k} j={j} u={u}: {} vs {fd}",
                        d[k * 4 + j]
                    );
                }
            }
            // derivatives of a partition of unity sum to zero
            for k in 1..=3 {
                let s: f64 = d[k * 4..k * 4 + 4].iter().sum();
                assert!(s.abs() < 1e-9, "k={k}: {s}");
            }
        }
    }

    #[test]
    fn derivatives_above_degree_vanish() {
        let kv = KnotVector::uniform_clamped(2, 5).unwrap();
        let mut ws = BasisWorkspace::new(2, 4);
        let s = kv.find_span(0.4);
        let d = ws.ders(kv.as_slice(), s, 0.4, 4).to_vec();
        assert!(d[9..].iter().all(|&v| v == 0.0));
    }

    #[test]
    fn single_function_value() {
        let kv = knots();
        let mut ws = BasisWorkspace::new(3, 2);
        let mut out = [0.0; 3];
        // N_0 at u = 0 is 1 (clamped), N_3 vanishes at 0
        single_basis_ders(kv.as_slice(), 3, 0, 0.0, &mut ws, &mut out);
        assert_eq!(out[0], 1.0);
        single_basis_ders(kv.as_slice(), 3, 3, 0.0, &mut ws, &mut out);
        assert_eq!(out[0], 0.0);
        let mut total = 0.0;
        for i in 0..kv.basis_count() {
            single_basis_ders(kv.as_slice(), 3, i, 0.63, &mut ws, &mut out);
            total += out[0];
        }
        assert!((total - 1.0).abs() < 1e-14);
    }
}
