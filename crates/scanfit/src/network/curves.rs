//! One curve per network edge, fitted once and shared (issue 15, item 3).
//!
//! The border points of both patches along an edge are placed on the edge
//! by their nearest point of the first patch's border polyline (arc length
//! from the edge's start), averaged in bins about one spacing long, and the
//! resulting ordered polyline from the start vertex to the end vertex is fitted
//! by the end-pinned least-squares B-spline of the PDE paper §4.2
//! ([`fit_boundary_curve`]). Its first and last control points are the two
//! vertices exactly, so every curve meeting at a vertex ends at the same
//! point. The knot vectors are uniform with a power-of-two span count, so
//! that their knots (dyadic fractions) survive reversal `t -> 1 - t` and
//! refinement without rounding.

use crate::base::{fit_boundary_curve, BoundaryCurveConfig, BoundaryFit};
use crate::bspline::Curve;
use crate::{Error, Point3, Result};

/// Settings of [`fit_edge_curve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCurveConfig {
    /// Degree (default 3).
    pub degree: usize,
    /// Most knot spans per edge curve (default 16; a power of two).
    pub max_spans: usize,
}

impl Default for EdgeCurveConfig {
    fn default() -> Self {
        Self {
            degree: 3,
            max_spans: 16,
        }
    }
}

/// A fitted edge curve and the points it was fitted to.
#[derive(Debug, Clone)]
pub struct EdgeCurve {
    /// The curve on `[0, 1]`, from the edge's start vertex to its end vertex.
    pub curve: Curve,
    /// The ordered (binned) points it was fitted to, vertices included.
    pub fitted: Vec<Point3>,
    /// Largest distance of a fitted point from the curve at its parameter.
    pub max_error: f64,
}

/// Largest power of two not above `x` (at least 1).
fn pow2_floor(x: usize) -> usize {
    if x <= 1 {
        1
    } else {
        1 << (usize::BITS - 1 - x.leading_zeros())
    }
}

/// Fits the curve of an edge from `start` to `end` through the border points
/// of its patches: `guide` (ordered from start to end, the first patch's
/// border) and `others` (any order: the second patch's border). `bin` is the
/// bin length (about one point spacing). Border points closer than
/// `clearance` to either vertex are left out: near a junction a border also
/// runs along the next edge (within the contact radius of the patch across),
/// and the vertices pin the ends anyway.
///
/// ```
/// use scanfit::network::{fit_edge_curve, EdgeCurveConfig};
/// use scanfit::Point3;
/// let guide: Vec<Point3> = (0..=40).map(|i| Point3::new(i as f64 * 0.025, 0.01, 0.0)).collect();
/// let others: Vec<Point3> = (0..=40).map(|i| Point3::new(i as f64 * 0.025, -0.01, 0.0)).collect();
/// let (a, b) = (Point3::new(0., 0., 0.), Point3::new(1., 0., 0.));
/// let e = fit_edge_curve(a, b, &guide, &others, 0.025, 0.05, &EdgeCurveConfig::default())?;
/// assert_eq!(e.curve.point(0.0), a);
/// assert_eq!(e.curve.point(1.0), b);
/// assert!(e.curve.point(0.5).y.abs() < 1e-3);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn fit_edge_curve(
    start: Point3,
    end: Point3,
    guide: &[Point3],
    others: &[Point3],
    bin: f64,
    clearance: f64,
    cfg: &EdgeCurveConfig,
) -> Result<EdgeCurve> {
    if !(clearance.is_finite() && clearance >= 0.0) {
        return Err(Error::InvalidInput(format!(
            "edge end clearance {clearance} must be finite and >= 0"
        )));
    }
    if !(bin.is_finite() && bin > 0.0) {
        return Err(Error::InvalidInput(format!(
            "edge bin length {bin} must be positive"
        )));
    }
    if cfg.max_spans == 0 || !cfg.max_spans.is_power_of_two() {
        return Err(Error::InvalidInput(format!(
            "edge curve span limit {} must be a power of two",
            cfg.max_spans
        )));
    }
    // the guide polyline from start to end, with its arc length
    let mut poly = Vec::with_capacity(guide.len() + 2);
    poly.push(start);
    poly.extend_from_slice(guide);
    poly.push(end);
    let mut s = vec![0.0; poly.len()];
    for k in 1..poly.len() {
        s[k] = s[k - 1] + (poly[k] - poly[k - 1]).norm();
    }
    let length = s[poly.len() - 1];
    if length.is_nan() || length <= 0.0 {
        return Err(Error::InvalidInput(
            "an edge of zero length (its two corners coincide)".into(),
        ));
    }
    // place every border point at the arc length of its nearest guide vertex
    let bins = ((length / bin).round() as usize).max(1);
    let mut acc = vec![(crate::Vector3::zeros(), 0usize); bins];
    let interior = &poly[1..poly.len() - 1];
    let clear = |q: &Point3| (q - start).norm() >= clearance && (q - end).norm() >= clearance;
    for q in guide.iter().chain(others).filter(|q| clear(q)) {
        let (k, _) = interior
            .iter()
            .enumerate()
            .map(|(k, p)| (k, (p - q).norm_squared()))
            .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        let t = s[k + 1] / length;
        let b = ((t * bins as f64) as usize).min(bins - 1);
        acc[b].0 += q.coords;
        acc[b].1 += 1;
    }
    let mut fitted = vec![start];
    fitted.extend(
        acc.iter()
            .filter(|(_, n)| *n > 0)
            .map(|(c, n)| Point3::from(c / *n as f64)),
    );
    fitted.push(end);
    fitted.dedup();
    let p = cfg.degree;
    // spans: a power of two near sqrt(points), at most the limit, and few
    // enough that the points determine the control points
    let n = fitted.len();
    let mut spans = pow2_floor(((n as f64).sqrt()) as usize).min(cfg.max_spans);
    while spans > 1 && spans + p > n {
        spans /= 2;
    }
    let fit = fit_boundary_curve(
        &fitted,
        &BoundaryCurveConfig {
            degree: p,
            fit: BoundaryFit::LeastSquares {
                ctrl_count: Some(spans + p),
            },
        },
    )?;
    Ok(EdgeCurve {
        curve: fit.curve,
        fitted,
        max_error: fit.max_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow2() {
        assert_eq!(pow2_floor(0), 1);
        assert_eq!(pow2_floor(5), 4);
        assert_eq!(pow2_floor(16), 16);
        assert_eq!(pow2_floor(17), 16);
    }

    #[test]
    fn arc_between_two_noisy_borders() {
        // a quarter circle of radius 1 seen from both sides at +-0.01
        let side = |r: f64| -> Vec<Point3> {
            (1..200)
                .map(|i| {
                    let t = i as f64 / 200.0 * std::f64::consts::FRAC_PI_2;
                    Point3::new(r * t.cos(), r * t.sin(), 0.0)
                })
                .collect()
        };
        let (a, b) = (Point3::new(1., 0., 0.), Point3::new(0., 1., 0.));
        let mut other = side(0.99);
        other.reverse();
        let e = fit_edge_curve(
            a,
            b,
            &side(1.01),
            &other,
            0.01,
            0.03,
            &EdgeCurveConfig::default(),
        )
        .unwrap();
        assert_eq!(e.curve.control_points()[0], a);
        for k in 0..=20 {
            let p = e.curve.point(k as f64 / 20.0);
            let r = (p.x * p.x + p.y * p.y).sqrt();
            assert!((r - 1.0).abs() < 2e-3, "radius {r}");
        }
        // dyadic spans
        let spans = e.curve.control_points().len() - 3;
        assert!(spans.is_power_of_two() && spans <= 16);
    }
}
