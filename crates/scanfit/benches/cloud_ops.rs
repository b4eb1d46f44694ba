#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]
//! Point-cloud benchmarks of issue 3: KD-tree build and 16-NN over 10^6
//! points, normals for 10^6 points, directed projection of 10^4 points onto
//! 10^6. Run: `cargo bench -p scanfit --bench cloud_ops -- --sample-size 10`.

use criterion::{criterion_group, criterion_main, Criterion};
use scanfit::cloud::normals::{estimate_normals, NormalsConfig};
use scanfit::project::{project_directed_batch, DirectedConfig};
use scanfit::{Point3, PointCloud, Vector3};

/// A jittered terrain-like sheet of `n` points over [0, 100]^2.
fn sheet(n: usize) -> Vec<Point3> {
    let side = (n as f64).sqrt().ceil() as usize;
    let mut rng = scanfit::testdata::Lcg::new(7);
    let mut rnd = || rng.next_f64();
    (0..n)
        .map(|i| {
            let x = (i % side) as f64 + rnd();
            let y = (i / side) as f64 + rnd();
            let (x, y) = (x * 100.0 / side as f64, y * 100.0 / side as f64);
            Point3::new(
                x,
                y,
                5.0 * (x * 0.05).sin() * (y * 0.07).cos() + 0.01 * rnd(),
            )
        })
        .collect()
}

fn kd(c: &mut Criterion) {
    let pts = sheet(1_000_000);
    let mut g = c.benchmark_group("cloud");
    g.sample_size(10);
    g.bench_function("kd_build_1e6", |b| {
        b.iter(|| {
            let cloud = PointCloud::new(pts.clone()).unwrap();
            cloud.tree().unwrap();
            cloud
        })
    });
    let cloud = PointCloud::new(pts.clone()).unwrap();
    cloud.tree().unwrap();
    g.bench_function("knn16_all_1e6", |b| {
        b.iter(|| cloud.knn_batch(cloud.points(), 16).unwrap())
    });
    g.bench_function("normals_k16_mst_1e6", |b| {
        b.iter(|| estimate_normals(&cloud, &NormalsConfig::default()).unwrap())
    });
    let queries: Vec<Point3> = sheet(10_000)
        .into_iter()
        .map(|p| Point3::new(p.x, p.y, p.z + 2.0))
        .collect();
    let dirs = vec![Vector3::new(0.0, 0.0, -1.0); queries.len()];
    g.bench_function("directed_1e4_onto_1e6", |b| {
        b.iter(|| {
            project_directed_batch(&cloud, &queries, &dirs, &DirectedConfig::default()).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, kd);
criterion_main!(benches);
