//! Property tests: invariants that must hold for any input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use proptest::prelude::*;
use scanfit::bspline::{BasisWorkspace, Curve, KnotVector};
use scanfit::fit::{approximate, interpolate, ApproximationConfig, InterpolationConfig};
use scanfit::param::Method;
use scanfit::Point3;

/// 5..40 points along a random walk with steps of length 0.1..10 (no duplicates).
fn walk() -> impl Strategy<Value = Vec<Point3>> {
    prop::collection::vec(
        (0.1f64..10.0, 0.0f64..std::f64::consts::TAU, -1.0f64..1.0),
        5..40,
    )
    .prop_map(|steps| {
        let mut p = Point3::origin();
        let mut out = vec![p];
        for (len, angle, dz) in steps {
            p += nalgebra::Vector3::new(angle.cos(), angle.sin(), dz).normalize() * len;
            out.push(p);
        }
        out
    })
}

proptest! {
    /// Interpolation hits every point (any degree 1..5, centripetal and the new method).
    #[test]
    fn interpolation_is_exact(pts in walk(), degree in 1usize..6, new in any::<bool>()) {
        prop_assume!(pts.len() > degree);
        let method = if new { Method::Proposed(0.8) } else { Method::Centripetal };
        let cfg = InterpolationConfig { degree, method, ..Default::default() };
        // the new method may legitimately refuse (non-increasing shifted parameters)
        if let Ok(fit) = interpolate(&pts, &cfg) {
            let scale = pts.iter().map(|p| p.coords.amax()).fold(1.0, f64::max);
            for (u, q) in fit.params.iter().zip(&pts) {
                prop_assert!((fit.curve.point(*u) - q).norm() < 1e-9 * scale);
            }
        } else {
            prop_assert!(new, "centripetal interpolation failed");
        }
    }

    /// Closed interpolation closes smoothly: C and C' agree across the seam.
    #[test]
    fn closed_interpolation_is_periodic(pts in walk(), degree in 2usize..4) {
        prop_assume!(pts.len() > 2 * degree);
        let cfg = InterpolationConfig { degree, method: Method::Centripetal, closed: true, ..Default::default() };
        let fit = interpolate(&pts, &cfg).unwrap();
        let c = &fit.curve;
        let mut ws = BasisWorkspace::new(degree, 1);
        let mut a = [nalgebra::Vector3::zeros(); 2];
        let mut b = [nalgebra::Vector3::zeros(); 2];
        c.derivatives_into(0.0, &mut ws, &mut a);
        c.derivatives_into(1.0 - 1e-15, &mut ws, &mut b);
        let scale = pts.iter().map(|p| p.coords.amax()).fold(1.0, f64::max);
        prop_assert!((a[0] - b[0]).norm() < 1e-9 * scale);
        prop_assert!((a[1] - b[1]).norm() < 1e-6 * (scale + a[1].norm()));
        for (u, q) in fit.params.iter().zip(&pts) {
            prop_assert!((c.point(*u) - q).norm() < 1e-9 * scale);
        }
    }

    /// Least squares with as many control points as points reproduces the points
    /// (it is then an interpolation), and fixed ends are exact.
    #[test]
    fn least_squares_pins_ends(pts in walk(), extra in 0usize..3) {
        let n = (4 + extra).min(pts.len());
        let cfg = ApproximationConfig { ctrl_count: n, method: Method::Centripetal, ..Default::default() };
        let fit = approximate(&pts, &cfg).unwrap();
        let c = &fit.curve;
        prop_assert_eq!(c.control_points()[0], pts[0]);
        prop_assert_eq!(*c.control_points().last().unwrap(), *pts.last().unwrap());
        prop_assert!((c.point(1.0) - pts.last().unwrap()).norm() < 1e-12 * (1.0 + pts.last().unwrap().coords.norm()));
    }

    /// Knot insertion never changes the curve.
    #[test]
    fn knot_insertion_preserves_shape(pts in walk(), x in 0.01f64..0.99, r in 1usize..3) {
        prop_assume!(pts.len() >= 4);
        let kv = KnotVector::uniform_clamped(3, pts.len()).unwrap();
        let c = Curve::new(kv, pts.clone()).unwrap();
        let mult = c.knots().multiplicity(x);
        prop_assume!(mult + r <= 3);
        let c2 = c.insert_knot(x, r).unwrap();
        let scale = pts.iter().map(|p| p.coords.amax()).fold(1.0, f64::max);
        for k in 0..=50 {
            let u = k as f64 / 50.0;
            prop_assert!((c.point(u) - c2.point(u)).norm() < 1e-12 * scale);
        }
    }
}
