//! The grid layout against one patch with as many control points (issue 16;
//! the table in BENCHMARKS.md, "Grid layout"):
//!
//! ```sh
//! cargo run --release -p scanfit-io --example grid_study -- examples/data/panel_20k.ply 11
//! PDE=1 cargo run --release -p scanfit-io --example grid_study -- examples/data/terrain_50k.xyz 11
//! ```
//!
//! For a 3x3 grid of `N x N` least-squares nets (argument 2; `PDE=1`: the
//! PDE route's 5 x 5 terms per patch against one patch of 15 x 15) in three
//! variants (edges from the border points and the same net everywhere; edges
//! from the frame surface; frame edges and nets by detail), it prints the
//! model's control points counted once
//! (`PatchComplex::control_point_count`), its orthogonal RMSE by the model
//! measure (`pipeline::measure_model`, each point against its own patch), and
//! the same for one least-squares patch of `n x n` with `n^2` the first square
//! at or above the grid's count, and for the best single patch from
//! `(n - 3) x (n - 3)` to `n x n`. `DIAG=1` adds the RMSE per patch, of the
//! grid and of the single patch over the same points.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use scanfit::base::CoonsProjection;
use scanfit::network::layout::{GridOptions, LabelSource, Layout};
use scanfit::network::FaceFit;
use scanfit::pipeline::coons::{self, CoonsConfig, CoonsRoute};
use scanfit::pipeline::measure_model::{self, ModelMeasureConfig};
use scanfit::pipeline::reconstruct::{run, ReconstructConfig};
use scanfit::progress::NoProgress;
use scanfit::topology::{FaceCorners, PatchComplex};
use scanfit::PointCloud;

fn rmse(model: &PatchComplex, cloud: &PointCloud) -> f64 {
    measure_model::run(model, cloud, &ModelMeasureConfig::default(), &NoProgress)
        .unwrap()
        .totals
        .orthogonal
        .rmse
}

fn one_patch(cloud: &PointCloud, n: usize) -> (usize, f64, Vec<f64>) {
    let mut one = CoonsConfig::default();
    one.route = if std::env::var_os("PDE").is_some() {
        CoonsRoute::pde(15, 15)
    } else {
        CoonsRoute::bspline((3, 3), (n, n))
    };
    one.ctrl_from_density = false;
    one.relative_smoothing = None;
    one.projection = Some(CoonsProjection::Inversion(Default::default()));
    let r = coons::run(cloud, &one, &NoProgress).unwrap();
    let s = r.surface;
    let ((u0, u1), (v0, v1)) = s.domain();
    let v = vec![
        s.point(u0, v0),
        s.point(u1, v0),
        s.point(u1, v1),
        s.point(u0, v1),
    ];
    let d: Vec<f64> = scanfit::project::SurfaceInverter::new(&s, Default::default())
        .unwrap()
        .invert_all(cloud.points())
        .iter()
        .map(|r| r.distance)
        .collect();
    let m = PatchComplex::assemble(
        v,
        vec![FaceCorners {
            id: 0,
            surface: s,
            corners: [0, 1, 2, 3],
        }],
    )
    .unwrap();
    (m.control_point_count(), rmse(&m, cloud), d)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let t = scanfit_io::read_cloud(std::path::Path::new(&args[1]), &Default::default()).unwrap();
    let cloud = PointCloud::new(t.points).unwrap();
    let ctrl: usize = args.get(2).map_or(11, |s| s.parse().unwrap());
    let pde = std::env::var_os("PDE").is_some();
    let mut cache = std::collections::BTreeMap::new();
    for (name, options) in [
        ("border edges, same nets", GridOptions::plain()),
        ("frame edges, same nets", GridOptions::frame_only()),
        ("frame edges, nets by detail", GridOptions::default()),
    ] {
        let mut cfg = ReconstructConfig::default();
        cfg.source = LabelSource::Layout(Layout::Grid {
            rows: 3,
            cols: 3,
            options,
        });
        if !pde {
            cfg.fit = FaceFit::Bspline { ctrl: (ctrl, ctrl) };
        }
        let rep = match run(&cloud, &cfg, &NoProgress) {
            Ok(r) => r,
            Err(e) => {
                println!("{name}: {e}");
                continue;
            }
        };
        let mut lab = vec![-1.0; cloud.len()];
        for p in &rep.network.patches {
            for &i in &p.points {
                lab[i] = p.id as f64;
            }
        }
        let lc = cloud.clone().with_attribute("label", lab).unwrap();
        let count = rep.complex.control_point_count();
        let e = rmse(&rep.complex, &lc);
        let nn = (count as f64).sqrt().ceil() as usize;
        let (oc, oe, od) = cache
            .entry(nn)
            .or_insert_with(|| one_patch(&cloud, nn))
            .clone();
        let mut best = (nn, oe);
        for m in (nn.saturating_sub(3).max(4)..nn).filter(|_| !pde) {
            let e = cache.entry(m).or_insert_with(|| one_patch(&cloud, m)).1;
            if e < best.1 {
                best = (m, e);
            }
        }
        if std::env::var_os("DIAG").is_some() {
            for (p, f) in rep.network.patches.iter().zip(&rep.faces) {
                let r = |d: &mut dyn Iterator<Item = f64>| {
                    let v: Vec<f64> = d.collect();
                    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
                };
                let mine = r(&mut f.distances.iter().copied());
                let one = r(&mut p.points.iter().map(|&i| od[i]));
                println!(
                    "   patch {} pts {} grid {mine:.4} one {one:.4} net {:?}",
                    p.id,
                    p.points.len(),
                    f.surface.counts()
                );
            }
        }
        let nets: Vec<String> = rep
            .faces
            .iter()
            .map(|f| format!("{}x{}", f.surface.counts().0, f.surface.counts().1))
            .collect();
        println!(
            "{name}: count {count:5} rmse {e:.4} | one {nn}x{nn} ({oc}) rmse {oe:.4} ratio {:.3}; best one from {}x{}: {}x{} {:.4} ratio {:.3} | {} | nets {}",
            e / oe,
            nn.saturating_sub(3).max(4), nn.saturating_sub(3).max(4), best.0, best.0, best.1, e / best.1,
            rep.layout.as_deref().unwrap_or(""),
            nets.join(" ")
        );
    }
}
