#![allow(clippy::unwrap_used, clippy::expect_used)]
//! The PDE paper's checks (`pde-coons-surface-reconstruction`, §5.1, §5.3,
//! §5.4, eq. 15) on points sampled from a bicubic Bezier surface, and the
//! Coons paper's pipeline (Coons parameters -> least-squares B-spline surface).
//!
//! The paper does not print its Bezier surface; ours has control points on
//! the 4 x 4 grid `(i, j)`, `i, j = 0..3`, with the heights of `BEZIER_Z`,
//! which bulge the interior well away from what the boundaries imply (so the
//! Coons patch alone is off by 0.2519 on average, as the paper's 0.4343).

use scanfit::base::{
    coons_from_cloud, coons_parameters, CoonsFromCloudConfig, CoonsParamConfig, CoonsPatch,
    CoonsProjection,
};
use scanfit::bspline::{Curve, KnotVector, Surface};
use scanfit::fit::surface::{fit_surface, SurfaceFitConfig};
use scanfit::metrics::{orthogonal_errors, parametric_distances, ErrorStats};
use scanfit::pde::{fit_pde, BsplineConversionConfig, PdeConfig};
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit::{Point3, Vector3};

const BEZIER_Z: [[f64; 4]; 4] = [
    [0.0, 0.5, 0.4, 0.0],
    [0.5, 2.0, 1.0, 0.3],
    [0.3, 1.5, 2.5, 0.2],
    [0.0, 0.4, 0.2, 0.0],
];

fn bezier() -> Surface {
    let k = KnotVector::uniform_clamped(3, 4).unwrap();
    let ctrl = (0..4)
        .flat_map(|i| (0..4).map(move |j| Point3::new(i as f64, j as f64, BEZIER_Z[i][j])))
        .collect();
    Surface::new(k.clone(), k, ctrl).unwrap()
}

/// The Coons patch of the Bezier surface's exact boundary curves.
fn exact_coons(s: &Surface) -> CoonsPatch {
    let k = KnotVector::uniform_clamped(3, 4).unwrap();
    let row = |f: &dyn Fn(usize) -> Point3| {
        Curve::new(k.clone(), (0..4).map(f).collect::<Vec<_>>()).unwrap()
    };
    let bottom = row(&|i| s.control_point(i, 0));
    let top = row(&|i| s.control_point(i, 3));
    let left = row(&|j| s.control_point(0, j));
    let right = row(&|j| s.control_point(3, j));
    CoonsPatch::new(&bottom, &top, &left, &right).unwrap()
}

/// Structured points: `n x n` samples at `u, v = (k + offset) / (n - 1 + 2 offset)`.
fn structured(s: &Surface, n: usize, offset: f64) -> (Vec<Point3>, Vec<[f64; 2]>) {
    let mut pts = Vec::new();
    let mut uv = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let den = (n - 1) as f64 + 2.0 * offset;
            let (u, v) = ((i as f64 + offset) / den, (j as f64 + offset) / den);
            pts.push(s.point(u, v));
            uv.push([u, v]);
        }
    }
    (pts, uv)
}

#[test]
fn pde_deformation_reduces_the_coons_error_section_5_1() {
    let s = bezier();
    let coons = exact_coons(&s);
    let (pts, uv) = structured(&s, 50, 0.0);
    let f5 = fit_pde(&coons, &pts, &uv, &PdeConfig::default()).unwrap();
    let f10 = fit_pde(
        &coons,
        &pts,
        &uv,
        &PdeConfig {
            m: 10,
            n: 10,
            d: 1.0,
        },
    )
    .unwrap();
    println!(
        "6a: Coons mean {:.4} max {:.4}; PDE 5x5 mean {:.6} max {:.6} (x{:.0}); PDE 10x10 mean {:.2e} max {:.2e} (x{:.0})",
        f5.coons_errors.mean,
        f5.coons_errors.max,
        f5.errors.mean,
        f5.errors.max,
        f5.coons_errors.mean / f5.errors.mean,
        f10.errors.mean,
        f10.errors.max,
        f5.coons_errors.mean / f10.errors.mean
    );
    assert!(
        (f5.coons_errors.mean - 0.2519).abs() < 1e-4,
        "{:?}",
        f5.coons_errors
    );
    assert!(f5.coons_errors.mean / f5.errors.mean >= 50.0);
    assert!(f10.errors.mean < 0.2 * f5.errors.mean);
    assert!(f10.errors.max < f5.errors.max);
    // the boundary of S is the boundary of the Bezier surface
    for k in 0..=10 {
        let t = k as f64 / 10.0;
        for (u, v) in [(t, 0.0), (t, 1.0), (0.0, t), (1.0, t)] {
            assert!((f5.surface.point(u, v) - s.point(u, v)).norm() < 1e-13);
        }
    }
}

#[test]
fn mn_equal_to_the_point_count_interpolates() {
    let s = bezier();
    let coons = exact_coons(&s);
    for n in [5, 6, 8] {
        let (pts, uv) = structured(&s, n, 0.5);
        let f = fit_pde(&coons, &pts, &uv, &PdeConfig { m: n, n, d: 1.0 }).unwrap();
        println!(
            "6b: {} points, M = N = {n}: max error {:.2e}",
            pts.len(),
            f.errors.max
        );
        assert!(f.errors.max < 1e-13, "{n}: {:?}", f.errors);
        assert!(f.coons_errors.mean > 0.1);
    }
}

#[test]
fn the_rigidity_d_does_not_change_the_surface() {
    let s = bezier();
    let coons = exact_coons(&s);
    let (pts, uv) = structured(&s, 30, 0.0);
    let fits: Vec<_> = [1e-3, 1.0, 1e3, 0.37]
        .iter()
        .map(|&d| fit_pde(&coons, &pts, &uv, &PdeConfig { m: 5, n: 5, d }).unwrap())
        .collect();
    for f in &fits[1..] {
        assert!((f.errors.mean - fits[0].errors.mean).abs() < 1e-15);
        assert!((f.errors.max - fits[0].errors.max).abs() < 1e-15);
        for (a, b) in [(0.3, 0.4), (0.77, 0.12)] {
            assert!((f.surface.point(a, b) - fits[0].surface.point(a, b)).norm() < 1e-14);
        }
        let d = f.surface.deformation.rigidity();
        let d0 = fits[0].surface.deformation.rigidity();
        for (m, n) in [(1, 1), (3, 2), (5, 5)] {
            let q = f.surface.deformation.q_coefficient(m, n).unwrap() / d;
            let q0 = fits[0].surface.deformation.q_coefficient(m, n).unwrap() / d0;
            assert!(
                (q - q0).norm() <= 1e-12 * q0.norm(),
                "q/D differs at {m},{n}"
            );
        }
    }
    println!(
        "6c: D in 1e-3, 1, 1e3, 0.37: mean error {:.6} max {:.6} each",
        fits[0].errors.mean, fits[0].errors.max
    );
}

/// xorshift64* and Box-Muller: reproducible noise without a dependency.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }
    fn direction(&mut self) -> Vector3 {
        loop {
            let v = Vector3::new(self.normal(), self.normal(), self.normal());
            if v.norm() > 1e-9 {
                return v.normalize();
            }
        }
    }
}

/// Mean and max orthogonal distance of `clean` to `surface`.
fn distance_to(surface: &Surface, clean: &[Point3]) -> ErrorStats {
    let inv = SurfaceInverter::new(surface, InversionConfig::default()).unwrap();
    orthogonal_errors(&inv, clean).0
}

#[test]
fn noisy_data_section_5_4() {
    let s = bezier();
    let (clean, _) = structured(&s, 60, 0.0);
    let (lo, hi) = clean.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
    );
    let d = (hi - lo).norm();
    println!("6d: bounding-box diagonal d = {d:.4}; noise sigma = (l d)%; M = N = 10; errors of the noise-free points");
    println!("| l (%) | sigma | points outside | Coons mean | Coons max | PDE mean | PDE max |");
    println!("|---|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    for (k, l) in [0.0, 0.5, 1.0, 1.5].into_iter().enumerate() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15 + k as u64);
        let sigma = l * d / 100.0;
        let noisy: Vec<Point3> = clean
            .iter()
            .map(|p| p + rng.direction() * (rng.normal() * sigma))
            .collect();
        let base = coons_from_cloud(&noisy, &CoonsFromCloudConfig::default()).unwrap();
        let coons_b = base.patch.to_bspline().unwrap();
        let par = coons_parameters(
            &coons_b,
            &noisy,
            &CoonsParamConfig {
                projection: CoonsProjection::Inversion(InversionConfig::default()),
                outside_tolerance: None,
            },
        )
        .unwrap();
        let fit = fit_pde(
            &base.patch,
            &noisy,
            &par.uv,
            &PdeConfig {
                m: 10,
                n: 10,
                d: 1.0,
            },
        )
        .unwrap();
        let b = fit
            .surface
            .to_bspline(&BsplineConversionConfig::new(1e-5 * d))
            .unwrap();
        let (ec, ep) = (
            distance_to(&coons_b, &clean),
            distance_to(&b.surface, &clean),
        );
        println!(
            "| {l} | {sigma:.4} | {} | {:.4} | {:.4} | {:.4} | {:.4} |",
            par.outside_count, ec.mean, ec.max, ep.mean, ep.max
        );
        rows.push((ec, ep));
    }
    // the deformation always improves on the Coons patch (the paper's Fig. 16)
    for (ec, ep) in &rows {
        assert!(ep.mean < 0.5 * ec.mean);
    }
    // noise-free: close to exact; then the error grows with the noise
    assert!(rows[0].1.mean < 1e-3, "{:?}", rows[0].1);
    assert!(rows[1].1.mean < 5e-3, "{:?}", rows[1].1);
    for k in 1..rows.len() {
        assert!(rows[k - 1].1.mean < rows[k].1.mean);
    }
}

#[test]
fn coons_paper_route_least_squares_surface_on_coons_parameters() {
    let s = bezier();
    let (pts, _) = structured(&s, 40, 0.0);
    let base = coons_from_cloud(&pts, &CoonsFromCloudConfig::default()).unwrap();
    let b = base.patch.to_bspline().unwrap();
    let par = coons_parameters(&b, &pts, &CoonsParamConfig::default()).unwrap();
    assert_eq!(par.unconverged, 0);
    let fit = fit_surface(
        &pts,
        &par.uv,
        &SurfaceFitConfig {
            ctrl: (12, 12),
            ..Default::default()
        },
    )
    .unwrap();
    let e = ErrorStats::of(&parametric_distances(&fit, &pts, &par.uv));
    let o = distance_to(&fit, &pts);
    println!(
        "Coons paper route: {} outside, eq. 15 mean {:.2e} max {:.2e}; orthogonal mean {:.2e} max {:.2e}",
        par.outside_count, e.mean, e.max, o.mean, o.max
    );
    assert!(e.max < 0.01 && o.max < 0.01, "{e:?} {o:?}");
}
