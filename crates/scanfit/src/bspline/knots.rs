//! Knot vectors: validation, span search, multiplicity.
//!
//! Conventions follow Piegl & Tiller, [NURBS97] (2nd ed.), chapter 2:
//! a knot vector `U = {t_0, ..., t_m}` of degree `p` carries `n + 1 = m - p`
//! basis functions, and the curve's domain is `[t_p, t_{m-p}]`.

use crate::{Error, Result};

/// A validated, non-decreasing knot vector together with its degree.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    knots: Vec<f64>,
    degree: usize,
}

impl KnotVector {
    /// Validates `knots` for `degree`: finite, non-decreasing, at least `2(p+1)`
    /// knots, interior multiplicity at most `p` (`p+1` at the ends), and a
    /// non-empty domain `[t_p, t_{m-p}]`.
    pub fn new(knots: Vec<f64>, degree: usize) -> Result<Self> {
        if degree == 0 {
            return Err(Error::InvalidKnots("degree must be at least 1".into()));
        }
        let m = knots.len();
        if m < 2 * (degree + 1) {
            return Err(Error::InvalidKnots(format!(
                "degree {degree} needs at least {} knots, got {m}",
                2 * (degree + 1)
            )));
        }
        if let Some(i) = knots.iter().position(|k| !k.is_finite()) {
            return Err(Error::InvalidKnots(format!(
                "knot {i} is not finite ({})",
                knots[i]
            )));
        }
        if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
            return Err(Error::InvalidKnots(format!(
                "knots must be non-decreasing, but knot {} = {} > knot {} = {}",
                i,
                knots[i],
                i + 1,
                knots[i + 1]
            )));
        }
        let (lo, hi) = (knots[degree], knots[m - 1 - degree]);
        if hi <= lo {
            return Err(Error::InvalidKnots(format!(
                "empty domain [t_{degree}, t_{}] = [{lo}, {hi}]",
                m - 1 - degree
            )));
        }
        // Multiplicity: at most p+1 anywhere, at most p strictly inside the domain
        // (otherwise the curve breaks apart there).
        let mut i = 0;
        while i < m {
            let mut j = i;
            while j + 1 < m && knots[j + 1] == knots[i] {
                j += 1;
            }
            let mult = j - i + 1;
            let interior = knots[i] > lo && knots[i] < hi;
            if mult > degree + 1 || (interior && mult > degree) {
                return Err(Error::InvalidKnots(format!(
                    "knot value {} at indices {i}..={j} has multiplicity {mult}; at most {} allowed {}",
                    knots[i],
                    if interior { degree } else { degree + 1 },
                    if interior { "inside the domain" } else { "at the ends" }
                )));
            }
            i = j + 1;
        }
        Ok(Self { knots, degree })
    }

    /// Clamped (open) knot vector with the given interior knots on `[a, b]`:
    /// `p+1` copies of each end.
    pub fn clamped(degree: usize, a: f64, b: f64, interior: &[f64]) -> Result<Self> {
        let mut k = Vec::with_capacity(interior.len() + 2 * (degree + 1));
        k.extend(std::iter::repeat_n(a, degree + 1));
        k.extend_from_slice(interior);
        k.extend(std::iter::repeat_n(b, degree + 1));
        Self::new(k, degree)
    }

    /// Uniform clamped knot vector on `[0, 1]` for `ctrl_count` control points.
    pub fn uniform_clamped(degree: usize, ctrl_count: usize) -> Result<Self> {
        if ctrl_count < degree + 1 {
            return Err(Error::InvalidKnots(format!(
                "{ctrl_count} control points are too few for degree {degree} (need {})",
                degree + 1
            )));
        }
        let spans = ctrl_count - degree;
        let interior: Vec<f64> = (1..spans).map(|j| j as f64 / spans as f64).collect();
        Self::clamped(degree, 0.0, 1.0, &interior)
    }

    /// Uniform periodic knot vector on the domain `[0, 1]` for a closed curve with
    /// `distinct` control points: `distinct + 2p + 1` equally spaced knots, so that
    /// `distinct + p` control points (the last `p` repeating the first `p`) are used.
    pub fn uniform_periodic(degree: usize, distinct: usize) -> Result<Self> {
        if distinct < degree + 1 {
            return Err(Error::InvalidKnots(format!(
                "a closed curve of degree {degree} needs at least {} distinct control points, got {distinct}",
                degree + 1
            )));
        }
        let h = 1.0 / distinct as f64;
        let k = (0..distinct + 2 * degree + 1)
            .map(|i| (i as f64 - degree as f64) * h)
            .collect();
        Self::new(k, degree)
    }

    /// Degree `p`.
    #[inline]
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knots.
    #[inline]
    pub fn as_slice(&self) -> &[f64] {
        &self.knots
    }

    /// Number of knots `m + 1`.
    #[inline]
    pub fn len(&self) -> usize {
        self.knots.len()
    }

    /// Always false: a valid knot vector has at least `2(p+1)` knots.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.knots.is_empty()
    }

    /// Number of basis functions (control points) `n + 1 = m - p`.
    #[inline]
    pub fn basis_count(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// Parameter domain `[t_p, t_{m-p}]`.
    #[inline]
    pub fn domain(&self) -> (f64, f64) {
        (
            self.knots[self.degree],
            self.knots[self.knots.len() - 1 - self.degree],
        )
    }

    /// True when both ends have multiplicity `p+1` (the curve starts and ends at
    /// its first and last control points).
    pub fn is_clamped(&self) -> bool {
        let p = self.degree;
        let k = &self.knots;
        let m = k.len();
        k[..=p].iter().all(|&t| t == k[0]) && k[m - 1 - p..].iter().all(|&t| t == k[m - 1])
    }

    /// Knot span index `s` with `t_s <= u < t_{s+1}`, `p <= s <= n` (NURBS Book
    /// A2.1). `u` is clamped to the domain; at the right end the last non-empty
    /// span is returned.
    #[inline]
    pub fn find_span(&self, u: f64) -> usize {
        find_span(&self.knots, self.degree, u)
    }

    /// Multiplicity of the value `u` in the knot vector (0 when absent).
    pub fn multiplicity(&self, u: f64) -> usize {
        self.knots.iter().filter(|&&t| t == u).count()
    }

    /// Distinct knot values inside the domain, ends included.
    pub fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut out: Vec<f64> = Vec::new();
        for &t in &self.knots {
            if t >= a && t <= b && out.last() != Some(&t) {
                out.push(t);
            }
        }
        out
    }

    /// Maps `u` into the domain: wrapped by the period when `periodic`, clamped
    /// otherwise (used by curve and surface evaluation alike).
    #[inline]
    pub fn wrap(&self, u: f64, periodic: bool) -> f64 {
        let (a, b) = self.domain();
        if periodic && (u < a || u > b) {
            let r = a + (u - a).rem_euclid(b - a);
            // rem_euclid may round up to exactly the period
            if r >= b {
                a
            } else {
                r
            }
        } else {
            u.clamp(a, b)
        }
    }

    /// Consumes the vector, returning the knots.
    pub fn into_vec(self) -> Vec<f64> {
        self.knots
    }
}

/// Span search on a raw knot slice (see [`KnotVector::find_span`]).
#[inline]
pub(crate) fn find_span(knots: &[f64], p: usize, u: f64) -> usize {
    let n = knots.len() - p - 2; // index of the last basis function
    if u >= knots[n + 1] {
        // right end: the last span with t_s < t_{s+1}
        let mut s = n;
        while s > p && knots[s] == knots[s + 1] {
            s -= 1;
        }
        return s;
    }
    if u <= knots[p] {
        let mut s = p;
        while s < n && knots[s + 1] <= u {
            s += 1;
        }
        return s;
    }
    // binary search in [p, n+1): largest s with t_s <= u
    let (mut lo, mut hi) = (p, n + 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if u < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_problem() {
        assert!(KnotVector::new(vec![0., 0., 1., 1.], 1).is_ok());
        let e = KnotVector::new(vec![0., 0., 0.5, 0.4, 1., 1.], 1).unwrap_err();
        assert!(e.to_string().contains("non-decreasing"), "{e}");
        let e = KnotVector::new(vec![0., 0., 0.5, 0.5, 1., 1.], 1).unwrap_err();
        assert!(e.to_string().contains("multiplicity 2"), "{e}");
        let e = KnotVector::new(vec![0., 0., f64::NAN, 1., 1.], 1).unwrap_err();
        assert!(e.to_string().contains("knot 2"), "{e}");
        assert!(KnotVector::new(vec![0., 0., 0., 1.], 2).is_err());
        assert!(KnotVector::new(vec![1., 1., 1., 1.], 1).is_err());
    }

    #[test]
    fn span_search_matches_linear_scan() {
        let kv = KnotVector::new(vec![0., 0., 0., 1., 2., 2., 3., 4., 4., 4.], 2).unwrap();
        assert_eq!(kv.basis_count(), 7);
        for (u, s) in [
            (0.0, 2),
            (0.5, 2),
            (1.0, 3),
            (1.9, 3),
            (2.0, 5),
            (3.5, 6),
            (4.0, 6),
        ] {
            assert_eq!(kv.find_span(u), s, "u = {u}");
        }
        assert_eq!(kv.find_span(-1.0), 2);
        assert_eq!(kv.find_span(9.0), 6);
        assert_eq!(kv.breakpoints(), vec![0., 1., 2., 3., 4.]);
        assert!(kv.is_clamped());
    }

    #[test]
    fn uniform_constructors() {
        let kv = KnotVector::uniform_clamped(3, 7).unwrap();
        assert_eq!(
            kv.as_slice(),
            &[0., 0., 0., 0., 0.25, 0.5, 0.75, 1., 1., 1., 1.]
        );
        let kp = KnotVector::uniform_periodic(3, 5).unwrap();
        assert_eq!(kp.basis_count(), 8);
        assert_eq!(kp.domain(), (0.0, 1.0));
        assert!(!kp.is_clamped());
    }
}
