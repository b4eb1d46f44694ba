//! Quality report of a fitted curve: how far it is from the data, how much it
//! bends, whether it wiggles or loops, and how much longer than the data
//! polygon it is. These are the properties [CURVE12] judges its figures
//! by ("bulky", "small loop", "cusp", "inflection point").

use crate::bspline::{BasisWorkspace, Curve};
use crate::{Point3, Vector3};

/// Settings of [`curve_quality`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QualityConfig {
    /// Samples per knot span for curvature, length and loop detection (default 64).
    pub samples_per_span: usize,
    /// A curvature lobe (a run of one sign) counts towards the inflections only
    /// if its peak exceeds this fraction of the maximum curvature (default 0.01),
    /// so the faint ringing of an interpolant along collinear data does not
    /// count as an inflection.
    pub curvature_zero: f64,
}

impl Default for QualityConfig {
    fn default() -> Self {
        Self {
            samples_per_span: 64,
            curvature_zero: 0.01,
        }
    }
}

/// The per-curve quality report.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveQuality {
    /// Largest `|C(u_k) - Q_k|` over the data (at the fit parameters).
    pub max_deviation: f64,
    /// Index of the point with the largest deviation.
    pub max_deviation_index: usize,
    /// Mean of `|C(u_k) - Q_k|`.
    pub mean_deviation: f64,
    /// Root mean square of `|C(u_k) - Q_k|`.
    pub rms_deviation: f64,
    /// Largest orthogonal (closest-point) distance from a data point to the curve.
    pub max_distance: f64,
    /// Largest curvature `|C' x C''| / |C'|^3` along the curve (1/length units).
    pub max_curvature: f64,
    /// Parameter where the curvature is largest.
    pub max_curvature_at: f64,
    /// Number of sign changes between significant curvature lobes, the curvature
    /// signed about the best-fit plane's normal (inflections of a planar curve).
    pub curvature_sign_changes: usize,
    /// Number of self-intersections (loops) of the curve.
    pub self_intersections: usize,
    /// Length of the curve.
    pub length: f64,
    /// Length of the data polygon (closed polygons include the closing edge).
    pub polygon_length: f64,
    /// `length / polygon_length`: near 1 for a tight fit, large for bulges.
    pub length_ratio: f64,
}

/// Computes the quality report of `curve` fitted to `points` at `params`.
pub fn curve_quality(
    curve: &Curve,
    points: &[Point3],
    params: &[f64],
    cfg: &QualityConfig,
) -> CurveQuality {
    let p = curve.degree();
    let mut ws = BasisWorkspace::new(p, 2);

    // deviations at the fit parameters, and orthogonal distances by Newton
    let (mut max_dev, mut max_idx, mut sum, mut sum2, mut max_dist) =
        (0.0f64, 0usize, 0.0, 0.0, 0.0f64);
    for (k, (q, &u)) in points.iter().zip(params).enumerate() {
        let d = (curve.point(u) - q).norm();
        if d > max_dev {
            max_dev = d;
            max_idx = k;
        }
        sum += d;
        sum2 += d * d;
        let (_, dist) = closest_point_near(curve, q, u, &mut ws);
        max_dist = max_dist.max(dist.min(d));
    }
    let count = points.len().max(1) as f64;

    // dense samples: per span, uniformly
    let bps = curve.knots().breakpoints();
    let mut us = Vec::with_capacity(bps.len() * cfg.samples_per_span + 1);
    for w in bps.windows(2) {
        for k in 0..cfg.samples_per_span {
            us.push(w[0] + (w[1] - w[0]) * k as f64 / cfg.samples_per_span as f64);
        }
    }
    us.push(bps[bps.len() - 1]);
    let mut samples = vec![Point3::origin(); us.len()];
    curve.eval_many(&us, &mut samples);
    let length: f64 = samples.windows(2).map(|w| (w[1] - w[0]).norm()).sum();

    // curvature, signed about the normal of the best-fit plane of the samples
    let normal = plane_normal(&samples);
    let mut d = [Vector3::zeros(); 3];
    let mut signed = Vec::with_capacity(us.len());
    let (mut kmax, mut kmax_at) = (0.0f64, us[0]);
    for &u in &us {
        curve.derivatives_into(u, &mut ws, &mut d);
        let speed = d[1].norm();
        let k = if speed > 0.0 {
            let c = d[1].cross(&d[2]);
            c.norm() / speed.powi(3) * if c.dot(&normal) < 0.0 { -1.0 } else { 1.0 }
        } else {
            0.0
        };
        if k.abs() > kmax {
            kmax = k.abs();
            kmax_at = u;
        }
        signed.push(k);
    }
    let changes = count_inflections(&signed, kmax * cfg.curvature_zero);

    let closed = curve.is_closed();
    let mut polygon_length: f64 = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    if curve.is_periodic() && points.len() > 1 {
        polygon_length += (points[0] - points[points.len() - 1]).norm();
    }
    let self_intersections = count_self_intersections(&samples, closed);
    CurveQuality {
        max_deviation: max_dev,
        max_deviation_index: max_idx,
        mean_deviation: sum / count,
        rms_deviation: (sum2 / count).sqrt(),
        max_distance: max_dist,
        max_curvature: kmax,
        max_curvature_at: kmax_at,
        curvature_sign_changes: changes,
        self_intersections,
        length,
        polygon_length,
        length_ratio: if polygon_length > 0.0 {
            length / polygon_length
        } else {
            f64::NAN
        },
    }
}

/// Sign changes between lobes of `signed` curvature whose peak exceeds `threshold`.
fn count_inflections(signed: &[f64], threshold: f64) -> usize {
    let mut lobes: Vec<f64> = Vec::new(); // signs of significant lobes
    let (mut sign, mut peak) = (0.0f64, 0.0f64);
    let close = |sign: f64, peak: f64, lobes: &mut Vec<f64>| {
        if sign != 0.0 && peak > threshold && lobes.last() != Some(&sign) {
            lobes.push(sign);
        }
    };
    for &k in signed {
        if k == 0.0 {
            continue;
        }
        if k.signum() != sign {
            close(sign, peak, &mut lobes);
            sign = k.signum();
            peak = 0.0;
        }
        peak = peak.max(k.abs());
    }
    close(sign, peak, &mut lobes);
    lobes.len().saturating_sub(1)
}

/// Closest point on `curve` to `q` by Newton iteration on `(C(u) - q) . C'(u) = 0`
/// started at `u0` (NURBS Book section 6.1), clamped (or wrapped) to the domain.
/// Returns `(u, distance)`; if Newton does not improve on the start, the start.
pub fn closest_point_near(
    curve: &Curve,
    q: &Point3,
    u0: f64,
    ws: &mut BasisWorkspace,
) -> (f64, f64) {
    let (a, b) = curve.domain();
    let mut d = [Vector3::zeros(); 3];
    let mut u = u0;
    let start = (curve.point(u0) - q).norm();
    let mut best = (u0, start);
    for _ in 0..20 {
        curve.derivatives_into(u, ws, &mut d);
        let r = d[0] - q.coords;
        let f = r.dot(&d[1]);
        let fp = d[2].dot(&r) + d[1].norm_squared();
        if fp <= 0.0 || !fp.is_finite() {
            break;
        }
        let mut next = u - f / fp;
        next = if curve.is_periodic() {
            curve.wrap(next)
        } else {
            next.clamp(a, b)
        };
        let dist = (curve.point(next) - q).norm();
        if dist < best.1 {
            best = (next, dist);
        }
        if (next - u).abs() <= 1e-15 * (b - a) {
            break;
        }
        u = next;
    }
    best
}

/// Closest points on `curve` to each of `points`: Newton by
/// [`closest_point_near`] started at the nearest of `samples_per_span`
/// uniform samples per knot span (at least 1), in parallel. Returns
/// `(u, distance)` per point, in order.
///
/// ```
/// use scanfit::bspline::{Curve, KnotVector};
/// use scanfit::quality::closest_points;
/// use scanfit::Point3;
///
/// // the straight line from (0, 0, 0) to (3, 0, 0), degree 1
/// let kv = KnotVector::new(vec![0.0, 0.0, 1.0, 1.0], 1)?;
/// let c = Curve::new(kv, vec![Point3::origin(), Point3::new(3.0, 0.0, 0.0)])?;
/// let r = closest_points(&c, &[Point3::new(1.5, 2.0, 0.0)], 4);
/// assert!((r[0].0 - 0.5).abs() < 1e-12 && (r[0].1 - 2.0).abs() < 1e-12);
/// # Ok::<(), scanfit::Error>(())
/// ```
pub fn closest_points(
    curve: &Curve,
    points: &[Point3],
    samples_per_span: usize,
) -> Vec<(f64, f64)> {
    use rayon::prelude::*;
    let n = samples_per_span.max(1);
    let bps = curve.knots().breakpoints();
    let mut us = Vec::with_capacity(bps.len() * n + 1);
    for w in bps.windows(2) {
        us.extend((0..n).map(|k| w[0] + (w[1] - w[0]) * k as f64 / n as f64));
    }
    us.extend(bps.last());
    let mut samples = vec![Point3::origin(); us.len()];
    curve.eval_many(&us, &mut samples);
    points
        .par_iter()
        .map_init(
            || BasisWorkspace::new(curve.degree(), 2),
            |ws, q| {
                let start = samples
                    .iter()
                    .zip(&us)
                    .map(|(s, &u)| ((s - q).norm_squared(), u))
                    .fold((f64::INFINITY, us[0]), |a, b| if b.0 < a.0 { b } else { a });
                closest_point_near(curve, q, start.1, ws)
            },
        )
        .collect()
}

/// Unit normal of the least-squares plane through `pts` (eigenvector of the
/// smallest eigenvalue of their covariance); `z` for degenerate input.
pub(crate) fn plane_normal(pts: &[Point3]) -> Vector3 {
    let n = pts.len().max(1) as f64;
    let c = pts.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
    let mut cov = nalgebra::Matrix3::zeros();
    for p in pts {
        let d = p.coords - c;
        cov += d * d.transpose();
    }
    let eig = nalgebra::SymmetricEigen::new(cov);
    let i = eig.eigenvalues.imin();
    let v: Vector3 = eig.eigenvectors.column(i).into();
    // orientation: make the largest component positive, so that the sign of the
    // curvature does not depend on the eigen solver's choice
    let j = v.iamax();
    let v = if v[j] < 0.0 { -v } else { v };
    if v.norm() > 0.0 {
        v.normalize()
    } else {
        Vector3::z()
    }
}

/// Counts crossings of a sampled polyline with itself. Segments are swept in
/// order of their smallest x; non-adjacent pairs whose distance is below
/// `1e-9 x` the polyline's size intersect. Hits at neighbouring segment pairs
/// (a crossing at a shared vertex) count once.
pub(crate) fn count_self_intersections(poly: &[Point3], closed: bool) -> usize {
    let m = poly.len().saturating_sub(1);
    if m < 3 {
        return 0;
    }
    let tol = 1e-9 * crate::geom::bbox_diagonal(poly);
    let mut order: Vec<usize> = (0..m).collect();
    let lo = |i: usize| poly[i].x.min(poly[i + 1].x);
    let hi = |i: usize| poly[i].x.max(poly[i + 1].x);
    order.sort_by(|&a, &b| lo(a).total_cmp(&lo(b)));
    let mut hits: Vec<(usize, usize)> = Vec::new();
    for (oi, &i) in order.iter().enumerate() {
        for &j in &order[oi + 1..] {
            if lo(j) > hi(i) + tol {
                break;
            }
            let (a, b) = (i.min(j), i.max(j));
            if b - a <= 1 || (closed && a == 0 && b == m - 1) {
                continue;
            }
            if segment_distance(&poly[a], &poly[a + 1], &poly[b], &poly[b + 1]) <= tol {
                hits.push((a, b));
            }
        }
    }
    hits.sort_unstable();
    // neighbouring segments (cyclically for a closed polyline) are one crossing
    let near = |a: usize, b: usize| {
        let d = a.abs_diff(b);
        d <= 1 || (closed && m - d <= 1)
    };
    let mut count = 0;
    let mut kept: Vec<(usize, usize)> = Vec::new();
    for h in hits {
        if !kept
            .iter()
            .any(|k| (near(h.0, k.0) && near(h.1, k.1)) || (near(h.0, k.1) && near(h.1, k.0)))
        {
            count += 1;
        }
        kept.push(h);
    }
    count
}

/// Distance between segments `[p0, p1]` and `[q0, q1]` (closest points of two
/// segments, clamped parameters).
fn segment_distance(p0: &Point3, p1: &Point3, q0: &Point3, q1: &Point3) -> f64 {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let (s, t);
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return r.norm();
    }
    if a <= f64::MIN_POSITIVE {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= f64::MIN_POSITIVE {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::KnotVector;

    fn p(x: f64, y: f64) -> Point3 {
        Point3::new(x, y, 0.0)
    }

    #[test]
    fn figure_eight_has_one_crossing_and_square_none() {
        let eight: Vec<Point3> = (0..=400)
            .map(|k| {
                let t = k as f64 / 400.0 * std::f64::consts::TAU;
                p(t.sin(), (2.0 * t).sin() * 0.5)
            })
            .collect();
        assert_eq!(count_self_intersections(&eight, true), 1);
        let square = vec![p(0., 0.), p(1., 0.), p(1., 1.), p(0., 1.), p(0., 0.)];
        assert_eq!(count_self_intersections(&square, true), 0);
        let open_loop = vec![p(0., 0.), p(2., 0.), p(2., 1.), p(1., 1.), p(1., -1.)];
        assert_eq!(count_self_intersections(&open_loop, false), 1);
    }

    #[test]
    fn straight_line_has_zero_curvature_and_unit_length_ratio() {
        let kv = KnotVector::uniform_clamped(3, 5).unwrap();
        let ctrl: Vec<Point3> = (0..5).map(|i| p(i as f64, 2.0 * i as f64)).collect();
        let c = Curve::new(kv, ctrl).unwrap();
        let pts = vec![p(0., 0.), p(4., 8.)];
        let q = curve_quality(&c, &pts, &[0.0, 1.0], &QualityConfig::default());
        assert!(q.max_curvature < 1e-12);
        assert_eq!(q.curvature_sign_changes, 0);
        assert!((q.length_ratio - 1.0).abs() < 1e-12);
        assert!(q.max_deviation < 1e-12);
    }

    #[test]
    fn s_curve_has_one_inflection_and_circle_arc_curvature() {
        // an S: two opposite bends
        let kv = KnotVector::uniform_clamped(3, 6).unwrap();
        let ctrl = vec![
            p(0., 0.),
            p(1., 1.),
            p(2., 1.),
            p(3., -1.),
            p(4., -1.),
            p(5., 0.),
        ];
        let c = Curve::new(kv, ctrl).unwrap();
        let q = curve_quality(&c, &[p(0., 0.)], &[0.0], &QualityConfig::default());
        assert_eq!(q.curvature_sign_changes, 1);
        assert_eq!(q.self_intersections, 0);
    }

    #[test]
    fn faint_lobes_do_not_count() {
        let k = [1.0, 2.0, -0.001, 0.5, 1.0, -1.0, -2.0, 0.0, -1.0];
        assert_eq!(count_inflections(&k, 0.02), 1);
        assert_eq!(count_inflections(&k, 0.0), 3);
    }

    #[test]
    fn closest_point_newton_finds_foot() {
        let kv = KnotVector::uniform_clamped(2, 3).unwrap();
        // parabola y = x^2 on [-1, 1]: control points (-1,1), (0,-1), (1,1)
        let c = Curve::new(kv, vec![p(-1., 1.), p(0., -1.), p(1., 1.)]).unwrap();
        let mut ws = BasisWorkspace::new(2, 2);
        let (u, d) = closest_point_near(&c, &p(0.0, -2.0), 0.3, &mut ws);
        assert!((u - 0.5).abs() < 1e-10, "{u}");
        assert!((d - 2.0).abs() < 1e-12);
    }
}
