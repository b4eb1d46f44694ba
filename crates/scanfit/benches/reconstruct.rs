//! Whole-object reconstruction benchmark (issue 15, item 10): 10^6 labelled
//! points in 20 patches (a closed can: 6 sectors x 3 rows on the side, two
//! caps) end to end: labels, borders, junctions, edge curves, Coons patches,
//! closest-point parameters, PDE 8 x 8 per patch, B-spline forms, orthogonal
//! distances, edge gaps.
//! Run: `cargo bench -p scanfit --bench reconstruct`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::TAU;
use std::sync::Mutex;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use scanfit::network::FaceFit;
use scanfit::pde::PdeConfig;
use scanfit::pipeline::reconstruct::{run, ReconstructConfig};
use scanfit::progress::{NoProgress, Progress};
use scanfit::{Point3, PointCloud};

/// Uniformly random points on a closed can (radius 1, height 2) with noise.
fn can(n: usize) -> PointCloud {
    let mut s = 5u64;
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let side = TAU * 2.0;
    let cap = TAU / 2.0;
    let (mut pts, mut lab) = (Vec::with_capacity(n), Vec::with_capacity(n));
    while pts.len() < n {
        let pick = rnd() * (side + 2.0 * cap);
        let noise = 0.001 * (rnd() - 0.5);
        if pick < side {
            let (t, z) = (rnd() * TAU, rnd() * 2.0);
            let r = 1.0 + noise;
            pts.push(Point3::new(r * t.cos(), r * t.sin(), z));
            let sector = ((t / (TAU / 6.0)) as usize).min(5);
            let row = ((z / (2.0 / 3.0)) as usize).min(2);
            lab.push((row * 6 + sector) as f64);
        } else {
            let (x, y) = (2.0 * rnd() - 1.0, 2.0 * rnd() - 1.0);
            if x * x + y * y >= 1.0 {
                continue;
            }
            let top = pick >= side + cap;
            pts.push(Point3::new(x, y, if top { 2.0 } else { 0.0 } + noise));
            lab.push(if top { 21.0 } else { 20.0 });
        }
    }
    PointCloud::new(pts)
        .unwrap()
        .with_attribute("label", lab)
        .unwrap()
}

/// Prints how long each stage took (once, before the measurements).
struct Stages(Mutex<Vec<(String, Instant)>>);

impl Progress for Stages {
    fn stage(&self, name: &str, _steps: Option<u64>) {
        if let Ok(mut v) = self.0.lock() {
            v.push((name.to_string(), Instant::now()));
        }
    }
}

fn bench(c: &mut Criterion) {
    let cloud = can(1_000_000);
    let mut cfg = ReconstructConfig::default();
    cfg.fit = FaceFit::Pde(PdeConfig {
        m: 8,
        n: 8,
        ..Default::default()
    });
    let stages = Stages(Mutex::new(Vec::new()));
    let t0 = Instant::now();
    let r = run(&cloud, &cfg, &stages).unwrap();
    let end = Instant::now();
    let v = stages.0.lock().unwrap();
    let mut last = t0;
    let mut names = vec!["(start)".to_string()];
    for (name, t) in v.iter() {
        eprintln!(
            "  {:<14} {:.3} s",
            names.last().unwrap(),
            (*t - last).as_secs_f64()
        );
        names.push(name.clone());
        last = *t;
    }
    eprintln!(
        "  {:<14} {:.3} s",
        names.last().unwrap(),
        (end - last).as_secs_f64()
    );
    eprintln!(
        "  {} patches, {} edges, {} corners; max gap {:.2e}; orthogonal rmse {:.2e}; total {:.3} s",
        r.patches.len(),
        r.network.edges.len(),
        r.network.vertices.len(),
        r.totals.max_gap,
        r.totals.orthogonal.rmse,
        (end - t0).as_secs_f64()
    );
    assert_eq!(r.patches.len(), 20);
    let mut g = c.benchmark_group("reconstruct");
    g.sample_size(10);
    g.bench_function("can_1e6_points_20_patches_pde_8x8", |b| {
        b.iter(|| run(&cloud, &cfg, &NoProgress).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
