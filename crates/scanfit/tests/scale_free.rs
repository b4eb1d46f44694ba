#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Scale-free defaults: every surface pipeline gives, on a cloud scaled by
//! 1000, the same surface scaled by 1000 (its control net within 1e-7 of the
//! diagonal, the same net size, the same decisions), because every default
//! tolerance and threshold is relative to the data. A threshold in data
//! units (the Coons paper's epsilon 0.01) makes these fail: the grid
//! iteration stops at other points in millimetres and in metres. The same
//! holds for the curve fits (the same parameters), `reconstruct`, and the
//! cloud tools (normals, boundary loops and corners, cleaning).

use std::f64::consts::PI;

use scanfit::bspline::Surface;
use scanfit::cloud::clean::OutlierConfig;
use scanfit::pipeline::{cloud, coons, curve, mba, reconstruct, surface_fit, turntable};
use scanfit::progress::NoProgress;
use scanfit::testdata::{franke, scattered, Lcg};
use scanfit::{Point3, PointCloud};

const SCALE: f64 = 1000.0;

fn scaled(points: &[Point3]) -> PointCloud {
    PointCloud::new(points.iter().map(|p| p * SCALE).collect()).unwrap()
}

/// Largest distance between the control points `big` and `small` scaled by
/// 1000, as a share of the scaled diagonal `diag`.
fn net_mismatch(small: &[Point3], big: &[Point3], diag: f64) -> f64 {
    assert_eq!(small.len(), big.len());
    small
        .iter()
        .zip(big)
        .map(|(a, b)| (a * SCALE - b).norm())
        .fold(0.0, f64::max)
        / diag
}

/// [`net_mismatch`] of two surfaces (with the same net size).
fn mismatch(small: &Surface, big: &Surface, diag: f64) -> f64 {
    assert_eq!(small.counts(), big.counts());
    net_mismatch(small.control_points(), big.control_points(), diag)
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

#[test]
fn curve_fits_are_scale_free() {
    // an open spiral arc, unevenly spaced, and a closed loop
    let open: Vec<Point3> = (0..60)
        .map(|k| {
            let t = (k as f64 / 59.0).powf(1.4) * 3.0;
            Point3::new(t.cos() * (1.0 + 0.2 * t), t.sin(), 0.1 * t)
        })
        .collect();
    let closed: Vec<Point3> = (0..50)
        .map(|k| {
            let t = k as f64 / 50.0 * 2.0 * PI;
            Point3::new(1.3 * t.cos(), 0.8 * t.sin() + 0.1 * (3.0 * t).cos(), 0.0)
        })
        .collect();
    let mut lsq = curve::CurveConfig::default();
    lsq.kind = curve::CurveFitKind::LeastSquares {
        ctrl_count: 12,
        fix_ends: true,
        smoothing: 0.0,
    };
    let mut periodic = curve::CurveConfig::default();
    periodic.closed = true;
    for (pts, cfg) in [
        (&open, curve::CurveConfig::default()),
        (&open, lsq),
        (&closed, periodic),
    ] {
        let big: Vec<Point3> = pts.iter().map(|p| p * SCALE).collect();
        let a = curve::run(pts, &cfg, &NoProgress).unwrap();
        let b = curve::run(&big, &cfg, &NoProgress).unwrap();
        // the same parameters (they are ratios of lengths) and the curve scaled
        for (ua, ub) in a.fit.params.iter().zip(&b.fit.params) {
            assert!((ua - ub).abs() < 1e-12, "{ua} {ub}");
        }
        let diag = PointCloud::new(big).unwrap().diagonal();
        let m = net_mismatch(
            a.fit.curve.control_points(),
            b.fit.curve.control_points(),
            diag,
        );
        assert!(m < 1e-9, "{cfg:?}: {m}");
        let (ea, eb) = (a.quality.max_deviation, b.quality.max_deviation);
        assert!((eb - SCALE * ea).abs() <= 1e-6 * diag, "{ea} {eb}");
    }
}

#[test]
fn reconstruct_is_scale_free() {
    // a gently curved 2 x 1 sheet in two labelled halves
    let (mut pts, mut lab) = (Vec::new(), Vec::new());
    for i in 0..=60 {
        for j in 0..=30 {
            let (x, y) = (i as f64 / 30.0, j as f64 / 30.0);
            pts.push(Point3::new(
                x,
                y,
                0.1 * (x * y).sin() + 0.05 * (3.0 * x).cos(),
            ));
            lab.push(if i < 30 { 0.0 } else { 1.0 });
        }
    }
    let small = PointCloud::new(pts.clone())
        .unwrap()
        .with_attribute("label", lab.clone())
        .unwrap();
    let big = scaled(&pts).with_attribute("label", lab).unwrap();
    let cfg = reconstruct::ReconstructConfig::default();
    let a = reconstruct::run(&small, &cfg, &NoProgress).unwrap();
    let b = reconstruct::run(&big, &cfg, &NoProgress).unwrap();
    assert_eq!(a.faces.len(), 2);
    assert_eq!(a.faces.len(), b.faces.len());
    for (fa, fb) in a.faces.iter().zip(&b.faces) {
        let m = mismatch(&fa.surface, &fb.surface, big.diagonal());
        assert!(m < 1e-7, "{m}");
    }
    let (ga, gb) = (a.totals.max_gap, b.totals.max_gap);
    assert!(gb <= SCALE * ga + 1e-9 * big.diagonal(), "{ga} {gb}");
}

#[test]
fn cloud_normals_boundary_corners_and_clean_are_scale_free() {
    // the curved patch with 12 strays well above it
    let mut pts = patch(3000);
    let mut r = Lcg::new(17);
    for _ in 0..12 {
        pts.push(Point3::new(
            r.next_f64(),
            0.7 * r.next_f64(),
            0.4 + 0.4 * r.next_f64(),
        ));
    }
    let small = PointCloud::new(pts.clone()).unwrap();
    let big = scaled(&pts);
    // normals: the same directions
    let cfg = cloud::CloudNormalsConfig::default();
    let (na, nb) = (
        cloud::normals(&small, &cfg, &NoProgress).unwrap(),
        cloud::normals(&big, &cfg, &NoProgress).unwrap(),
    );
    let worst = na
        .normals
        .normals
        .iter()
        .zip(&nb.normals.normals)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
    // boundary and corners: the same loop, the same corners, alpha x 1000
    let patch_only = PointCloud::new(pts[..3000].to_vec()).unwrap();
    let patch_big = scaled(&pts[..3000]);
    let cfg = cloud::CloudBoundaryConfig::default();
    let (ba, bb) = (
        cloud::boundary(&patch_only, &cfg, &NoProgress).unwrap(),
        cloud::boundary(&patch_big, &cfg, &NoProgress).unwrap(),
    );
    assert_eq!(ba.boundary.loops, bb.boundary.loops);
    assert_eq!(
        ba.corners.as_ref().unwrap().corners,
        bb.corners.as_ref().unwrap().corners
    );
    assert!((bb.boundary.alpha - SCALE * ba.boundary.alpha).abs() < 1e-9 * bb.boundary.alpha);
    // clean: outliers, fragments and voxels in spacings remove the same points
    let mut cfg = cloud::CloudCleanConfig::remove_outliers();
    cfg.outliers = Some(OutlierConfig::default());
    cfg.fragments = Some(cloud::FragmentConfig::default());
    let (ca, cb) = (
        cloud::clean(&small, &cfg, &NoProgress).unwrap(),
        cloud::clean(&big, &cfg, &NoProgress).unwrap(),
    );
    assert_eq!(ca.kept, cb.kept);
    assert!(
        ca.kept.len() <= 3000 && ca.kept.len() > 2900,
        "{}",
        ca.kept.len()
    );
    assert!(ca.kept.iter().all(|&i| i < 3000));
}
