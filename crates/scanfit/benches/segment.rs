//! Segmentation benchmark (issue 16, item 6): 10^6 points on the surface of
//! a box 2 x 1.5 x 1 with noise 2e-4 (six faces, twelve creases), segmented
//! by normal variation with the default settings: k-NN graph, PCA normals,
//! neighbour variation, octree, region growing, hand-off of the edge points.
//! Run: `cargo bench -p scanfit --bench segment`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use scanfit::cloud::segment::{segment, SegmentConfig};
use scanfit::{Point3, PointCloud};

/// Area-uniform random points on the box surface, with noise.
fn boxed(n: usize) -> PointCloud {
    let mut s = 7u64;
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let size = [2.0, 1.5, 1.0];
    let areas = [size[1] * size[2], size[0] * size[2], size[0] * size[1]];
    let total = 2.0 * areas.iter().sum::<f64>();
    let mut pts = Vec::with_capacity(n);
    while pts.len() < n {
        let mut pick = rnd() * total;
        let mut axis = 0;
        while pick >= 2.0 * areas[axis] && axis < 2 {
            pick -= 2.0 * areas[axis];
            axis += 1;
        }
        let side = if pick < areas[axis] { 0.0 } else { size[axis] };
        let mut p = [rnd() * size[0], rnd() * size[1], rnd() * size[2]];
        p[axis] = side + 2e-4 * (rnd() - 0.5);
        pts.push(Point3::new(p[0], p[1], p[2]));
    }
    PointCloud::new(pts).unwrap()
}

fn bench(c: &mut Criterion) {
    let cloud = boxed(1_000_000);
    let s = segment(&cloud, &SegmentConfig::default()).unwrap();
    eprintln!(
        "segment 10^6: {} regions, {} edge points, {} cells",
        s.regions.len(),
        s.edge.iter().filter(|&&e| e).count(),
        s.cells.len()
    );
    assert_eq!(s.regions.len(), 6);
    let mut g = c.benchmark_group("segment");
    g.sample_size(10);
    g.bench_function("box_1e6_points", |b| {
        // a fresh cloud each time: its KD-tree is built lazily and cached
        b.iter_batched(
            || cloud.clone(),
            |c| segment(&c, &SegmentConfig::default()).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
