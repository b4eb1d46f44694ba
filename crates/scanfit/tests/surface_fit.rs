//! Least-squares surface fitting: golden values from scipy's LSQBivariateSpline
//! (`python3 crates/scanfit/tests/data/golden/make_surface_golden.py`), exact
//! refits of known surfaces, periodic fits, smoothing, and bad input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use scanfit::bspline::{KnotVector, Surface};
use scanfit::fit::surface::{
    fit_surface, least_squares_surface_with, KnotPlacement, SurfaceFitConfig, SurfaceLsqOptions,
};
use scanfit::Point3;
use serde_json::Value;

fn load(name: &str) -> Value {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/golden")
        .join(name);
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}
fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}
fn pts(v: &Value) -> Vec<Point3> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let c = floats(p);
            Point3::new(c[0], c[1], c[2])
        })
        .collect()
}
fn uvs(v: &Value) -> Vec<[f64; 2]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let c = floats(p);
            [c[0], c[1]]
        })
        .collect()
}

#[test]
fn matches_scipy_lsq_bivariate_spline() {
    for file in ["surface_lsq_scattered.json", "surface_lsq_degree_2x3.json"] {
        let g = load(file);
        let (p, q) = (
            g["degree_u"].as_u64().unwrap() as usize,
            g["degree_v"].as_u64().unwrap() as usize,
        );
        let ku = KnotVector::new(floats(&g["knots_u"]), p).unwrap();
        let kv = KnotVector::new(floats(&g["knots_v"]), q).unwrap();
        let s = least_squares_surface_with(
            &pts(&g["points"]),
            &uvs(&g["params"]),
            ku,
            kv,
            SurfaceLsqOptions::default(),
        )
        .unwrap();
        let want = pts(&g["coefficients"]);
        assert_eq!(s.control_points().len(), want.len());
        for (k, (a, b)) in s.control_points().iter().zip(&want).enumerate() {
            assert!((a - b).norm() < 1e-9, "{file}: coefficient {k}: {a} vs {b}");
        }
        let su = uvs(&g["samples"]["uv"]);
        for (t, w) in su.iter().zip(pts(&g["samples"]["values"])) {
            assert!((s.point(t[0], t[1]) - w).norm() < 1e-9, "{file}");
        }
    }
}

/// A known bicubic surface with irregular knots.
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
                (0.9 * x).sin() * (0.7 * y).cos() + 0.1 * x * y,
            ));
        }
    }
    Surface::new(ku, kv, c).unwrap()
}

fn sample(s: &Surface, n: usize, seed: u64) -> (Vec<Point3>, Vec<[f64; 2]>) {
    let mut rng = scanfit::testdata::Lcg::new(seed);
    let mut rnd = || rng.next_f64();
    let uv: Vec<[f64; 2]> = (0..n).map(|_| [rnd(), rnd()]).collect();
    (uv.iter().map(|t| s.point(t[0], t[1])).collect(), uv)
}

#[test]
fn refits_a_known_surface_exactly() {
    let s = known();
    let (p, uv) = sample(&s, 3000, 1);
    let opts = SurfaceLsqOptions::default();
    let fit = least_squares_surface_with(&p, &uv, s.knots_u().clone(), s.knots_v().clone(), opts)
        .unwrap();
    for (a, b) in fit.control_points().iter().zip(s.control_points()) {
        assert!((a - b).norm() < 1e-9, "{a} vs {b}");
    }
    // weights do not change an exact fit
    let w: Vec<f64> = (0..p.len()).map(|k| 0.5 + (k % 7) as f64).collect();
    let opts = SurfaceLsqOptions {
        weights: Some(&w),
        ..Default::default()
    };
    let fit = least_squares_surface_with(&p, &uv, s.knots_u().clone(), s.knots_v().clone(), opts)
        .unwrap();
    for (a, b) in fit.control_points().iter().zip(s.control_points()) {
        assert!((a - b).norm() < 1e-9);
    }
}

#[test]
fn smoothing_keeps_planes_and_fills_empty_regions() {
    // data only on the left half: without smoothing it is an error naming the
    // empty region, with smoothing the fit is well posed and reproduces a plane
    let plane = |u: f64, v: f64| Point3::new(u * 3.0, v * 2.0, 0.5 * u - v + 1.0);
    let uv: Vec<[f64; 2]> = (0..2000)
        .map(|k| {
            [
                ((k * 7919) % 1000) as f64 / 2000.0,
                ((k * 104729) % 1000) as f64 / 999.0,
            ]
        })
        .collect();
    let p: Vec<Point3> = uv.iter().map(|t| plane(t[0], t[1])).collect();
    let cfg = SurfaceFitConfig {
        ctrl: (10, 8),
        knots: KnotPlacement::Uniform,
        ..Default::default()
    };
    let e = fit_surface(&p, &uv, &cfg).unwrap_err().to_string();
    assert!(
        e.contains("no data point influences control point") && e.contains("u in [0.5"),
        "{e}"
    );
    let cfg = SurfaceFitConfig {
        smoothing: 1e-3,
        ..cfg
    };
    let s = fit_surface(&p, &uv, &cfg).unwrap();
    // the thin-plate energy of a plane is zero: it is reproduced everywhere,
    // also where there are no data
    for &(u, v) in &[(0.1, 0.1), (0.9, 0.9), (0.75, 0.2)] {
        assert!((s.point(u, v) - plane(u, v)).norm() < 1e-8, "({u},{v})");
    }
}

#[test]
fn periodic_in_u_closes_smoothly() {
    // a cylinder: u around, v along
    let f = |u: f64, v: f64| {
        let a = u * std::f64::consts::TAU;
        Point3::new(
            2.0 * a.cos(),
            2.0 * a.sin(),
            3.0 * v + 0.1 * (2.0 * a).sin(),
        )
    };
    let uv: Vec<[f64; 2]> = (0..4000)
        .map(|k| {
            [
                ((k * 7919) % 4000) as f64 / 4000.0,
                ((k * 104729) % 997) as f64 / 996.0,
            ]
        })
        .collect();
    let p: Vec<Point3> = uv.iter().map(|t| f(t[0], t[1])).collect();
    let cfg = SurfaceFitConfig {
        ctrl: (16, 6),
        periodic_u: true,
        ..Default::default()
    };
    let s = fit_surface(&p, &uv, &cfg).unwrap();
    assert!(s.periodic().0);
    for &v in &[0.0, 0.3, 1.0] {
        assert!((s.point(0.0, v) - s.point(1.0 - 1e-14, v)).norm() < 1e-9);
    }
    let err = p
        .iter()
        .zip(&uv)
        .map(|(q, t)| (s.point(t[0], t[1]) - q).norm())
        .fold(0.0, f64::max);
    assert!(err < 2e-3, "max error {err}");
}

#[test]
fn bad_input_is_reported() {
    let s = known();
    let (p, mut uv) = sample(&s, 100, 3);
    let cfg = SurfaceFitConfig {
        ctrl: (12, 12),
        ..Default::default()
    };
    let e = fit_surface(&p, &uv, &cfg).unwrap_err().to_string();
    assert!(
        e.contains("100 points given") && e.contains("144 control points"),
        "{e}"
    );
    let cfg = SurfaceFitConfig {
        ctrl: (5, 5),
        ..Default::default()
    };
    let same_u: Vec<[f64; 2]> = uv.iter().map(|t| [0.5, t[1]]).collect();
    let e = fit_surface(&p, &same_u, &cfg).unwrap_err().to_string();
    assert!(e.contains("only 1 distinct u parameters"), "{e}");
    uv[7] = [1.5, 0.2];
    let e = fit_surface(&p, &uv, &cfg).unwrap_err().to_string();
    assert!(
        e.contains("point 7 has parameters (1.5, 0.2) outside"),
        "{e}"
    );
    uv[7] = [f64::NAN, 0.2];
    assert!(fit_surface(&p, &uv, &cfg).is_err());
    let mut bad = p.clone();
    bad[3].z = f64::NAN;
    let (_, uv) = sample(&s, 100, 3);
    let e = fit_surface(&bad, &uv, &cfg).unwrap_err().to_string();
    assert!(e.contains("point 3"), "{e}");
}

#[test]
fn grid_interpolation_matches_the_nurbs_book_algorithm() {
    use scanfit::fit::grid::{fit_grid, GridFitConfig};
    let g = load("surface_grid_interp.json");
    let grid: Vec<Point3> = g["grid"].as_array().unwrap().iter().flat_map(pts).collect();
    let (rows, cols) = (
        g["grid"].as_array().unwrap().len(),
        g["grid"][0].as_array().unwrap().len(),
    );
    let fit = fit_grid(&grid, rows, cols, &GridFitConfig::default()).unwrap();
    for (a, b) in fit.params_u.iter().zip(floats(&g["params_u"])) {
        assert!((a - b).abs() < 1e-15);
    }
    for (a, b) in fit.params_v.iter().zip(floats(&g["params_v"])) {
        assert!((a - b).abs() < 1e-15);
    }
    let want = pts(&g["coefficients"]);
    for (k, (a, b)) in fit.surface.control_points().iter().zip(&want).enumerate() {
        assert!((a - b).norm() < 1e-9, "coefficient {k}: {a} vs {b}");
    }
    for k in 0..rows {
        for l in 0..cols {
            let s = fit.surface.point(fit.params_u[k], fit.params_v[l]);
            assert!((s - grid[k * cols + l]).norm() < 1e-9);
        }
    }
}

#[test]
fn periodic_grid_interpolation_and_approximation() {
    use scanfit::fit::grid::{fit_grid, GridFitConfig};
    // 12 layers x 9 samples around a wobbly cylinder: closed in u
    let (rows, cols) = (9, 12);
    let mut grid = Vec::new();
    for k in 0..rows {
        let a = k as f64 / rows as f64 * std::f64::consts::TAU;
        for l in 0..cols {
            let r = 2.0 + 0.3 * (3.0 * a).sin() + 0.1 * l as f64;
            grid.push(Point3::new(r * a.cos(), r * a.sin(), l as f64 * 0.5));
        }
    }
    let cfg = GridFitConfig {
        periodic_u: true,
        ..Default::default()
    };
    let fit = fit_grid(&grid, rows, cols, &cfg).unwrap();
    assert!(fit.surface.periodic().0);
    for k in 0..rows {
        for l in 0..cols {
            let s = fit.surface.point(fit.params_u[k], fit.params_v[l]);
            assert!((s - grid[k * cols + l]).norm() < 1e-9, "({k},{l})");
        }
    }
    // seam: smooth and closed
    for &v in &[0.0, 0.5, 1.0] {
        assert!((fit.surface.point(0.0, v) - fit.surface.point(1.0 - 1e-15, v)).norm() < 1e-9);
    }
    // least squares on the same grid: fewer control points, still close
    let cfg = GridFitConfig {
        periodic_u: true,
        ctrl: Some((7, 6)),
        ..Default::default()
    };
    let fit = fit_grid(&grid, rows, cols, &cfg).unwrap();
    assert_eq!(fit.surface.counts(), (7 + 3, 6));
    let err = (0..rows * cols)
        .map(|i| {
            (fit.surface
                .point(fit.params_u[i / cols], fit.params_v[i % cols])
                - grid[i])
                .norm()
        })
        .fold(0.0, f64::max);
    assert!(err < 0.2, "{err}");
    // wrong sizes are errors
    assert!(fit_grid(&grid, 10, 12, &GridFitConfig::default()).is_err());
}

#[test]
fn parameter_correction_reduces_the_error_every_round() {
    use scanfit::base::plane_parameters;
    use scanfit::fit::correction::{correct_parameters, CorrectionConfig};
    // a dome: plane parameters distort towards the rim, correction fixes it
    let mut pts = Vec::new();
    for i in 0..60 {
        for j in 0..60 {
            let (x, y) = (i as f64 / 59.0 * 2.0 - 1.0, j as f64 / 59.0 * 2.0 - 1.0);
            // a steep spherical cap: not representable by 8 x 8 bicubics, and
            // its plane parameters are far from orthogonal near the rim
            pts.push(Point3::new(x, y, (2.1 - x * x - y * y).sqrt()));
        }
    }
    let mut uv = plane_parameters(&pts).unwrap().uv;
    let cfg = SurfaceFitConfig {
        ctrl: (8, 8),
        ..Default::default()
    };
    let (s, rounds) = correct_parameters(
        &pts,
        &mut uv,
        |t| fit_surface(&pts, t, &cfg),
        &CorrectionConfig {
            max_rounds: 6,
            min_improvement: 1e-3,
        },
    )
    .unwrap();
    assert!(rounds.len() >= 3, "{rounds:?}");
    for w in rounds.windows(2).take(rounds.len() - 2) {
        assert!(w[1].errors.rmse < w[0].errors.rmse, "{rounds:?}");
    }
    let first = rounds[0].errors.rmse;
    let best = rounds
        .iter()
        .map(|r| r.errors.rmse)
        .fold(f64::INFINITY, f64::min);
    assert!(best < 0.7 * first, "{first} -> {best}");
    // the returned surface and parameters are the best round's
    let e =
        scanfit::metrics::ErrorStats::of(&scanfit::metrics::parametric_distances(&s, &pts, &uv));
    assert!((e.rmse - best).abs() < 1e-12);
}
