#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Point-cloud geometry benchmarks (criterion):
//!
//! * convex hull of 10^5 points on a sphere (all are vertices) and in a ball
//! * hidden point removal of 10^5 points on a sphere
//! * boundary loops + corners of a noisy 10^5-point rectangular patch
//! * boundary loops of a noisy 10^6-point patch: the boundary band and
//!   sampled spacing (the default above 200,000 points) and the
//!   triangulation of every point
//!
//! Run: `cargo bench -p scanfit --bench cloud -- --sample-size 10`

#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use scanfit::cloud::boundary::{boundary_loops, BoundaryConfig};
use scanfit::cloud::corners::{find_corners, CornerConfig};
use scanfit::cloud::hpr::{hidden_point_removal, HprConfig};
use scanfit::cloud::hull::convex_hull;
use scanfit::Point3;

/// SplitMix64 uniform numbers in [0, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn unit(&mut self) -> [f64; 3] {
        loop {
            let v = [
                2.0 * self.uniform() - 1.0,
                2.0 * self.uniform() - 1.0,
                2.0 * self.uniform() - 1.0,
            ];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.1 && n <= 1.0 {
                return [v[0] / n, v[1] / n, v[2] / n];
            }
        }
    }
}

fn sphere(n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let u = rng.unit();
            Point3::new(u[0], u[1], u[2])
        })
        .collect()
}

fn ball(n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let u = rng.unit();
            let r = rng.uniform().cbrt();
            Point3::new(r * u[0], r * u[1], r * u[2])
        })
        .collect()
}

/// Random points of a 4 x 2 patch z = 0.3 sin(x) cos(y) with 0.1% noise.
fn patch(n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let (x, y) = (4.0 * rng.uniform(), 2.0 * rng.uniform());
            let z = 0.3 * x.sin() * y.cos() + 0.004 * (rng.uniform() - 0.5);
            Point3::new(x, y, z)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let s = sphere(100_000, 1);
    let b = ball(100_000, 2);
    let big = ball(1_000_000, 3);
    let p = patch(100_000, 4);
    let eye = Point3::new(0.0, 0.0, 3.0);

    c.bench_function("hull: 1e5 points on a sphere", |bch| {
        bch.iter(|| convex_hull(black_box(&s)).unwrap())
    });
    c.bench_function("hull: 1e5 points in a ball", |bch| {
        bch.iter(|| convex_hull(black_box(&b)).unwrap())
    });
    c.bench_function("hull: 1e6 points in a ball", |bch| {
        bch.iter(|| convex_hull(black_box(&big)).unwrap())
    });
    c.bench_function("hpr: 1e5 points on a sphere", |bch| {
        bch.iter(|| hidden_point_removal(black_box(&s), &eye, &HprConfig::default()).unwrap())
    });
    c.bench_function("boundary: 1e5-point noisy patch", |bch| {
        bch.iter(|| boundary_loops(black_box(&p), &BoundaryConfig::default()).unwrap())
    });
    let million = patch(1_000_000, 5);
    c.bench_function("boundary: 1e6-point noisy patch (band)", |bch| {
        bch.iter(|| boundary_loops(black_box(&million), &BoundaryConfig::default()).unwrap())
    });
    let every = BoundaryConfig {
        sample_above: usize::MAX,
        ..Default::default()
    };
    c.bench_function("boundary: 1e6-point noisy patch (every point)", |bch| {
        bch.iter(|| boundary_loops(black_box(&million), &every).unwrap())
    });
    let bd = boundary_loops(&p, &BoundaryConfig::default()).unwrap();
    let lp: Vec<Point3> = bd.outer_loop().iter().map(|&i| p[i]).collect();
    assert_eq!(bd.loops.len(), 1);
    let corners = find_corners(&lp, &CornerConfig::default()).unwrap();
    for k in corners.corners {
        let q = lp[k];
        let near = [(0.0, 0.0), (4.0, 0.0), (4.0, 2.0), (0.0, 2.0)]
            .iter()
            .any(|&(x, y)| (q.x - x).hypot(q.y - y) < 0.05);
        assert!(near, "corner at {q} is not a patch corner");
    }
    c.bench_function("corners: outer loop of the 1e5-point patch", |bch| {
        bch.iter(|| find_corners(black_box(&lp), &CornerConfig::default()).unwrap())
    });
    c.bench_function("boundary + corners: 1e5-point noisy patch", |bch| {
        bch.iter(|| {
            let bd = boundary_loops(black_box(&p), &BoundaryConfig::default()).unwrap();
            let lp: Vec<Point3> = bd.outer_loop().iter().map(|&i| p[i]).collect();
            find_corners(&lp, &CornerConfig::default()).unwrap()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
