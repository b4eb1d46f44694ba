//! General B-spline operations on knot vectors, curves and surfaces, shared
//! by the Coons patch ([`crate::base::CoonsPatch`]), the PDE surface's
//! B-spline form ([`crate::pde`]) and MBA ([`crate::mba`]):
//!
//! * [`greville`]: the Greville abscissae ([NURBS97] eq. 9.30 is the same
//!   average for interpolation knots; [deBoor78] ch. XI for linear precision,
//!   `sum_i xi_i N_i(u) = u`);
//! * [`missing_knots`], [`knot_union`]: the knots one vector lacks to contain
//!   another, and the union of two (multiplicities kept);
//! * [`make_compatible`]: two curves of one degree refined to common knots
//!   ([NURBS97] §5.3, knot refinement A5.4), e.g. opposite Coons sides;
//! * [`refine_surface_to`]: a surface refined to contain given knots;
//! * [`reversed`]: a curve traversed backwards on `[0, 1]`;
//! * [`to_unit_domain`]: a clamped curve reparameterized to `[0, 1]`.
//!
//! Keys in brackets are those of `docs/references.md`.

use super::{Curve, Direction, KnotVector, Surface};
use crate::{Error, Result};

/// Greville abscissae `xi_i = (t_{i+1} + ... + t_{i+p}) / p` of a knot
/// vector, one per basis function (`t_i` for degree 0). The control values
/// `xi_i` reproduce the identity: `sum_i xi_i N_i(u) = u` (linear precision).
///
/// ```
/// use scanfit::bspline::{ops::greville, KnotVector};
/// let kv = KnotVector::new(vec![0., 0., 0., 0.5, 1., 1., 1.], 2).unwrap();
/// assert_eq!(greville(&kv), vec![0.0, 0.25, 0.75, 1.0]);
/// ```
pub fn greville(kv: &KnotVector) -> Vec<f64> {
    let p = kv.degree();
    let t = kv.as_slice();
    (0..kv.basis_count())
        .map(|i| {
            if p == 0 {
                t[i]
            } else {
                t[i + 1..=i + p].iter().sum::<f64>() / p as f64
            }
        })
        .collect()
}

/// The knots (with multiplicity) that `a` lacks to contain every knot of `b`,
/// in increasing order.
///
/// ```
/// use scanfit::bspline::{ops::missing_knots, KnotVector};
/// let a = KnotVector::new(vec![0., 0., 0., 0.5, 1., 1., 1.], 2).unwrap();
/// let b = KnotVector::new(vec![0., 0., 0., 0.25, 0.5, 0.5, 1., 1., 1.], 2).unwrap();
/// assert_eq!(missing_knots(&a, &b), vec![0.25, 0.5]);
/// assert!(missing_knots(&b, &a).is_empty());
/// ```
pub fn missing_knots(a: &KnotVector, b: &KnotVector) -> Vec<f64> {
    let (ta, tb) = (a.as_slice(), b.as_slice());
    let mut out = Vec::new();
    let mut i = 0;
    while i < tb.len() {
        let x = tb[i];
        let mb = tb[i..].iter().take_while(|&&y| y == x).count();
        let ma = ta.iter().filter(|&&y| y == x).count();
        out.extend(std::iter::repeat_n(x, mb.saturating_sub(ma)));
        i += mb;
    }
    out
}

/// The union of two knot vectors of one degree: every knot of either, with
/// the larger multiplicity (the smallest vector both refine to).
///
/// ```
/// use scanfit::bspline::{ops::knot_union, KnotVector};
/// let a = KnotVector::uniform_clamped(3, 5).unwrap(); // interior knot 0.5
/// let b = KnotVector::uniform_clamped(3, 6).unwrap(); // interior knots 1/3, 2/3
/// let u = knot_union(&a, &b).unwrap();
/// assert_eq!(u.basis_count(), 7);
/// assert!(knot_union(&a, &KnotVector::uniform_clamped(2, 4).unwrap()).is_err());
/// ```
pub fn knot_union(a: &KnotVector, b: &KnotVector) -> Result<KnotVector> {
    if a.degree() != b.degree() {
        return Err(Error::InvalidInput(format!(
            "knot vectors of degrees {} and {} have no common refinement of one degree; elevate one first",
            a.degree(),
            b.degree()
        )));
    }
    let mut k = a.as_slice().to_vec();
    k.extend(missing_knots(a, b));
    k.sort_by(f64::total_cmp);
    KnotVector::new(k, a.degree())
}

/// Two curves of the same degree refined (exactly, by knot insertion) to the
/// union of their knots, so their control points correspond one to one
/// (`what` names them in the error for different degrees).
///
/// ```
/// use scanfit::bspline::{ops::make_compatible, Curve, KnotVector};
/// use scanfit::Point3;
/// let line = |n: usize| {
///     let ctrl = (0..n).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
///     Curve::new(KnotVector::uniform_clamped(3, n).unwrap(), ctrl).unwrap()
/// };
/// let (a, b) = make_compatible(&line(5), &line(6), "the two sides").unwrap();
/// assert_eq!(a.knots(), b.knots());
/// assert!((a.point(0.4) - line(5).point(0.4)).norm() < 1e-14);
/// ```
pub fn make_compatible(a: &Curve, b: &Curve, what: &str) -> Result<(Curve, Curve)> {
    if a.degree() != b.degree() {
        return Err(Error::InvalidInput(format!(
            "{what} have degrees {} and {}; opposite boundary curves must have the same degree for the B-spline form (fit them with one degree)",
            a.degree(),
            b.degree()
        )));
    }
    let ra = a.refine(&missing_knots(a.knots(), b.knots()))?;
    let rb = b.refine(&missing_knots(b.knots(), a.knots()))?;
    Ok((ra, rb))
}

/// `s` refined (exactly) to knot vectors containing `ku` and `kv` (same
/// degrees as `s`).
///
/// ```
/// use scanfit::bspline::{ops::refine_surface_to, KnotVector, Surface};
/// use scanfit::Point3;
/// let k = KnotVector::uniform_clamped(1, 2).unwrap();
/// let ctrl = vec![Point3::new(0., 0., 0.), Point3::new(0., 1., 0.), Point3::new(1., 0., 0.), Point3::new(1., 1., 1.)];
/// let s = Surface::new(k.clone(), k, ctrl).unwrap();
/// let fine = KnotVector::uniform_clamped(1, 3).unwrap();
/// let r = refine_surface_to(&s, &fine, &fine).unwrap();
/// assert_eq!(r.control_points().len(), 9);
/// assert!((r.point(0.3, 0.8) - s.point(0.3, 0.8)).norm() < 1e-15);
/// ```
pub fn refine_surface_to(s: &Surface, ku: &KnotVector, kv: &KnotVector) -> Result<Surface> {
    let s = s.refine(Direction::U, &missing_knots(s.knots_u(), ku))?;
    s.refine(Direction::V, &missing_knots(s.knots_v(), kv))
}

/// Checks a curve is clamped, non-rational and non-periodic (`what` names it
/// in the error) and returns it reparameterized to `[0, 1]` (an affine map of
/// the knots; the control points are unchanged).
///
/// ```
/// use scanfit::bspline::{ops::to_unit_domain, Curve, KnotVector};
/// use scanfit::Point3;
/// let kv = KnotVector::new(vec![2., 2., 4., 4.], 1).unwrap();
/// let c = Curve::new(kv, vec![Point3::origin(), Point3::new(1., 0., 0.)]).unwrap();
/// let u = to_unit_domain(&c, "the side").unwrap();
/// assert_eq!(u.domain(), (0.0, 1.0));
/// assert_eq!(u.point(0.25), c.point(2.5));
/// ```
pub fn to_unit_domain(curve: &Curve, what: &str) -> Result<Curve> {
    if curve.is_rational() || curve.is_periodic() || !curve.knots().is_clamped() {
        return Err(Error::InvalidInput(format!(
            "{what} must be a clamped, non-rational B-spline curve (clamp it with to_clamped first)"
        )));
    }
    let (a, b) = curve.domain();
    if a == 0.0 && b == 1.0 {
        return Ok(curve.clone());
    }
    let k: Vec<f64> = curve
        .knots()
        .as_slice()
        .iter()
        .map(|&t| ((t - a) / (b - a)).clamp(0.0, 1.0))
        .collect();
    Curve::new(
        KnotVector::new(k, curve.degree())?,
        curve.control_points().to_vec(),
    )
}

/// The curve run backwards on `[0, 1]`: `C_r(t) = C(1 - t)` after mapping
/// the domain of `C` to `[0, 1]` (clamped, non-rational curves).
///
/// ```
/// use scanfit::bspline::{ops::reversed, Curve, KnotVector};
/// use scanfit::Point3;
/// let ctrl = vec![Point3::origin(), Point3::new(1., 2., 0.), Point3::new(3., 0., 1.)];
/// let c = Curve::new(KnotVector::uniform_clamped(2, 3).unwrap(), ctrl).unwrap();
/// let r = reversed(&c).unwrap();
/// assert!((r.point(0.3) - c.point(0.7)).norm() < 1e-15);
/// ```
pub fn reversed(curve: &Curve) -> Result<Curve> {
    let c = to_unit_domain(curve, "a reversed curve")?;
    let k: Vec<f64> = c
        .knots()
        .as_slice()
        .iter()
        .rev()
        .map(|&t| 1.0 - t)
        .collect();
    let mut ctrl = c.control_points().to_vec();
    ctrl.reverse();
    Curve::new(KnotVector::new(k, c.degree())?, ctrl)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Point3;

    #[test]
    fn greville_reproduces_the_identity() {
        let kv = KnotVector::new(vec![0., 0., 0., 0., 0.2, 0.45, 0.5, 1., 1., 1., 1.], 3).unwrap();
        let ctrl: Vec<Point3> = greville(&kv)
            .into_iter()
            .map(|x| Point3::new(x, 0.0, 0.0))
            .collect();
        let c = Curve::new(kv, ctrl).unwrap();
        for i in 0..=40 {
            let u = i as f64 / 40.0;
            assert!((c.point(u).x - u).abs() < 1e-15, "u = {u}");
        }
    }

    #[test]
    fn union_holds_both_and_nothing_more() {
        let a = KnotVector::new(vec![0., 0., 0., 0.3, 0.3, 1., 1., 1.], 2).unwrap();
        let b = KnotVector::new(vec![0., 0., 0., 0.3, 0.6, 1., 1., 1.], 2).unwrap();
        let u = knot_union(&a, &b).unwrap();
        assert_eq!(u.as_slice(), &[0., 0., 0., 0.3, 0.3, 0.6, 1., 1., 1.]);
        assert!(missing_knots(&u, &a).is_empty() && missing_knots(&u, &b).is_empty());
    }

    #[test]
    fn compatible_curves_keep_their_shape() {
        let mk = |n: usize, f: fn(f64) -> f64| {
            let ctrl = (0..n)
                .map(|i| {
                    let x = i as f64 / (n - 1) as f64;
                    Point3::new(x, f(x), 0.0)
                })
                .collect();
            Curve::new(KnotVector::uniform_clamped(3, n).unwrap(), ctrl).unwrap()
        };
        let (a0, b0) = (mk(5, f64::sin), mk(7, f64::cos));
        let (a, b) = make_compatible(&a0, &b0, "a and b").unwrap();
        assert_eq!(a.knots(), b.knots());
        // interior knots {0.5} and {0.25, 0.5, 0.75}: the union has 3
        assert_eq!(a.control_points().len(), 7);
        for i in 0..=20 {
            let u = i as f64 / 20.0;
            assert!((a.point(u) - a0.point(u)).norm() < 1e-14);
            assert!((b.point(u) - b0.point(u)).norm() < 1e-14);
        }
        let quad = Curve::new(
            KnotVector::uniform_clamped(2, 3).unwrap(),
            vec![Point3::origin(); 3],
        )
        .unwrap();
        let e = make_compatible(&a0, &quad, "the sides")
            .unwrap_err()
            .to_string();
        assert!(e.contains("degrees 3 and 2"), "{e}");
    }
}
