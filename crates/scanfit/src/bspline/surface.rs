//! Tensor-product B-spline (and NURBS) surfaces: evaluation, partial derivatives,
//! knot insertion in either direction.
//!
//! Algorithms from [NURBS97]: A3.5 (point), A3.6 (derivatives), A4.4
//! (rational derivatives), A5.3 (surface knot insertion, done here as A5.1 on
//! every row or column of the control net).

use super::basis::{basis_funs, BasisWorkspace};
use super::curve::{binomial, insert_homogeneous, validate_weights, STACK_DEGREE};
use super::knots::{find_span, KnotVector};
use crate::{Error, Point3, Result, Vector3};

/// A tensor-product B-spline surface `S(u,v) = sum_i sum_j N_i(u) M_j(v) P_ij`.
///
/// Control points are stored row-major with `u` the slow index:
/// `P_ij = ctrl[i * count_v + j]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    knots_u: KnotVector,
    knots_v: KnotVector,
    ctrl: Vec<Point3>,
    weights: Option<Vec<f64>>,
    periodic_u: bool,
    periodic_v: bool,
}

/// Which parameter direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// The `u` direction (first index of the control net).
    U,
    /// The `v` direction (second index of the control net).
    V,
}

impl Surface {
    /// The same surface moved by `by` (every control point; weights, knots
    /// and periodicity kept): used to evaluate far from the origin about a
    /// nearby centre without losing digits.
    pub(crate) fn translated(&self, by: nalgebra::Vector3<f64>) -> Self {
        let mut s = self.clone();
        s.ctrl.iter_mut().for_each(|p| *p += by);
        s
    }

    /// A non-rational surface.
    pub fn new(knots_u: KnotVector, knots_v: KnotVector, ctrl: Vec<Point3>) -> Result<Self> {
        Self::with_options(knots_u, knots_v, ctrl, None, false, false)
    }

    /// A surface with optional weights and periodicity flags (a periodic direction
    /// must repeat its first `p` rows of control points at its end).
    pub fn with_options(
        knots_u: KnotVector,
        knots_v: KnotVector,
        ctrl: Vec<Point3>,
        weights: Option<Vec<f64>>,
        periodic_u: bool,
        periodic_v: bool,
    ) -> Result<Self> {
        let (nu, nv) = (knots_u.basis_count(), knots_v.basis_count());
        if ctrl.len() != nu * nv {
            return Err(Error::InvalidInput(format!(
                "{} control points given, but the knot vectors need {nu} x {nv} = {}",
                ctrl.len(),
                nu * nv
            )));
        }
        crate::validate_points(&ctrl)?;
        if let Some(w) = &weights {
            validate_weights(w, ctrl.len())?;
        }
        let s = Self {
            knots_u,
            knots_v,
            ctrl,
            weights,
            periodic_u,
            periodic_v,
        };
        if periodic_u {
            let p = s.knots_u.degree();
            for i in 0..p {
                for j in 0..nv {
                    if s.ctrl[(nu - p + i) * nv + j] != s.ctrl[i * nv + j] {
                        return Err(Error::InvalidInput(format!(
                            "periodic in u: control row {} must repeat row {i}",
                            nu - p + i
                        )));
                    }
                }
            }
        }
        if periodic_v {
            let q = s.knots_v.degree();
            for i in 0..nu {
                for j in 0..q {
                    if s.ctrl[i * nv + nv - q + j] != s.ctrl[i * nv + j] {
                        return Err(Error::InvalidInput(format!(
                            "periodic in v: control column {} must repeat column {j}",
                            nv - q + j
                        )));
                    }
                }
            }
        }
        Ok(s)
    }

    /// Knot vector in `u`.
    pub fn knots_u(&self) -> &KnotVector {
        &self.knots_u
    }
    /// Knot vector in `v`.
    pub fn knots_v(&self) -> &KnotVector {
        &self.knots_v
    }
    /// Degrees `(p, q)`.
    pub fn degrees(&self) -> (usize, usize) {
        (self.knots_u.degree(), self.knots_v.degree())
    }
    /// Control-net size `(count_u, count_v)`.
    pub fn counts(&self) -> (usize, usize) {
        (self.knots_u.basis_count(), self.knots_v.basis_count())
    }
    /// Control points, row-major (`u` slow).
    pub fn control_points(&self) -> &[Point3] {
        &self.ctrl
    }
    /// Control point `P_ij`.
    pub fn control_point(&self, i: usize, j: usize) -> Point3 {
        self.ctrl[i * self.knots_v.basis_count() + j]
    }
    /// Weights, if rational.
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
    /// Periodicity flags `(u, v)`.
    pub fn periodic(&self) -> (bool, bool) {
        (self.periodic_u, self.periodic_v)
    }
    /// Domains `((u0, u1), (v0, v1))`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        (self.knots_u.domain(), self.knots_v.domain())
    }

    /// Point at `(u, v)` (A3.5, homogeneous for rational surfaces). Allocation-free
    /// for degrees <= 15.
    pub fn point(&self, u: f64, v: f64) -> Point3 {
        let (p, q) = self.degrees();
        if p > STACK_DEGREE || q > STACK_DEGREE {
            let mut wu = BasisWorkspace::new(p, 0);
            let mut wv = BasisWorkspace::new(q, 0);
            let mut out = [Vector3::zeros()];
            self.derivatives_into(u, v, &mut wu, &mut wv, 0, &mut out);
            return Point3::from(out[0]);
        }
        let u = self.knots_u.wrap(u, self.periodic_u);
        let v = self.knots_v.wrap(v, self.periodic_v);
        let (tu, tv) = (self.knots_u.as_slice(), self.knots_v.as_slice());
        let (su, sv) = (find_span(tu, p, u), find_span(tv, q, v));
        let mut nu = [0.0; STACK_DEGREE + 1];
        let mut nv = [0.0; STACK_DEGREE + 1];
        let mut l = [0.0; STACK_DEGREE + 1];
        let mut r = [0.0; STACK_DEGREE + 1];
        basis_funs(tu, p, su, u, &mut nu, &mut l, &mut r);
        basis_funs(tv, q, sv, v, &mut nv, &mut l, &mut r);
        let cv = self.knots_v.basis_count();
        let mut acc = Vector3::zeros();
        let mut wsum = 0.0;
        for a in 0..=p {
            let row = (su - p + a) * cv + sv - q;
            for b in 0..=q {
                let w = self.weights.as_ref().map_or(1.0, |w| w[row + b]);
                let c = nu[a] * nv[b] * w;
                acc += self.ctrl[row + b].coords * c;
                wsum += c;
            }
        }
        Point3::from(acc / wsum)
    }

    /// Partial derivatives `S_{u^k v^l}` for `k + l <= order`, written to
    /// `out[k * (order + 1) + l]` (length `(order+1)^2`; entries with `k+l > order`
    /// are zero). A3.6, and A4.4 for rational surfaces. The workspaces must have
    /// the surface's degrees and `max_order >= order`.
    pub fn derivatives_into(
        &self,
        u: f64,
        v: f64,
        wu: &mut BasisWorkspace,
        wv: &mut BasisWorkspace,
        order: usize,
        out: &mut [Vector3],
    ) {
        let (p, q) = self.degrees();
        let d1 = order + 1;
        let u = self.knots_u.wrap(u, self.periodic_u);
        let v = self.knots_v.wrap(v, self.periodic_v);
        let (tu, tv) = (self.knots_u.as_slice(), self.knots_v.as_slice());
        let (su, sv) = (find_span(tu, p, u), find_span(tv, q, v));
        let du = wu.ders(tu, su, u, order);
        let dv = wv.ders(tv, sv, v, order);
        let (ku, kv) = (du.len() / (p + 1) - 1, dv.len() / (q + 1) - 1);
        let cv = self.knots_v.basis_count();
        out.iter_mut().for_each(|o| *o = Vector3::zeros());
        if self.weights.is_none() && (order + 1) * (p + 1) <= 64 {
            // Non-rational fast path, contracted in two stages: first along v,
            // tmp[l][a] = sum_b M_b^(l)(v) P_{a,b}, then along u,
            // S^(k,l) = sum_a N_a^(k)(u) tmp[l][a].
            let mut tmp = [Vector3::zeros(); 64];
            let lmax = order.min(kv);
            for a in 0..=p {
                let row = (su - p + a) * cv + sv - q;
                let ctrl = &self.ctrl[row..=row + q];
                for l in 0..=lmax {
                    let dvl = &dv[l * (q + 1)..(l + 1) * (q + 1)];
                    let mut acc = Vector3::zeros();
                    for (c, &m) in ctrl.iter().zip(dvl) {
                        acc += c.coords * m;
                    }
                    tmp[l * (p + 1) + a] = acc;
                }
            }
            for k in 0..=order.min(ku) {
                let duk = &du[k * (p + 1)..(k + 1) * (p + 1)];
                for l in 0..=(order - k).min(lmax) {
                    let mut acc = Vector3::zeros();
                    for (t, &nk) in tmp[l * (p + 1)..(l + 1) * (p + 1)].iter().zip(duk) {
                        acc += t * nk;
                    }
                    out[k * d1 + l] = acc;
                }
            }
            return;
        }
        // homogeneous derivatives A^(k,l) and w^(k,l) (w = 1 when non-rational);
        // orders above 7 are not supported for rational surfaces (stack buffer)
        // (stride 8 in `wd`: orders up to 7)
        let mut wd = [0.0f64; 64];
        let order = if self.weights.is_some() {
            order.min(7)
        } else {
            order
        };
        let wi = |k: usize, l: usize| k * 8 + l;
        for k in 0..=order.min(ku) {
            for l in 0..=(order - k).min(kv) {
                let mut acc = Vector3::zeros();
                let mut wacc = 0.0;
                for a in 0..=p {
                    let row = (su - p + a) * cv + sv - q;
                    let nu = du[k * (p + 1) + a];
                    for b in 0..=q {
                        let w = self.weights.as_ref().map_or(1.0, |w| w[row + b]);
                        let c = nu * dv[l * (q + 1) + b] * w;
                        acc += self.ctrl[row + b].coords * c;
                        wacc += c;
                    }
                }
                out[k * d1 + l] = acc;
                if k < 8 && l < 8 {
                    wd[wi(k, l)] = wacc;
                }
            }
        }
        if self.weights.is_none() {
            return;
        }
        // A4.4: quotient rule for rational surfaces
        for k in 0..=order {
            for l in 0..=(order - k) {
                let mut v = out[k * d1 + l];
                for j in 1..=l {
                    v -= out[k * d1 + l - j] * (binomial(l, j) * wd[wi(0, j)]);
                }
                for i in 1..=k {
                    v -= out[(k - i) * d1 + l] * (binomial(k, i) * wd[wi(i, 0)]);
                    let mut v2 = Vector3::zeros();
                    for j in 1..=l {
                        v2 += out[(k - i) * d1 + l - j] * (binomial(l, j) * wd[wi(i, j)]);
                    }
                    v -= v2 * binomial(k, i);
                }
                out[k * d1 + l] = v / wd[wi(0, 0)];
            }
        }
    }

    /// Unit normal `S_u x S_v / |S_u x S_v|` at `(u, v)` (zero where degenerate).
    pub fn normal(
        &self,
        u: f64,
        v: f64,
        wu: &mut BasisWorkspace,
        wv: &mut BasisWorkspace,
    ) -> Vector3 {
        let mut d = [Vector3::zeros(); 4];
        self.derivatives_into(u, v, wu, wv, 1, &mut d);
        let n = d[2].cross(&d[1]);
        let len = n.norm();
        if len > 0.0 {
            n / len
        } else {
            n
        }
    }

    /// Inserts knot `x` `r` times in direction `dir`; the shape is unchanged.
    pub fn insert_knot(&self, dir: Direction, x: f64, r: usize) -> Result<Self> {
        let (cu, cv) = self.counts();
        let kv = match dir {
            Direction::U => &self.knots_u,
            Direction::V => &self.knots_v,
        };
        let p = kv.degree();
        let (a, b) = kv.domain();
        if !(x > a && x < b) {
            return Err(Error::InvalidInput(format!(
                "knot {x} to insert lies outside the open domain ({a}, {b})"
            )));
        }
        let s = kv.multiplicity(x);
        if s + r > p {
            return Err(Error::InvalidInput(format!(
                "inserting {x} {r} times would raise its multiplicity to {} > degree {p}",
                s + r
            )));
        }
        if r == 0 {
            return Ok(self.clone());
        }
        let t = kv.as_slice();
        let k = find_span(t, p, x);
        let hw = |i: usize| {
            let c = self.ctrl[i];
            let w = self.weights.as_ref().map_or(1.0, |w| w[i]);
            [c.x * w, c.y * w, c.z * w, w]
        };
        let (lines, len) = match dir {
            Direction::U => (cv, cu),
            Direction::V => (cu, cv),
        };
        let mut new_knots = Vec::new();
        let new_len = len + r;
        let mut out = vec![[0.0; 4]; lines * new_len];
        for line in 0..lines {
            let pw: Vec<[f64; 4]> = (0..len)
                .map(|e| match dir {
                    Direction::U => hw(e * cv + line),
                    Direction::V => hw(line * cv + e),
                })
                .collect();
            let (nk, q) = insert_homogeneous(t, p, &pw, x, k, s, r);
            new_knots = nk;
            for (e, h) in q.into_iter().enumerate() {
                let idx = match dir {
                    Direction::U => e * cv + line,
                    Direction::V => line * new_len + e,
                };
                out[idx] = h;
            }
        }
        let ctrl = out
            .iter()
            .map(|h| Point3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3]))
            .collect();
        let weights = self
            .weights
            .as_ref()
            .map(|_| out.iter().map(|h| h[3]).collect());
        let new_kv = KnotVector::new(new_knots, p)?;
        let (ku, kvv) = match dir {
            Direction::U => (new_kv, self.knots_v.clone()),
            Direction::V => (self.knots_u.clone(), new_kv),
        };
        // as for curves, insertion leaves the repeated-row periodic form
        let (pu, pv) = match dir {
            Direction::U => (false, self.periodic_v),
            Direction::V => (self.periodic_u, false),
        };
        Self::with_options(ku, kvv, ctrl, weights, pu, pv)
    }

    /// Inserts all knots `xs` in direction `dir` (knot refinement).
    pub fn refine(&self, dir: Direction, xs: &[f64]) -> Result<Self> {
        let mut s = self.clone();
        for &x in xs {
            s = s.insert_knot(dir, x, 1)?;
        }
        Ok(s)
    }
}

/// A surface translates with its control points (also a rational one: the
/// basis sums to one).
impl crate::centring::Translate for Surface {
    fn translate(&mut self, by: &Vector3) {
        for p in &mut self.ctrl {
            *p += by;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(rational: bool) -> Surface {
        let ku = KnotVector::new(vec![0., 0., 0., 0., 0.4, 1., 1., 1., 1.], 3).unwrap();
        let kv = KnotVector::new(vec![0., 0., 0., 0.5, 1., 1., 1.], 2).unwrap();
        let mut ctrl = Vec::new();
        let mut w = Vec::new();
        for i in 0..5 {
            for j in 0..4 {
                let (x, y) = (i as f64, j as f64);
                ctrl.push(Point3::new(x, y, (x * 0.7).sin() + (y * 1.3).cos()));
                w.push(1.0 + 0.1 * ((i * 4 + j) % 5) as f64);
            }
        }
        Surface::with_options(ku, kv, ctrl, rational.then_some(w), false, false).unwrap()
    }

    #[test]
    fn partials_match_finite_differences() {
        for rational in [false, true] {
            let s = sample(rational);
            let mut wu = BasisWorkspace::new(3, 2);
            let mut wv = BasisWorkspace::new(2, 2);
            let mut d = [Vector3::zeros(); 9];
            let h = 1e-6;
            for &(u, v) in &[(0.2, 0.3), (0.6, 0.7), (0.9, 0.1)] {
                s.derivatives_into(u, v, &mut wu, &mut wv, 2, &mut d);
                assert!((Point3::from(d[0]) - s.point(u, v)).norm() < 1e-13);
                let fu = (s.point(u + h, v) - s.point(u - h, v)) / (2.0 * h);
                let fv = (s.point(u, v + h) - s.point(u, v - h)) / (2.0 * h);
                assert!(
                    (d[3] - fu).norm() < 1e-6 * (1.0 + fu.norm()),
                    "rational={rational}"
                );
                assert!(
                    (d[1] - fv).norm() < 1e-6 * (1.0 + fv.norm()),
                    "rational={rational}"
                );
                let fuv = (s.point(u + h, v + h).coords
                    - s.point(u + h, v - h).coords
                    - s.point(u - h, v + h).coords
                    + s.point(u - h, v - h).coords)
                    / (4.0 * h * h);
                assert!((d[4] - fuv).norm() < 1e-3 * (1.0 + fuv.norm()));
            }
        }
    }

    #[test]
    fn knot_insertion_keeps_shape() {
        for rational in [false, true] {
            let s = sample(rational);
            let s2 = s.insert_knot(Direction::U, 0.7, 2).unwrap();
            let s3 = s2.refine(Direction::V, &[0.25, 0.75]).unwrap();
            assert_eq!(s3.counts(), (7, 6));
            for a in 0..=10 {
                for b in 0..=10 {
                    let (u, v) = (a as f64 / 10.0, b as f64 / 10.0);
                    assert!((s.point(u, v) - s3.point(u, v)).norm() < 1e-13);
                }
            }
        }
    }

    #[test]
    fn partition_of_unity_reproduces_planes() {
        // control points on a plane -> every surface point on it
        let ku = KnotVector::uniform_clamped(3, 6).unwrap();
        let kv = KnotVector::uniform_clamped(3, 5).unwrap();
        let mut ctrl = Vec::new();
        for i in 0..6 {
            for j in 0..5 {
                let (x, y) = (i as f64 * 0.3, j as f64 * 0.7);
                ctrl.push(Point3::new(x, y, 2.0 * x - y + 1.0));
            }
        }
        let s = Surface::new(ku, kv, ctrl).unwrap();
        for k in 0..50 {
            let p = s.point(k as f64 / 49.0, (k * 7 % 50) as f64 / 49.0);
            assert!((p.z - (2.0 * p.x - p.y + 1.0)).abs() < 1e-13);
        }
    }
}
