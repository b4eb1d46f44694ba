#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Scale-free defaults: every surface pipeline gives, on a cloud scaled by
//! 1000, the same surface scaled by 1000 (its control net within 1e-7 of the
//! diagonal, the same net size, the same decisions), because every default
//! tolerance and threshold is relative to the data. A threshold in data
//! units (the Coons paper's epsilon 0.01) makes these fail: the grid
//! iteration stops at other points in millimetres and in metres.

use std::f64::consts::PI;

use scanfit::bspline::Surface;
use scanfit::pipeline::{coons, mba, surface_fit, turntable};
use scanfit::progress::NoProgress;
use scanfit::testdata::{franke, scattered, Lcg};
use scanfit::{Point3, PointCloud};

const SCALE: f64 = 1000.0;

fn scaled(points: &[Point3]) -> PointCloud {
    PointCloud::new(points.iter().map(|p| p * SCALE).collect()).unwrap()
}

/// Largest distance between `big`'s control points and `small`'s scaled by
/// 1000, as a share of the scaled diagonal `diag`.
fn mismatch(small: &Surface, big: &Surface, diag: f64) -> f64 {
    assert_eq!(small.counts(), big.counts());
    small
        .control_points()
        .iter()
        .zip(big.control_points())
        .map(|(a, b)| (a * SCALE - b).norm())
        .fold(0.0, f64::max)
        / diag
}

/// A curved four-sided patch of scattered points (unit-ish size).
fn patch(n: usize) -> Vec<Point3> {
    let mut r = Lcg::new(5);
    (0..n)
        .map(|_| {
            let (u, v) = (r.next_f64(), r.next_f64());
            Point3::new(
                1.0 * u + 0.06 * (PI * v).sin(),
                0.7 * v - 0.04 * (PI * u).sin(),
                0.18 * (u - 0.5).powi(2) - 0.12 * (v - 0.5).powi(2) + 0.05 * (2.0 * u).sin() * v,
            )
        })
        .collect()
}

#[test]
fn fit_is_scale_free() {
    let pts = scattered(3000, 3, [0.0, 0.0, 1.0, 1.0], franke);
    let cfg = surface_fit::FitConfig::default();
    let a = surface_fit::run(&PointCloud::new(pts.clone()).unwrap(), &cfg, &NoProgress).unwrap();
    let big = scaled(&pts);
    let b = surface_fit::run(&big, &cfg, &NoProgress).unwrap();
    // the density rule and the scaled weight: 14 x 14 and the same lambda
    assert_eq!(a.surface.counts(), (14, 14));
    assert_eq!(a.smoothing, b.smoothing);
    let m = mismatch(&a.surface, &b.surface, big.diagonal());
    assert!(m < 1e-9, "{m}");
    assert_eq!(
        a.assessment.quality.extent.leaves,
        b.assessment.quality.extent.leaves
    );
}

#[test]
fn mba_is_scale_free() {
    let pts = scattered(3000, 4, [0.0, 0.0, 1.0, 1.0], franke);
    let mut cfg = mba::MbaRunConfig::default();
    cfg.mba.max_levels = 4;
    let a = mba::run(&PointCloud::new(pts.clone()).unwrap(), &cfg, &NoProgress).unwrap();
    let big = scaled(&pts);
    let b = mba::run(&big, &cfg, &NoProgress).unwrap();
    let m = mismatch(&a.surface, &b.surface, big.diagonal());
    assert!(m < 1e-9, "{m}");
}

#[test]
fn coons_is_scale_free_on_both_routes() {
    let pts = patch(3000);
    let small = PointCloud::new(pts.clone()).unwrap();
    let big = scaled(&pts);
    for route in [coons::CoonsRoute::default(), coons::CoonsRoute::pde(5, 5)] {
        let mut cfg = coons::CoonsConfig::default();
        cfg.route = route;
        let a = coons::run(&small, &cfg, &NoProgress).unwrap();
        let b = coons::run(&big, &cfg, &NoProgress).unwrap();
        assert_eq!(a.base.corners.corners, b.base.corners.corners);
        let m = mismatch(&a.surface, &b.surface, big.diagonal());
        assert!(m < 1e-7, "{}: {m}", a.route);
        let (ea, eb) = (
            a.assessment.quality.at_parameters.rmse,
            b.assessment.quality.at_parameters.rmse,
        );
        assert!((eb - SCALE * ea).abs() <= 1e-6 * eb, "{ea} {eb}");
    }
    // the paper's epsilon in data units (0.01) is not scale-free: the grid
    // iteration stops elsewhere on the scaled cloud
    let mut cfg = coons::CoonsConfig::default();
    cfg.relative_epsilon = None;
    let a = coons::run(&small, &cfg, &NoProgress).unwrap();
    let b = coons::run(&big, &cfg, &NoProgress).unwrap();
    let m = mismatch(&a.surface, &b.surface, big.diagonal());
    assert!(m > 1e-6, "{m}");
}

#[test]
fn turntable_is_scale_free() {
    // a tube of radius 1, height 4, closed at the bottom by a disk
    let mut r = Lcg::new(9);
    let mut pts = Vec::new();
    for k in 0..6000 {
        let t = 2.0 * PI * r.next_f64();
        if k % 5 == 0 {
            let rad = r.next_f64().sqrt();
            pts.push(Point3::new(rad * t.cos(), 0.0, rad * t.sin()));
        } else {
            let h = 4.0 * r.next_f64();
            let rad = 1.0 + 0.1 * (PI * h / 4.0).sin();
            pts.push(Point3::new(rad * t.cos(), h, rad * t.sin()));
        }
    }
    let mut cfg = turntable::TurntableConfig::default();
    cfg.turntable.fit.ctrl = (16, 16);
    cfg.turntable.layers.layers = 20;
    let a = turntable::run(&PointCloud::new(pts.clone()).unwrap(), &cfg, &NoProgress).unwrap();
    let big = scaled(&pts);
    let b = turntable::run(&big, &cfg, &NoProgress).unwrap();
    let (ta, tb) = (&a.turntable, &b.turntable);
    // the bottom (low end along the axis, or high if the axis points down) is closed, the rim open
    let open =
        |t: &scanfit::base::turntable::Turntable| [t.end_shapes[0].open, t.end_shapes[1].open];
    assert_eq!(open(ta), open(tb));
    assert_eq!(
        open(ta).iter().filter(|&&o| o).count(),
        1,
        "{:?}",
        ta.end_shapes
    );
    let m = mismatch(&ta.surface, &tb.surface, big.diagonal());
    assert!(m < 1e-7, "{m}");
}
