//! Curve benchmarks (criterion): the targets of the foundation issue.
//!
//! * cubic curve evaluation throughput (target >= 50 M points/s per core)
//! * interpolation of 10^5 points
//! * least squares of 10^6 points onto 1000 control points (target < 150 ms)
//!
//! Run: `cargo bench -p scanfit --bench curves`

#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use scanfit::bspline::{Curve, KnotVector};
use scanfit::fit::{
    self, least_squares_with, ApproximationConfig, InterpolationConfig, LeastSquaresOptions,
};
use scanfit::param::{knots, Method};
use scanfit::Point3;

/// Points on a wavy 3D spiral, ordered along the curve, with a deterministic wobble.
fn spiral(n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64 * 20.0;
            let wobble = ((i * 7919) % 1000) as f64 * 1e-6;
            Point3::new(
                t.cos() * (1.0 + 0.1 * t),
                t.sin() * (1.0 + 0.1 * t),
                0.3 * t + wobble,
            )
        })
        .collect()
}

fn evaluation(c: &mut Criterion) {
    let ctrl = spiral(200);
    let curve = Curve::new(KnotVector::uniform_clamped(3, ctrl.len()).unwrap(), ctrl).unwrap();
    let n = 1_000_000;
    let us: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
    let mut out = vec![Point3::origin(); n];
    let mut g = c.benchmark_group("cubic_eval");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("eval_many_sorted_1e6", |b| {
        b.iter(|| curve.eval_many(black_box(&us), &mut out))
    });
    // random order: no span reuse, a binary search per point
    let mut shuffled = us.clone();
    let mut state = 0x9e3779b97f4a7c15u64;
    for i in (1..n).rev() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        shuffled.swap(i, (state % (i as u64 + 1)) as usize);
    }
    g.bench_function("eval_many_random_1e6", |b| {
        b.iter(|| curve.eval_many(black_box(&shuffled), &mut out))
    });
    g.finish();
}

fn interpolation(c: &mut Criterion) {
    let mut g = c.benchmark_group("interpolate");
    g.sample_size(10);
    let pts = spiral(100_000);
    for method in [Method::Centripetal, Method::Proposed(0.8)] {
        let cfg = InterpolationConfig {
            method,
            ..Default::default()
        };
        g.bench_with_input(
            BenchmarkId::new("cubic_1e5", method.to_string()),
            &pts,
            |b, pts| b.iter(|| fit::interpolate(black_box(pts), &cfg).unwrap()),
        );
    }
    g.finish();
}

fn least_squares(c: &mut Criterion) {
    let mut g = c.benchmark_group("least_squares");
    g.sample_size(10);
    let pts = spiral(1_000_000);
    let params: Vec<f64> = (0..pts.len())
        .map(|i| i as f64 / (pts.len() - 1) as f64)
        .collect();
    let kv = knots::least_squares(&params, 3, 1000).unwrap();
    g.bench_function("solve_1e6_points_1000_ctrl", |b| {
        b.iter(|| {
            least_squares_with(
                black_box(&pts),
                &params,
                kv.clone(),
                LeastSquaresOptions {
                    fix_ends: true,
                    ..Default::default()
                },
            )
            .unwrap()
        })
    });
    let cfg = ApproximationConfig {
        ctrl_count: 1000,
        method: Method::Centripetal,
        ..Default::default()
    };
    g.bench_function("approximate_1e6_points_1000_ctrl_centripetal", |b| {
        b.iter(|| fit::approximate(black_box(&pts), &cfg).unwrap())
    });
    g.finish();
}

criterion_group!(benches, evaluation, interpolation, least_squares);
criterion_main!(benches);
