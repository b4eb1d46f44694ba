//! The polynomial pieces of a non-rational B-spline surface in power
//! (Taylor) form, for many evaluations of the point and its derivatives
//! (issue 18: the orthogonal distances of every point of a fit).
//!
//! Over each knot rectangle `[u_i, u_{i+1}) x [v_j, v_{j+1})` a B-spline
//! surface of degrees `(p, q)` is one polynomial; its Taylor expansion at
//! the rectangle's lower corner is exact:
//! `S(u, v) = sum_{k <= p, l <= q} c_kl s^k t^l`, `s = u - u_i`, `t = v - v_j`,
//! `c_kl = S_{u^k v^l}(u_i, v_j) / (k! l!)` ([NURBS97] section 6.6, the
//! power-basis form of a piece). The coefficients come from
//! [`Surface::derivatives_into`] once per rectangle; an evaluation is then a
//! lookup of the rectangle (a table over the breakpoints, no binary search)
//! and Horner-like sums of at most 16 terms, with no basis functions. The
//! values agree with [`Surface::derivatives_into`] to rounding (the test
//! checks 1e-13 of the control net's size plus the value's).

use rayon::prelude::*;

use crate::bspline::{BasisWorkspace, Surface};
use crate::Vector3;

/// Highest degree in each direction the power form is built for.
const MAX_DEGREE: usize = 3;

/// Rectangles of breakpoints in one direction, and a table that maps a
/// parameter to the rectangle at (or just before) it.
#[derive(Debug, Clone)]
struct Breaks {
    /// Distinct knots of the domain, ends included.
    at: Vec<f64>,
    /// `lookup[b]`: the last rectangle starting at or before the start of
    /// bucket `b` of `buckets` equal ones over the domain.
    lookup: Vec<u32>,
    scale: f64,
}

impl Breaks {
    fn new(at: Vec<f64>) -> Self {
        let spans = at.len() - 1;
        let buckets = 4 * spans;
        let (a, b) = (at[0], at[spans]);
        let scale = buckets as f64 / (b - a);
        let mut lookup = Vec::with_capacity(buckets);
        let mut i = 0;
        for k in 0..buckets {
            let x = a + k as f64 / scale;
            while i + 1 < spans && at[i + 1] <= x {
                i += 1;
            }
            lookup.push(i as u32);
        }
        Self { at, lookup, scale }
    }

    /// The rectangle of `x` (clamped to the domain): `at[i] <= x <
    /// at[i + 1]`, the last one at the right end.
    #[inline]
    fn span(&self, x: f64) -> usize {
        let spans = self.at.len() - 1;
        let b = ((x - self.at[0]) * self.scale).max(0.0);
        // NaN and values past the end go to the last bucket
        let b = if b < self.lookup.len() as f64 {
            b as usize
        } else {
            self.lookup.len() - 1
        };
        let mut i = self.lookup[b] as usize;
        while i + 1 < spans && self.at[i + 1] <= x {
            i += 1;
        }
        while i > 0 && x < self.at[i] {
            i -= 1;
        }
        i
    }
}

/// The power form of a non-rational B-spline surface of degrees up to 3.
#[derive(Debug, Clone)]
pub(crate) struct PowerForm {
    u: Breaks,
    v: Breaks,
    /// Coefficients per rectangle (`u` rectangle major), `c[k * 4 + l]`.
    coefficients: Vec<[Vector3; 16]>,
}

impl PowerForm {
    /// The power form of `surface`; `None` for a rational surface or a
    /// degree above 3 (those evaluate through [`Surface::derivatives_into`]).
    pub(crate) fn new(surface: &Surface) -> Option<Self> {
        let (p, q) = surface.degrees();
        if surface.weights().is_some() || p > MAX_DEGREE || q > MAX_DEGREE {
            return None;
        }
        let u = Breaks::new(surface.knots_u().breakpoints());
        let v = Breaks::new(surface.knots_v().breakpoints());
        let (nu, nv) = (u.at.len() - 1, v.at.len() - 1);
        let order = p + q;
        let width = order + 1;
        let factorial = [1.0, 1.0, 2.0, 6.0];
        let coefficients = (0..nu * nv)
            .into_par_iter()
            .map_init(
                || {
                    (
                        BasisWorkspace::new(p, order),
                        BasisWorkspace::new(q, order),
                        vec![Vector3::zeros(); width * width],
                    )
                },
                |(wu, wv, d), r| {
                    let (i, j) = (r / nv, r % nv);
                    surface.derivatives_into(u.at[i], v.at[j], wu, wv, order, d);
                    let mut c = [Vector3::zeros(); 16];
                    for k in 0..=p {
                        for l in 0..=q {
                            c[k * 4 + l] = d[k * width + l] / (factorial[k] * factorial[l]);
                        }
                    }
                    c
                },
            )
            .collect();
        Some(Self { u, v, coefficients })
    }

    /// `S` and its derivatives up to `order` (1 or 2) at `(u, v)` (clamped
    /// to the domain), in the layout of [`Surface::derivatives_into`]:
    /// `out[k * (order + 1) + l] = S_{u^k v^l}` for `k + l <= order`.
    #[inline]
    pub(crate) fn derivatives(&self, u: f64, v: f64, order: usize, out: &mut [Vector3]) {
        let (i, j) = (self.u.span(u), self.v.span(v));
        let c = &self.coefficients[i * (self.v.at.len() - 1) + j];
        let clamp = |x: f64, b: &Breaks| x.clamp(b.at[0], b.at[b.at.len() - 1]);
        let s = clamp(u, &self.u) - self.u.at[i];
        let t = clamp(v, &self.v) - self.v.at[j];
        // the monomials and their first and second derivatives
        let powers = |x: f64| {
            let (x2, x3) = (x * x, x * x * x);
            [
                [1.0, x, x2, x3],
                [0.0, 1.0, 2.0 * x, 3.0 * x2],
                [0.0, 0.0, 2.0, 6.0 * x],
            ]
        };
        let (ps, pt) = (powers(s), powers(t));
        let d1 = order + 1;
        // rows[m][l] = sum_k c_kl d^m/ds^m s^k
        let mut rows = [[Vector3::zeros(); 4]; 3];
        for (m, row) in rows.iter_mut().enumerate().take(d1) {
            for (l, r) in row.iter_mut().enumerate() {
                *r = c[l] * ps[m][0]
                    + c[4 + l] * ps[m][1]
                    + c[8 + l] * ps[m][2]
                    + c[12 + l] * ps[m][3];
            }
        }
        for k in 0..=order {
            for l in 0..=(order - k) {
                let r = &rows[k];
                out[k * d1 + l] =
                    r[0] * pt[l][0] + r[1] * pt[l][1] + r[2] * pt[l][2] + r[3] * pt[l][3];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::KnotVector;
    use crate::Point3;

    /// Degrees `(p, q)` with non-uniform knots, and wavy control points.
    fn surface(p: usize, q: usize) -> Surface {
        let knots = |d: usize, n: usize| {
            let inner: Vec<f64> = (1..n - d)
                .map(|i| {
                    let x = i as f64 / (n - d) as f64;
                    2.0 * (x + 0.3 * x * (1.0 - x) * (5.0 * x).sin())
                })
                .collect();
            KnotVector::clamped(d, 0.0, 2.0, &inner).unwrap()
        };
        let (nu, nv) = (9, 7);
        let c: Vec<Point3> = (0..nu * nv)
            .map(|k| {
                let (i, j) = ((k / nv) as f64, (k % nv) as f64);
                Point3::new(i, j + 0.2 * i, (i * 0.7).sin() * (j * 0.9).cos())
            })
            .collect();
        Surface::new(knots(p, nu), knots(q, nv), c).unwrap()
    }

    #[test]
    fn power_form_agrees_with_the_b_spline_evaluation() {
        for (p, q) in [(3, 3), (2, 3), (1, 2), (3, 1)] {
            let s = surface(p, q);
            let f = PowerForm::new(&s).unwrap();
            let ((u0, u1), (v0, v1)) = s.domain();
            let (mut wu, mut wv) = (BasisWorkspace::new(p, 2), BasisWorkspace::new(q, 2));
            let mut worst = 0.0f64;
            // relative to the control net's size (about 12) and the value
            let size = crate::geom::bbox_diagonal(s.control_points());
            // a grid that hits the breakpoints and the ends, and points past them
            for a in -2..=102 {
                for b in -2..=102 {
                    let u = u0 + (u1 - u0) * a as f64 / 100.0;
                    let v = v0 + (v1 - v0) * b as f64 / 100.0;
                    for order in [1, 2] {
                        let n = (order + 1) * (order + 1);
                        let (mut x, mut y) = ([Vector3::zeros(); 9], [Vector3::zeros(); 9]);
                        f.derivatives(u, v, order, &mut x[..n]);
                        s.derivatives_into(u, v, &mut wu, &mut wv, order, &mut y[..n]);
                        for k in 0..=order {
                            for l in 0..=(order - k) {
                                let i = k * (order + 1) + l;
                                let scale = size + y[i].norm();
                                worst = worst.max((x[i] - y[i]).norm() / scale);
                            }
                        }
                    }
                }
            }
            assert!(worst < 1e-13, "degrees {p} {q}: {worst}");
        }
    }

    #[test]
    fn rational_and_high_degree_surfaces_have_no_power_form() {
        let k = KnotVector::uniform_clamped(4, 5).unwrap();
        let c = vec![Point3::origin(); 25];
        assert!(PowerForm::new(&Surface::new(k.clone(), k, c).unwrap()).is_none());
    }
}
