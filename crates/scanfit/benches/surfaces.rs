//! Surface benchmarks (criterion): the targets of the surface-fitting issue.
//!
//! * least squares of 10^6 scattered points onto a 64 x 64 bicubic (< 0.5 s wall)
//! * inversion of 10^6 points onto a 64 x 64 bicubic (< 1 s wall)
//!
//! Run: `cargo bench -p scanfit --bench surfaces`

#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use scanfit::bspline::{KnotVector, Surface};
use scanfit::fit::surface::{least_squares_surface_with, SurfaceLsqOptions};
use scanfit::project::{InversionConfig, SurfaceInverter};
use scanfit::Point3;

/// 10^6 points of a smooth bumpy sheet with small deterministic noise, and their parameters.
pub fn data(n: usize) -> (Vec<Point3>, Vec<[f64; 2]>) {
    let mut rng = scanfit::testdata::Lcg::new(42);
    let mut rnd = || rng.next_f64();
    let uv: Vec<[f64; 2]> = (0..n).map(|_| [rnd(), rnd()]).collect();
    let pts = uv
        .iter()
        .map(|t| {
            Point3::new(
                100.0 * t[0],
                100.0 * t[1],
                10.0 * (3.0 * t[0]).sin() * (4.0 * t[1]).cos() + 0.01 * (rnd() - 0.5),
            )
        })
        .collect();
    (pts, uv)
}

fn surfaces(c: &mut Criterion) {
    let (pts, uv) = data(1_000_000);
    let ku = KnotVector::uniform_clamped(3, 64).unwrap();
    let kv = KnotVector::uniform_clamped(3, 64).unwrap();
    let mut g = c.benchmark_group("surface");
    g.sample_size(10);
    g.bench_function("lsq_1e6_points_64x64_bicubic", |b| {
        b.iter(|| {
            least_squares_surface_with(
                black_box(&pts),
                &uv,
                ku.clone(),
                kv.clone(),
                SurfaceLsqOptions::default(),
            )
            .unwrap()
        })
    });
    let s: Surface = least_squares_surface_with(
        &pts,
        &uv,
        ku.clone(),
        kv.clone(),
        SurfaceLsqOptions::default(),
    )
    .unwrap();
    // points off the surface: the data themselves (noise 0.01)
    g.bench_function("inversion_1e6_points_64x64_bicubic", |b| {
        b.iter(|| {
            let inv = SurfaceInverter::new(&s, InversionConfig::default()).unwrap();
            inv.invert_all(black_box(&pts))
        })
    });
    g.finish();
}

criterion_group!(benches, surfaces);
criterion_main!(benches);
