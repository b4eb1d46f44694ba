//! Point inversion: true parameters of points on the surface to 1e-10, true foot
//! points of points off it, boundary and periodic cases, and the Coons-paper
//! grid scheme.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use scanfit::bspline::{BasisWorkspace, KnotVector, Surface};
use scanfit::project::{
    grid_iteration, GridIterationConfig, InversionConfig, InversionWorkspace, SurfaceInverter,
};
use scanfit::testdata::Lcg;
use scanfit::Point3;

fn known() -> Surface {
    let ku = KnotVector::new(vec![0., 0., 0., 0., 0.2, 0.45, 0.7, 1., 1., 1., 1.], 3).unwrap();
    let kv = KnotVector::new(vec![0., 0., 0., 0., 0.3, 0.6, 1., 1., 1., 1.], 3).unwrap();
    let mut c = Vec::new();
    for i in 0..7 {
        for j in 0..6 {
            let (x, y) = (i as f64, j as f64);
            c.push(Point3::new(
                x + 0.1 * y,
                y - 0.05 * x * x,
                0.8 * (0.9 * x).sin() * (0.7 * y).cos() + 0.1 * x * y,
            ));
        }
    }
    Surface::new(ku, kv, c).unwrap()
}

fn rnd(state: &mut Lcg) -> f64 {
    state.next_f64()
}

#[test]
fn recovers_parameters_of_points_on_the_surface() {
    let s = known();
    let inv = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
    let mut st = Lcg::new(11);
    let uv: Vec<[f64; 2]> = (0..5000).map(|_| [rnd(&mut st), rnd(&mut st)]).collect();
    let pts: Vec<Point3> = uv.iter().map(|t| s.point(t[0], t[1])).collect();
    let res = inv.invert_all(&pts);
    for (r, t) in res.iter().zip(&uv) {
        assert!(r.converged);
        assert!(
            (r.uv[0] - t[0]).abs() < 1e-10 && (r.uv[1] - t[1]).abs() < 1e-10,
            "{:?} vs {t:?}",
            r.uv
        );
        assert!(r.distance < 1e-10);
    }
}

#[test]
fn recovers_foot_points_of_points_off_the_surface() {
    let s = known();
    let inv = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
    let (mut wu, mut wv) = (BasisWorkspace::new(3, 1), BasisWorkspace::new(3, 1));
    let mut ws = InversionWorkspace::new(&s);
    let mut st = Lcg::new(5);
    for _ in 0..2000 {
        // interior parameters, offset along the normal by less than the radius of curvature
        let t = [0.05 + 0.9 * rnd(&mut st), 0.05 + 0.9 * rnd(&mut st)];
        let d = (rnd(&mut st) - 0.5) * 0.2;
        let n = s.normal(t[0], t[1], &mut wu, &mut wv);
        let p = s.point(t[0], t[1]) + n * d;
        let r = inv.invert(&p, &mut ws);
        assert!(r.converged);
        assert!(
            (r.uv[0] - t[0]).abs() < 1e-10 && (r.uv[1] - t[1]).abs() < 1e-10,
            "{:?} vs {t:?} (d = {d})",
            r.uv
        );
        assert!((r.distance - d.abs()).abs() < 1e-10);
    }
}

#[test]
fn points_beyond_the_boundary_project_onto_it() {
    let s = known();
    let inv = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
    let mut ws = InversionWorkspace::new(&s);
    // beyond the u = 0 edge: brute force over a fine sampling of that edge and the interior
    let p = s.point(0.0, 0.4) + nalgebra::Vector3::new(-1.5, 0.2, 0.3);
    let r = inv.invert(&p, &mut ws);
    let mut best = f64::INFINITY;
    for i in 0..=400 {
        for j in 0..=400 {
            best = best.min((s.point(i as f64 / 400.0, j as f64 / 400.0) - p).norm());
        }
    }
    assert!(r.uv[0] == 0.0, "{:?}", r.uv);
    assert!(
        r.distance <= best + 1e-9,
        "{} vs brute force {best}",
        r.distance
    );
    assert!(r.converged);
}

#[test]
fn periodic_direction_wraps() {
    // cylinder periodic in u
    let p = 3;
    let nd = 8;
    let ku = KnotVector::uniform_periodic(p, nd).unwrap();
    let kv = KnotVector::uniform_clamped(3, 4).unwrap();
    let mut c = Vec::new();
    for i in 0..nd + p {
        let a = (i % nd) as f64 / nd as f64 * std::f64::consts::TAU;
        for j in 0..4 {
            c.push(Point3::new(a.cos(), a.sin(), j as f64));
        }
    }
    let s = Surface::with_options(ku, kv, c, None, true, false).unwrap();
    let inv = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
    let mut ws = InversionWorkspace::new(&s);
    for &(u, v) in &[(0.001, 0.5), (0.999, 0.3), (0.5, 0.7)] {
        let q = s.point(u, v);
        let r = inv.invert(&q, &mut ws);
        let du = (r.uv[0] - u).abs().min(1.0 - (r.uv[0] - u).abs());
        assert!(
            du < 1e-10 && (r.uv[1] - v).abs() < 1e-10,
            "{:?} vs ({u},{v})",
            r.uv
        );
        // and starting across the seam converges through it
        let r2 = inv.invert_from(&q, [(u + 0.5) % 1.0 * 0.2 + u * 0.8, v], &mut ws);
        assert!(r2.distance < 1e-10, "{:?}", r2);
    }
}

#[test]
fn coons_grid_iteration_is_within_its_tolerance() {
    let s = known();
    let mut st = Lcg::new(3);
    let (mut wu, mut wv) = (BasisWorkspace::new(3, 1), BasisWorkspace::new(3, 1));
    let mut pts = Vec::new();
    let mut truth = Vec::new();
    for _ in 0..300 {
        let t = [0.05 + 0.9 * rnd(&mut st), 0.05 + 0.9 * rnd(&mut st)];
        let n = s.normal(t[0], t[1], &mut wu, &mut wv);
        pts.push(s.point(t[0], t[1]) + n * 0.05);
        truth.push(t);
    }
    let cfg = GridIterationConfig {
        h: 0.002,
        ..Default::default()
    };
    let res = grid_iteration(&s, &pts, &cfg).unwrap();
    let mut max_err: f64 = 0.0;
    for (r, t) in res.iter().zip(&truth) {
        assert!(r.converged);
        max_err = max_err.max((s.point(r.uv[0], r.uv[1]) - s.point(t[0], t[1])).norm());
        // distance within epsilon of the true 0.05
        assert!((r.distance - 0.05).abs() < cfg.epsilon, "{}", r.distance);
    }
    // the foot point is found to about epsilon (the paper's claim), not to rounding
    assert!(max_err < 2.0 * cfg.epsilon, "{max_err}");
}

#[test]
fn coons_grid_iteration_converges_on_a_skewed_patch() {
    // a flat parallelogram whose tangents meet at 60 degrees: eq. 19 as
    // printed (divided by |Q_u| |Q_w|) has length sin 60 and would never
    // reach |Q' - Q| <= epsilon at distance 0.1; the unit normal does
    let k = KnotVector::new(vec![0.0, 0.0, 1.0, 1.0], 1).unwrap();
    let (a, b) = (
        nalgebra::Vector3::new(1.0, 0.0, 0.0),
        nalgebra::Vector3::new(0.5, 3f64.sqrt() / 2.0, 0.0),
    );
    let o = Point3::origin();
    let s = Surface::new(k.clone(), k, vec![o, o + b, o + a, o + a + b]).unwrap();
    let truth = [[0.3, 0.4], [0.6, 0.5], [0.45, 0.7]];
    let pts: Vec<Point3> = truth
        .iter()
        .map(|t| s.point(t[0], t[1]) + nalgebra::Vector3::new(0.0, 0.0, 0.1))
        .collect();
    let res = grid_iteration(&s, &pts, &GridIterationConfig::default()).unwrap();
    for (r, t) in res.iter().zip(&truth) {
        assert!(r.converged, "{r:?}");
        assert!(
            (r.uv[0] - t[0]).abs() < 0.01 && (r.uv[1] - t[1]).abs() < 0.01,
            "{r:?} vs {t:?}"
        );
        assert!((r.distance - 0.1).abs() < 1e-3, "{}", r.distance);
    }
    // a grid step that would build more than 10^7 vertices is refused
    let tiny = GridIterationConfig {
        h: 1e-6,
        ..Default::default()
    };
    assert!(grid_iteration(&s, &pts, &tiny).is_err());
}
