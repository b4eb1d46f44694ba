//! MBA benchmarks: multilevel B-spline approximation of 10^6 scattered
//! points (8 levels on a 1 x 1 base lattice: 131 x 131 control points) and the projection
//! adjustment of the 35 x 35 terrain surface (50 000 points).
//! Run: `cargo bench -p scanfit --bench mba -- --sample-size 10`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use scanfit::cloud::PointCloud;
use scanfit::mba::adjust::{adjust_lattice, AdjustConfig};
use scanfit::mba::{mba, MbaConfig};
use scanfit::Point3;

fn scattered(n: usize) -> Vec<Point3> {
    let mut rng = scanfit::testdata::Lcg::new(11);
    let mut rnd = || rng.next_f64();
    (0..n)
        .map(|_| {
            let (x, y) = (rnd() * 1000.0, rnd() * 800.0);
            Point3::new(
                x,
                y,
                40.0 * (x * 0.01).sin() * (y * 0.013).cos() + 5.0 * (x * 0.05 + y * 0.03).sin(),
            )
        })
        .collect()
}

fn terrain() -> Vec<Point3> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/data/terrain_50k.xyz"
    );
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            Point3::new(v[0], v[1], v[2])
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("mba");
    g.sample_size(10);
    let p = scattered(1_000_000);
    let cfg = MbaConfig {
        max_levels: 8,
        ..Default::default()
    };
    g.bench_function("mba_1e6_points_8_levels", |b| {
        b.iter(|| mba(&p, &cfg).unwrap())
    });
    let t = terrain();
    let cloud = PointCloud::new(t.clone()).unwrap();
    cloud.tree().unwrap();
    let r = mba(
        &t,
        &MbaConfig {
            max_levels: 6,
            ..Default::default()
        },
    )
    .unwrap();
    g.bench_function("adjust_35x35_terrain_50k", |b| {
        b.iter(|| {
            let mut l = r.lattice.clone();
            adjust_lattice(&cloud, &r.frame, &mut l, &AdjustConfig::default()).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
