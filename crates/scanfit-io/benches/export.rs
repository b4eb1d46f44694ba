//! Export and picture benchmarks (criterion): a 64 x 64 bicubic surface to STEP
//! and IGES, its 256 x 256 tessellation to glTF, and a 1200 x 900 shaded render.
//!
//! Run: `cargo bench -p scanfit-io --bench export`

#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use scanfit::bspline::{tessellate, KnotVector, Surface};
use scanfit::Point3;
use scanfit_io::gltf::mesh_glb;
use scanfit_io::iges::iges_file;
use scanfit_io::render::{render_png, Colouring, RenderOptions};
use scanfit_io::step::{step_file, CadItem};

fn surface() -> Surface {
    let n = 64;
    let c: Vec<Point3> = (0..n * n)
        .map(|k| {
            let (i, j) = ((k / n) as f64, (k % n) as f64);
            Point3::new(i, j, 5.0 * (0.2 * i).sin() * (0.15 * j).cos())
        })
        .collect();
    Surface::new(
        KnotVector::uniform_clamped(3, n).unwrap(),
        KnotVector::uniform_clamped(3, n).unwrap(),
        c,
    )
    .unwrap()
}

fn export(c: &mut Criterion) {
    let s = surface();
    let mut g = c.benchmark_group("export");
    g.sample_size(20);
    g.bench_function("step_64x64_bicubic", |b| {
        b.iter(|| step_file(&[CadItem::Surface(black_box(&s))], "bench").unwrap())
    });
    g.bench_function("iges_64x64_bicubic", |b| {
        b.iter(|| iges_file(&[CadItem::Surface(black_box(&s))], "bench").unwrap())
    });
    g.bench_function("tessellate_256x256", |b| {
        b.iter(|| tessellate(black_box(&s), 256, 256))
    });
    let mesh = tessellate(&s, 256, 256);
    g.bench_function("glb_256x256_mesh", |b| {
        b.iter(|| mesh_glb(black_box(&mesh), None, "bench"))
    });
    g.bench_function("png_render_1200x900_256x256_mesh", |b| {
        b.iter(|| {
            render_png(
                black_box(&mesh),
                None,
                Colouring::Height,
                &RenderOptions::default(),
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, export);
criterion_main!(benches);
