//! B-spline (and NURBS) curves: evaluation, derivatives, knot insertion.
//!
//! Algorithms from Piegl & Tiller, [NURBS97]: A3.1 (point), A3.2
//! (derivatives), A4.2 (rational derivatives), A5.1 (knot insertion).

use super::basis::{basis_funs, BasisWorkspace};
use super::knots::{find_span, KnotVector};
use crate::{Error, Point3, Result, Vector3};

/// Degrees up to this use stack buffers in [`Curve::point`]; higher degrees fall
/// back to a heap workspace (use [`Curve::eval_many`] or a [`BasisWorkspace`]
/// to stay allocation-free for any degree).
pub(crate) const STACK_DEGREE: usize = 15;

/// A B-spline curve of any degree, optionally rational (weights) and periodic.
///
/// A periodic (closed, `C^{p-1}` at the seam) curve is stored in the standard
/// unclamped form: `n + p` control points whose last `p` repeat the first `p`,
/// and knot spacings that wrap around. Its domain `[t_p, t_{m-p}]` has the
/// period's length; parameters outside the domain are wrapped into it.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    knots: KnotVector,
    ctrl: Vec<Point3>,
    weights: Option<Vec<f64>>,
    periodic: bool,
}

impl Curve {
    /// A non-rational curve; `ctrl.len()` must equal the knot vector's basis count.
    pub fn new(knots: KnotVector, ctrl: Vec<Point3>) -> Result<Self> {
        Self::build(knots, ctrl, None, false)
    }

    /// A rational (NURBS) curve with positive finite weights.
    pub fn new_rational(knots: KnotVector, ctrl: Vec<Point3>, weights: Vec<f64>) -> Result<Self> {
        Self::build(knots, ctrl, Some(weights), false)
    }

    /// A periodic curve: the last `p` control points (and weights) must repeat the
    /// first `p`, and the first `2p` knot intervals must repeat the last `2p`.
    pub fn new_periodic(
        knots: KnotVector,
        ctrl: Vec<Point3>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self> {
        Self::build(knots, ctrl, weights, true)
    }

    fn build(
        knots: KnotVector,
        ctrl: Vec<Point3>,
        weights: Option<Vec<f64>>,
        periodic: bool,
    ) -> Result<Self> {
        let n = knots.basis_count();
        if ctrl.len() != n {
            return Err(Error::InvalidInput(format!(
                "{} control points given, but {} knots of degree {} need {n}",
                ctrl.len(),
                knots.len(),
                knots.degree()
            )));
        }
        crate::validate_points(&ctrl)?;
        if let Some(w) = &weights {
            validate_weights(w, n)?;
        }
        if periodic {
            check_periodic(&knots, &ctrl, weights.as_deref())?;
        }
        Ok(Self {
            knots,
            ctrl,
            weights,
            periodic,
        })
    }

    /// Degree `p`.
    #[inline]
    pub fn degree(&self) -> usize {
        self.knots.degree()
    }
    /// The knot vector.
    #[inline]
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }
    /// Control points (for a periodic curve including the `p` repeated ones).
    #[inline]
    pub fn control_points(&self) -> &[Point3] {
        &self.ctrl
    }
    /// Weights, if the curve is rational.
    #[inline]
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
    /// True for a rational curve whose weights are not all equal.
    pub fn is_rational(&self) -> bool {
        self.weights
            .as_ref()
            .is_some_and(|w| w.iter().any(|&x| x != w[0]))
    }
    /// True for a periodic (closed, smooth at the seam) curve.
    #[inline]
    pub fn is_periodic(&self) -> bool {
        self.periodic
    }
    /// True when the curve starts where it ends.
    pub fn is_closed(&self) -> bool {
        let (a, b) = self.domain();
        self.periodic || (self.point(a) - self.point(b)).norm() <= 1e-12 * self.scale()
    }
    /// Parameter domain `[t_p, t_{m-p}]`.
    #[inline]
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain()
    }

    fn scale(&self) -> f64 {
        crate::geom::bbox_diagonal(&self.ctrl).max(f64::MIN_POSITIVE)
    }

    /// Maps `u` into the domain: wrapped for periodic curves, clamped otherwise.
    #[inline]
    pub fn wrap(&self, u: f64) -> f64 {
        self.knots.wrap(u, self.periodic)
    }

    /// Point at `u` (A3.1; rational by homogeneous coordinates). Allocation-free
    /// for degree <= 15.
    #[inline]
    pub fn point(&self, u: f64) -> Point3 {
        let p = self.degree();
        if p > STACK_DEGREE {
            let mut ws = BasisWorkspace::new(p, 0);
            let mut out = [Vector3::zeros()];
            self.derivatives_into(u, &mut ws, &mut out);
            return Point3::from(out[0]);
        }
        let mut n = [0.0; STACK_DEGREE + 1];
        let mut left = [0.0; STACK_DEGREE + 1];
        let mut right = [0.0; STACK_DEGREE + 1];
        let u = self.wrap(u);
        let t = self.knots.as_slice();
        let s = find_span(t, p, u);
        basis_funs(t, p, s, u, &mut n, &mut left, &mut right);
        self.combine(s, &n[..=p])
    }

    #[inline]
    fn combine(&self, span: usize, n: &[f64]) -> Point3 {
        let p = n.len() - 1;
        let base = span - p;
        match &self.weights {
            None => {
                let mut acc = Vector3::zeros();
                for (j, &nj) in n.iter().enumerate() {
                    acc += self.ctrl[base + j].coords * nj;
                }
                Point3::from(acc)
            }
            Some(w) => {
                let mut acc = Vector3::zeros();
                let mut ws = 0.0;
                for (j, &nj) in n.iter().enumerate() {
                    let c = nj * w[base + j];
                    acc += self.ctrl[base + j].coords * c;
                    ws += c;
                }
                Point3::from(acc / ws)
            }
        }
    }

    /// Evaluates the curve at every `us[i]` into `out[i]`. Allocation-free for any
    /// degree up to 15; consecutive parameters in the same span skip the search.
    /// Degrees 1 to 3 run a loop specialised at compile time (unrolled basis).
    pub fn eval_many(&self, us: &[f64], out: &mut [Point3]) {
        match self.degree() {
            1 => self.eval_many_fixed::<2>(us, out),
            2 => self.eval_many_fixed::<3>(us, out),
            3 => self.eval_many_fixed::<4>(us, out),
            p if p <= STACK_DEGREE => self.eval_many_generic(us, out),
            _ => {
                for (o, &u) in out.iter_mut().zip(us) {
                    *o = self.point(u);
                }
            }
        }
    }

    /// `eval_many` for degree `Q - 1`, with the basis recursion (A2.2) written out
    /// on fixed-size arrays. This repeats [`basis_funs`] on purpose: calling it
    /// with a constant degree does not unroll (45 M points/s instead of 75 M).
    fn eval_many_fixed<const Q: usize>(&self, us: &[f64], out: &mut [Point3]) {
        let t = self.knots.as_slice();
        let p = Q - 1;
        let (a, b) = self.domain();
        let last = t.len() - p - 2;
        let mut s = p;
        let mut n = [0.0; Q];
        let (mut left, mut right) = ([0.0; Q], [0.0; Q]);
        for (o, &u) in out.iter_mut().zip(us) {
            let u = if self.periodic {
                self.wrap(u)
            } else {
                u.clamp(a, b)
            };
            if !(t[s] <= u && (u < t[s + 1] || (s == last && u <= t[s + 1]))) {
                s = find_span(t, p, u);
            }
            // A2.2 with compile-time bounds
            n[0] = 1.0;
            for j in 1..Q {
                left[j] = u - t[s + 1 - j];
                right[j] = t[s + j] - u;
                let mut saved = 0.0;
                for r in 0..j {
                    let temp = n[r] / (right[r + 1] + left[j - r]);
                    n[r] = saved + right[r + 1] * temp;
                    saved = left[j - r] * temp;
                }
                n[j] = saved;
            }
            *o = self.combine(s, &n);
        }
    }

    fn eval_many_generic(&self, us: &[f64], out: &mut [Point3]) {
        let p = self.degree();
        let t = self.knots.as_slice();
        let (a, b) = self.domain();
        let mut n = [0.0; STACK_DEGREE + 1];
        let mut left = [0.0; STACK_DEGREE + 1];
        let mut right = [0.0; STACK_DEGREE + 1];
        let last = t.len() - p - 2;
        let mut s = p;
        for (o, &u) in out.iter_mut().zip(us) {
            let u = if self.periodic {
                self.wrap(u)
            } else {
                u.clamp(a, b)
            };
            // span hint: reuse the previous span when u is still inside it
            if !(t[s] <= u && (u < t[s + 1] || (s == last && u <= t[s + 1]))) {
                s = find_span(t, p, u);
            }
            basis_funs(t, p, s, u, &mut n, &mut left, &mut right);
            *o = self.combine(s, &n[..=p]);
        }
    }

    /// Derivatives `C^(k)(u)` for `k = 0..out.len()` (A3.2, and A4.2 for rational
    /// curves); `out[0]` is the point as a vector. Orders above the workspace's
    /// `max_order` are left zero for non-rational curves.
    pub fn derivatives_into(&self, u: f64, ws: &mut BasisWorkspace, out: &mut [Vector3]) {
        let p = self.degree();
        let q = p + 1;
        let order = out.len() - 1;
        let u = self.wrap(u);
        let t = self.knots.as_slice();
        let s = find_span(t, p, u);
        let d = ws.ders(t, s, u, order);
        let avail = d.len() / q - 1;
        let base = s - p;
        out.iter_mut().for_each(|o| *o = Vector3::zeros());
        match &self.weights {
            None => {
                for k in 0..=order.min(avail) {
                    let mut acc = Vector3::zeros();
                    for j in 0..=p {
                        acc += self.ctrl[base + j].coords * d[k * q + j];
                    }
                    out[k] = acc;
                }
            }
            Some(w) => {
                // A4.2: C^(k) = (A^(k) - sum_{i=1..k} binom(k,i) w^(i) C^(k-i)) / w
                let mut wd = [0.0f64; 8];
                let top = order.min(avail).min(7);
                for k in 0..=top {
                    let mut acc = Vector3::zeros();
                    let mut wk = 0.0;
                    for j in 0..=p {
                        let c = d[k * q + j] * w[base + j];
                        acc += self.ctrl[base + j].coords * c;
                        wk += c;
                    }
                    out[k] = acc;
                    wd[k] = wk;
                }
                for k in 0..=top {
                    let mut v = out[k];
                    for i in 1..=k {
                        v -= out[k - i] * (binomial(k, i) * wd[i]);
                    }
                    out[k] = v / wd[0];
                }
            }
        }
    }

    /// Unit-free curvature `|C' x C''| / |C'|^3` at `u` (0 where `C'` vanishes).
    pub fn curvature(&self, u: f64, ws: &mut BasisWorkspace) -> f64 {
        let mut d = [Vector3::zeros(); 3];
        self.derivatives_into(u, ws, &mut d);
        let speed = d[1].norm();
        if speed <= f64::MIN_POSITIVE {
            return 0.0;
        }
        d[1].cross(&d[2]).norm() / (speed * speed * speed)
    }

    /// Inserts the knot `u` `r` times (A5.1, in homogeneous coordinates so rational
    /// curves keep their shape). The curve's shape is unchanged.
    pub fn insert_knot(&self, u: f64, r: usize) -> Result<Self> {
        let p = self.degree();
        let (a, b) = self.domain();
        if !(u > a && u < b) {
            return Err(Error::InvalidInput(format!(
                "knot {u} to insert lies outside the open domain ({a}, {b})"
            )));
        }
        let mult = self.knots.multiplicity(u);
        if r == 0 {
            return Ok(self.clone());
        }
        if mult + r > p {
            return Err(Error::InvalidInput(format!(
                "inserting {u} {r} times would raise its multiplicity to {} > degree {p}",
                mult + r
            )));
        }
        let hw = self.homogeneous();
        let t = self.knots.as_slice();
        let k = find_span(t, p, u);
        let (new_knots, new_pw) = insert_homogeneous(t, p, &hw, u, k, mult, r);
        let kv = KnotVector::new(new_knots, p)?;
        let (ctrl, weights) = self.dehomogenize(new_pw);
        // Knot insertion breaks the repeated-control-point form of a periodic
        // curve; the result is the same closed curve in ordinary form.
        Self::build(kv, ctrl, weights, false)
    }

    /// Inserts every knot of `xs` (knot refinement, NURBS Book section 5.3, done
    /// as successive A5.1 insertions). The shape is unchanged.
    pub fn refine(&self, xs: &[f64]) -> Result<Self> {
        let mut c = self.clone();
        for &x in xs {
            c = c.insert_knot(x, 1)?;
        }
        Ok(c)
    }

    pub(crate) fn homogeneous(&self) -> Vec<[f64; 4]> {
        self.ctrl
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let w = self.weights.as_ref().map_or(1.0, |w| w[i]);
                [p.x * w, p.y * w, p.z * w, w]
            })
            .collect()
    }

    fn dehomogenize(&self, pw: Vec<[f64; 4]>) -> (Vec<Point3>, Option<Vec<f64>>) {
        let ctrl = pw
            .iter()
            .map(|h| Point3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3]))
            .collect();
        let weights = self
            .weights
            .as_ref()
            .map(|_| pw.iter().map(|h| h[3]).collect());
        (ctrl, weights)
    }

    /// Sampled arc length over the domain (`samples` chords per knot span,
    /// Gauss–Legendre would be exact only for polynomial speed, which B-splines lack).
    pub fn length(&self, samples_per_span: usize) -> f64 {
        let bps = self.knots.breakpoints();
        let mut len = 0.0;
        let mut prev = self.point(bps[0]);
        for w in bps.windows(2) {
            for k in 1..=samples_per_span {
                let u = w[0] + (w[1] - w[0]) * k as f64 / samples_per_span as f64;
                let q = self.point(u);
                len += (q - prev).norm();
                prev = q;
            }
        }
        len
    }
}

/// Checks one positive finite weight per control point.
pub(crate) fn validate_weights(w: &[f64], count: usize) -> Result<()> {
    if w.len() != count {
        return Err(Error::InvalidInput(format!(
            "{} weights given for {count} control points",
            w.len()
        )));
    }
    if let Some(i) = w.iter().position(|&w| !(w.is_finite() && w > 0.0)) {
        return Err(Error::InvalidInput(format!(
            "weight {i} is {} but weights must be positive and finite",
            w[i]
        )));
    }
    Ok(())
}

/// Binomial coefficient as f64 (small arguments).
pub(crate) fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// A5.1 on homogeneous points: inserts `u` (span `k`, multiplicity `s`) `r` times.
pub(crate) fn insert_homogeneous(
    t: &[f64],
    p: usize,
    pw: &[[f64; 4]],
    u: f64,
    k: usize,
    s: usize,
    r: usize,
) -> (Vec<f64>, Vec<[f64; 4]>) {
    let np = pw.len() - 1;
    let mp = np + p + 1;
    let mut uq = Vec::with_capacity(t.len() + r);
    uq.extend_from_slice(&t[..=k]);
    uq.extend(std::iter::repeat_n(u, r));
    uq.extend_from_slice(&t[k + 1..=mp]);
    let mut qw = vec![[0.0; 4]; np + 1 + r];
    qw[..=(k - p)].copy_from_slice(&pw[..=(k - p)]);
    qw[(k - s + r)..=(np + r)].copy_from_slice(&pw[(k - s)..=np]);
    let mut rw: Vec<[f64; 4]> = pw[(k - p)..=(k - s)].to_vec();
    let mut l = 0;
    for j in 1..=r {
        l = k - p + j;
        for i in 0..=(p - j - s) {
            let alpha = (u - t[l + i]) / (t[i + k + 1] - t[l + i]);
            for c in 0..4 {
                rw[i][c] = alpha * rw[i + 1][c] + (1.0 - alpha) * rw[i][c];
            }
        }
        qw[l] = rw[0];
        qw[k + r - j - s] = rw[p - j - s];
    }
    if l + 1 < k - s {
        qw[(l + 1)..(k - s)].copy_from_slice(&rw[1..(k - s - l)]);
    }
    (uq, qw)
}

fn check_periodic(kv: &KnotVector, ctrl: &[Point3], w: Option<&[f64]>) -> Result<()> {
    let p = kv.degree();
    let n = ctrl.len();
    if n < 2 * p + 1 {
        return Err(Error::InvalidInput(format!(
            "a periodic curve of degree {p} needs at least {} control points (with {p} repeated), got {n}",
            2 * p + 1
        )));
    }
    let d = n - p;
    for j in 0..p {
        if ctrl[d + j] != ctrl[j] || w.is_some_and(|w| w[d + j] != w[j]) {
            return Err(Error::InvalidInput(format!(
                "periodic curve: control point {} must repeat control point {j}",
                d + j
            )));
        }
    }
    let t = kv.as_slice();
    let m = t.len() - 1;
    let span = t[m - p] - t[p];
    for j in 0..2 * p {
        let a = t[j + 1] - t[j];
        let b = t[m - 2 * p + j + 1] - t[m - 2 * p + j];
        if (a - b).abs() > 1e-12 * span.abs().max(1.0) {
            return Err(Error::InvalidInput(format!(
                "periodic curve: knot interval {j} ({a}) must equal interval {} ({b})",
                m - 2 * p + j
            )));
        }
    }
    Ok(())
}

/// A curve translates with its control points (also a rational one: the
/// basis sums to one).
impl crate::centring::Translate for Curve {
    fn translate(&mut self, by: &Vector3) {
        for p in &mut self.ctrl {
            *p += by;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_curve() -> Curve {
        let kv = KnotVector::new(vec![0., 0., 0., 0., 0.3, 0.6, 1., 1., 1., 1.], 3).unwrap();
        let ctrl = vec![
            Point3::new(0., 0., 0.),
            Point3::new(1., 2., 0.),
            Point3::new(2., 2., 1.),
            Point3::new(3., 0., 1.),
            Point3::new(4., 1., 0.),
            Point3::new(5., 3., 2.),
        ];
        Curve::new(kv, ctrl).unwrap()
    }

    #[test]
    fn clamped_ends_interpolate_control_points() {
        let c = sample_curve();
        assert_eq!(c.point(0.0), Point3::new(0., 0., 0.));
        assert!((c.point(1.0) - Point3::new(5., 3., 2.)).norm() < 1e-15);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let c = sample_curve();
        let mut ws = BasisWorkspace::new(3, 3);
        let mut d = [Vector3::zeros(); 4];
        let h = 1e-6;
        for &u in &[0.1, 0.45, 0.8] {
            c.derivatives_into(u, &mut ws, &mut d);
            assert!((Point3::from(d[0]) - c.point(u)).norm() < 1e-14);
            let fd = (c.point(u + h) - c.point(u - h)) / (2.0 * h);
            assert!(
                (d[1] - fd).norm() < 1e-7 * (1.0 + fd.norm()),
                "{} vs {}",
                d[1],
                fd
            );
            let fd2 =
                (c.point(u + h).coords - 2.0 * c.point(u).coords + c.point(u - h).coords) / (h * h);
            assert!((d[2] - fd2).norm() < 1e-3 * (1.0 + fd2.norm()));
        }
    }

    #[test]
    fn rational_derivatives_match_finite_differences() {
        let c = sample_curve();
        let w = vec![1.0, 0.5, 2.0, 1.5, 0.7, 1.0];
        let r = Curve::new_rational(c.knots().clone(), c.control_points().to_vec(), w).unwrap();
        assert!(r.is_rational());
        let mut ws = BasisWorkspace::new(3, 2);
        let mut d = [Vector3::zeros(); 3];
        let h = 1e-6;
        for &u in &[0.2, 0.5, 0.9] {
            r.derivatives_into(u, &mut ws, &mut d);
            assert!((Point3::from(d[0]) - r.point(u)).norm() < 1e-13);
            let fd = (r.point(u + h) - r.point(u - h)) / (2.0 * h);
            assert!((d[1] - fd).norm() < 1e-6 * (1.0 + fd.norm()));
            let fd2 =
                (r.point(u + h).coords - 2.0 * r.point(u).coords + r.point(u - h).coords) / (h * h);
            assert!((d[2] - fd2).norm() < 1e-3 * (1.0 + fd2.norm()));
        }
    }

    #[test]
    fn knot_insertion_keeps_shape() {
        let c = sample_curve();
        let w = vec![1.0, 0.5, 2.0, 1.5, 0.7, 1.0];
        let r = Curve::new_rational(c.knots().clone(), c.control_points().to_vec(), w).unwrap();
        for curve in [c, r] {
            let c2 = curve.insert_knot(0.45, 2).unwrap();
            assert_eq!(c2.control_points().len(), 8);
            let c3 = curve.refine(&[0.1, 0.3, 0.7, 0.7]).unwrap();
            assert_eq!(c3.knots().len(), 14);
            for k in 0..=100 {
                let u = k as f64 / 100.0;
                assert!((curve.point(u) - c2.point(u)).norm() < 1e-13);
                assert!((curve.point(u) - c3.point(u)).norm() < 1e-13);
            }
            assert!(curve.insert_knot(0.3, 3).is_err());
            assert!(curve.insert_knot(1.0, 1).is_err());
        }
    }

    #[test]
    fn eval_many_matches_point() {
        let c = sample_curve();
        let us: Vec<f64> = (0..=1000).map(|k| k as f64 / 1000.0).collect();
        let mut out = vec![Point3::origin(); us.len()];
        c.eval_many(&us, &mut out);
        for (u, o) in us.iter().zip(&out) {
            assert_eq!(*o, c.point(*u));
        }
    }

    #[test]
    fn periodic_curve_validates_and_wraps() {
        let kv = KnotVector::uniform_periodic(2, 4).unwrap();
        let q = [
            Point3::new(1., 0., 0.),
            Point3::new(0., 1., 0.),
            Point3::new(-1., 0., 0.),
            Point3::new(0., -1., 0.),
        ];
        let ctrl = vec![q[0], q[1], q[2], q[3], q[0], q[1]];
        let c = Curve::new_periodic(kv.clone(), ctrl, None).unwrap();
        assert!((c.point(0.0) - c.point(1.0)).norm() < 1e-15);
        assert!((c.point(0.3) - c.point(1.3)).norm() < 1e-15);
        assert!((c.point(0.3) - c.point(-0.7)).norm() < 1e-15);
        assert!(c.is_closed());
        let bad = vec![q[0], q[1], q[2], q[3], q[0], q[2]];
        assert!(Curve::new_periodic(kv, bad, None).is_err());
    }

    #[test]
    fn binomials() {
        assert_eq!(binomial(5, 2), 10.0);
        assert_eq!(binomial(4, 0), 1.0);
    }
}
