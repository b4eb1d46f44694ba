//! Patch layouts without hand labels (issue 16) on the shipped samples:
//! the creased part segmented into its true faces, the blob laid out as a
//! cube and reconstructed as a closed solid of the true volume (read back by
//! OpenCASCADE when it is installed, loudly skipped when not).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use scanfit::base::turntable::AxisChoice;
use scanfit::cloud::segment::{segment, SegmentConfig};
use scanfit::network::layout::{LabelSource, Layout};
use scanfit::pipeline::reconstruct::{run, ReconstructConfig};
use scanfit::progress::NoProgress;
use scanfit::{PointCloud, Vector3};
use scanfit_io::model::ModelDoc;
use scanfit_io::step_shell::step_shell_file;

#[path = "support/occ.rs"]
mod occ;

fn data(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/data")
        .join(file)
}

/// The cloud of a shipped file and its column `name` (if asked).
fn read(file: &str, name: Option<&str>) -> (PointCloud, Vec<f64>) {
    let path = data(file);
    // the layouts' own samples are PLY (the older terrain text file is bigger)
    assert!(
        !file.ends_with(".ply") || std::fs::metadata(&path).unwrap().len() < 1 << 20,
        "{file} is over 1 MB"
    );
    let t = scanfit_io::read_cloud(&path, &scanfit_io::ReadOptions::default()).unwrap();
    let col = name
        .map(|n| t.extra[t.columns.iter().position(|c| c == n).unwrap() - 3].clone())
        .unwrap_or_default();
    (PointCloud::new(t.points).unwrap(), col)
}

#[test]
fn creased_part_splits_into_its_eight_faces() {
    let (cloud, truth) = read("part_30k.ply", Some("true_face"));
    let s = segment(&cloud, &SegmentConfig::default()).unwrap();
    // per true face, the count of each label among its points
    let mut table: BTreeMap<i64, BTreeMap<u32, usize>> = BTreeMap::new();
    for (&t, &l) in truth.iter().zip(&s.labels) {
        *table.entry(t as i64).or_default().entry(l).or_default() += 1;
    }
    assert_eq!(table.len(), 8);
    let mut majority = Vec::new();
    for (face, counts) in &table {
        let total: usize = counts.values().sum();
        let (&label, &most) = counts.iter().max_by_key(|(_, &c)| c).unwrap();
        let share = most as f64 / total as f64;
        println!(
            "face {face}: {total} points, {:.2}% label {label}",
            100.0 * share
        );
        assert!(
            share >= 0.95,
            "face {face}: only {share} carry label {label}: {counts:?}"
        );
        majority.push(label);
    }
    // every face is its own region, and there are no others
    majority.sort_unstable();
    majority.dedup();
    assert_eq!(majority.len(), 8, "two faces share a region: {table:?}");
    assert_eq!(s.regions.len(), 8, "{:?}", s.regions);
}

#[test]
fn smooth_blob_has_no_edges_and_says_which_layout() {
    let (cloud, _) = read("blob_30k.ply", None);
    let e = segment(&cloud, &SegmentConfig::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no sharp edges") || e.contains("separate no regions"),
        "{e}"
    );
    assert!(e.contains("--layout cube"), "{e}");
}

#[test]
fn blob_as_a_cube_is_a_closed_solid_of_the_true_volume() {
    let (cloud, _) = read("blob_30k.ply", None);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("blob_30k.json")).unwrap()).unwrap();
    let truth = doc["true_volume"].as_f64().unwrap();
    let mut cfg = ReconstructConfig::default();
    cfg.source = LabelSource::Layout(Layout::Cube);
    let r = run(&cloud, &cfg, &NoProgress).unwrap();
    assert_eq!(r.patches.len(), 6);
    assert!(r.patches.iter().all(|p| p.sides == 4), "{:?}", r.patches);
    few_folds(&r);
    assert_eq!(r.network.vertices.len(), 8);
    assert_eq!(r.network.edges.len(), 12);
    assert!(r.totals.closed);
    assert!(
        r.totals.max_gap <= 1e-9 * r.totals.diagonal,
        "{}",
        r.totals.max_gap
    );
    let model = &r.complex;
    let v = model.signed_volume().abs();
    println!(
        "blob: volume {v} (true {truth}), orthogonal rmse {}",
        r.totals.orthogonal.rmse
    );
    assert!((v - truth).abs() < 0.01 * truth, "volume {v} vs {truth}");
    let step = step_shell_file(model, "blob").unwrap();
    assert!(step.text.contains("CLOSED_SHELL(") && step.text.contains("MANIFOLD_SOLID_BREP("));
    let Some(occ) = occ_read(model, "blob") else {
        return;
    };
    assert_eq!(occ["solids"], 1, "{occ}");
    assert_eq!(occ["faces"], 6, "{occ}");
    assert_eq!(occ["valid"], true, "{occ}");
    assert_eq!(occ["free_edges"], 0, "{occ}");
    let vo = occ["volume"].as_f64().unwrap();
    assert!(
        (vo - truth).abs() < 0.01 * truth,
        "OpenCASCADE volume {vo} vs {truth}"
    );
}

/// The layouts' parameters do not fold: at most 0.5% of a patch's points
/// (noise at the borders), per patch.
fn few_folds(r: &scanfit::pipeline::reconstruct::ReconstructReport) {
    for p in &r.patches {
        println!(
            "patch {}: {} sides, {} points, {} folded, orth rmse {:.4}",
            p.id, p.sides, p.points, p.fold_overs, p.orthogonal.rmse
        );
        assert!(
            p.fold_overs * 200 <= p.points,
            "patch {}: {} folded",
            p.id,
            p.fold_overs
        );
    }
}

/// OpenCASCADE's reading of `model` written as STEP (`tests/occ/check_model.py`),
/// or `None`, said loudly, when OpenCASCADE is not installed.
fn occ_read(model: &scanfit::topology::PatchComplex, name: &str) -> Option<serde_json::Value> {
    let step = step_shell_file(model, name).unwrap();
    if occ::missing(&format!("{name} was NOT read back by a CAD kernel")) {
        return None;
    }
    let dir = std::env::temp_dir().join(format!("scanfit-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (jp, sp) = (dir.join("model.json"), dir.join("model.stp"));
    std::fs::write(&jp, ModelDoc::new(model).to_json().unwrap()).unwrap();
    std::fs::write(&sp, &step.text).unwrap();
    let out = occ::run(
        "check_model.py",
        &[&jp, &sp],
        &format!("OpenCASCADE on {name}"),
    );
    std::fs::remove_dir_all(&dir).ok();
    let occ: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    println!("OpenCASCADE on {name}: {occ}");
    Some(occ)
}

/// The revolve layout's numbers every test asserts: patch counts by sides,
/// no gap, fold-overs per patch at most 0.5% (noise at the borders).
fn check_revolve(r: &scanfit::pipeline::reconstruct::ReconstructReport, four: usize, three: usize) {
    let sides = |n| r.patches.iter().filter(|p| p.sides == n).count();
    assert_eq!((sides(4), sides(3)), (four, three), "{:?}", r.patches);
    few_folds(r);
    assert!(
        r.totals.max_gap <= 1e-9 * r.totals.diagonal,
        "{}",
        r.totals.max_gap
    );
}

fn revolve(sectors: usize, bands: usize, axis: AxisChoice) -> ReconstructConfig {
    let mut cfg = ReconstructConfig::default();
    cfg.source = LabelSource::Layout(Layout::Revolve {
        sectors,
        bands,
        axis,
    });
    cfg
}

#[test]
fn vessel_as_revolve_is_a_closed_solid_of_the_true_volume() {
    // the pot with its flat bottom and domed lid, its own labels ignored
    let (cloud, _) = read("vessel_30k.ply", None);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("vessel_30k.json")).unwrap()).unwrap();
    let truth = doc["true_volume"].as_f64().unwrap();
    let r = run(&cloud, &revolve(4, 3, AxisChoice::Principal), &NoProgress).unwrap();
    // 4 x 3 side patches, 4 three-sided caps at each closed end
    check_revolve(&r, 12, 8);
    assert!(r.totals.closed);
    // corners: 2 poles, 4 on each of the 4 circles (cap rims and band cuts)
    assert_eq!(r.network.vertices.len(), 2 + 4 * 4);
    assert_eq!(r.network.edges.len(), 4 * 4 + 4 * 5);
    let v = r.complex.signed_volume().abs();
    println!(
        "vessel: volume {v} (true {truth}), orthogonal rmse {}",
        r.totals.orthogonal.rmse
    );
    assert!((v - truth).abs() < 0.01 * truth, "volume {v} vs {truth}");
    let Some(occ) = occ_read(&r.complex, "vessel") else {
        return;
    };
    assert_eq!(occ["solids"], 1, "{occ}");
    assert_eq!(occ["faces"], 20, "{occ}");
    assert_eq!(occ["valid"], true, "{occ}");
    assert_eq!(occ["free_edges"], 0, "{occ}");
    let vo = occ["volume"].as_f64().unwrap();
    assert!(
        (vo - truth).abs() < 0.01 * truth,
        "OpenCASCADE volume {vo} vs {truth}"
    );
}

#[test]
fn open_pot_as_revolve_is_the_pde_papers_twelve_subsets() {
    // the vessel without its lid (label 14): open at the top, a flat bottom
    let (cloud, label) = read("vessel_30k.ply", Some("label"));
    let pts: Vec<_> = cloud
        .points()
        .iter()
        .zip(&label)
        .filter(|(_, &l)| l != 14.0)
        .map(|(p, _)| *p)
        .collect();
    let cloud = PointCloud::new(pts).unwrap();
    // without its lid the pot is wider than tall: its principal axis lies
    // across it, so the axis is given (as `--axis z`)
    let r = run(
        &cloud,
        &revolve(4, 2, AxisChoice::Given(Vector3::z())),
        &NoProgress,
    )
    .unwrap();
    // Fig. 9 of the PDE paper: 12 subsets, 8 side patches and 4 three-sided bottom patches
    check_revolve(&r, 8, 4);
    assert!(!r.totals.closed);
    let free = r.edges.iter().filter(|e| e.patches[1].is_none()).count();
    assert_eq!(free, 4, "the rim: one free edge per sector");
    let Some(occ) = occ_read(&r.complex, "open-pot") else {
        return;
    };
    assert_eq!(occ["shells"], 1, "{occ}");
    assert_eq!(occ["faces"], 12, "{occ}");
    assert_eq!(occ["valid"], true, "{occ}");
    assert_eq!(occ["free_edges"], 4, "{occ}");
}

/// One least-squares patch of `n x n` control points (the `coons` pipeline,
/// closest-point parameters on its Coons base), as a one-face model.
fn one_patch(cloud: &PointCloud, n: usize) -> scanfit::topology::PatchComplex {
    use scanfit::base::CoonsProjection;
    use scanfit::pipeline::coons::{self, CoonsConfig, CoonsRoute};
    use scanfit::topology::{FaceCorners, PatchComplex};
    let mut one = CoonsConfig::default();
    one.route = CoonsRoute::bspline((3, 3), (n, n));
    one.ctrl_from_density = false;
    one.relative_smoothing = None;
    one.projection = Some(CoonsProjection::Inversion(Default::default()));
    let s = coons::run(cloud, &one, &NoProgress).unwrap().surface;
    let c = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, v)| s.point(u, v));
    PatchComplex::assemble(
        c.to_vec(),
        vec![FaceCorners {
            id: 0,
            surface: s,
            corners: [0, 1, 2, 3],
        }],
    )
    .unwrap()
}

/// The orthogonal RMSE of `model` over `cloud` by the model measure
/// (`scanfit report`), each point measured against its own patch.
fn model_rmse(model: &scanfit::topology::PatchComplex, cloud: &PointCloud) -> f64 {
    use scanfit::pipeline::measure_model::{self, ModelMeasureConfig};
    measure_model::run(model, cloud, &ModelMeasureConfig::default(), &NoProgress)
        .unwrap()
        .totals
        .orthogonal
        .rmse
}

/// The grid's model and its RMSE, each point against its own patch.
fn grid_fit(
    cloud: &PointCloud,
    options: scanfit::network::layout::GridOptions,
    fit: scanfit::network::FaceFit,
) -> (scanfit::pipeline::reconstruct::ReconstructReport, f64) {
    let mut cfg = ReconstructConfig::default();
    cfg.source = LabelSource::Layout(Layout::Grid {
        rows: 3,
        cols: 3,
        options,
    });
    cfg.fit = fit;
    let r = run(cloud, &cfg, &NoProgress).unwrap();
    assert_eq!(r.patches.len(), 9);
    assert!(r.patches.iter().all(|p| p.sides == 4), "{:?}", r.patches);
    assert!(r.totals.max_gap <= 1e-9 * r.totals.diagonal);
    few_folds(&r);
    let mut label = vec![-1.0; cloud.len()];
    for p in &r.network.patches {
        for &i in &p.points {
            label[i] = p.id as f64;
        }
    }
    let labelled = cloud.clone().with_attribute("label", label).unwrap();
    let e = model_rmse(&r.complex, &labelled);
    (r, e)
}

#[test]
fn grid_3x3_beats_one_patch_on_a_panel_with_a_badge() {
    use scanfit::network::layout::GridOptions;
    use scanfit::network::FaceFit;
    // a bent car panel with a badge off its centre (make_sheet.py)
    let (cloud, _) = read("panel_20k.ply", None);
    let fit = FaceFit::Bspline { ctrl: (11, 11) };
    let (grid, g) = grid_fit(&cloud, GridOptions::default(), fit);
    // control points counted once, the same way for the grid and one patch
    let total = grid.complex.control_point_count();
    assert_eq!(total, grid.totals.control_points);
    let n = (total as f64).sqrt().ceil() as usize;
    let one = one_patch(&cloud, n);
    assert_eq!(one.control_point_count(), n * n);
    let s = model_rmse(&one, &cloud);
    // the same nets everywhere, edges from the frame or from the border points
    let (_, frame) = grid_fit(&cloud, GridOptions::frame_only(), fit);
    let (_, plain) = grid_fit(&cloud, GridOptions::plain(), fit);
    println!(
        "panel: grid 3x3 {total} control points rmse {g:.4}; one {n}x{n} rmse {s:.4}; same nets: frame {frame:.4}, border edges {plain:.4}; {}",
        grid.layout.as_deref().unwrap_or("")
    );
    // measured: 921 control points, rmse 0.0614 against 0.0798 for one
    // 31 x 31 patch (23% lower; the noise is 0.05): the badge's patch gets
    // a 19 x 27 net, the smooth ones 7 x 11
    assert!(total <= n * n && total > 850, "{total}");
    assert!(g < 0.85 * s, "grid rmse {g} vs one patch {s}");
    assert!((0.055..0.068).contains(&g), "{g}");
    // without the detail nets the grid does not win (0.0861, 0.0971)
    assert!(frame > s && plain > frame, "{frame} {plain} vs {s}");
}

#[test]
fn grid_3x3_against_one_patch_on_terrain() {
    use scanfit::network::layout::GridOptions;
    use scanfit::network::FaceFit;
    use scanfit::pipeline::coons::{self, CoonsConfig, CoonsRoute};
    // a sheet with detail everywhere: the Jacksboro fault DEM
    let (cloud, _) = read("terrain_50k.xyz", None);
    let (grid, g) = grid_fit(
        &cloud,
        GridOptions::default(),
        FaceFit::Bspline { ctrl: (11, 11) },
    );
    let total = grid.totals.control_points;
    let n = (total as f64).sqrt().ceil() as usize;
    let s = model_rmse(&one_patch(&cloud, n), &cloud);
    println!("terrain: grid 3x3 {total} control points rmse {g:.3}; one {n}x{n} rmse {s:.3}");
    // the PDE route: 9 patches of 5 x 5 terms against one of 15 x 15
    let (_, gp) = grid_fit(&cloud, GridOptions::default(), FaceFit::default());
    let (_, gp_plain) = grid_fit(&cloud, GridOptions::plain(), FaceFit::default());
    let mut one = CoonsConfig::default();
    one.route = CoonsRoute::pde(15, 15);
    let sp = coons::run(&cloud, &one, &NoProgress)
        .unwrap()
        .assessment
        .quality
        .orthogonal
        .rmse;
    println!(
        "PDE: grid 3x3 of 5x5 terms: rmse {gp:.3} (border edges {gp_plain:.3}); one patch of 15x15 terms: rmse {sp:.3}"
    );
    // Measured, not the hoped-for result: on this terrain (detail at every
    // scale, everywhere) the grid does NOT beat one patch with as many
    // control points: least squares 40.50 m with 933 control points
    // against 38.97 m for one 31 x 31 patch (+3.9%: the detail nets have
    // nothing to concentrate on, and the grid's C0 joints cost spans); PDE
    // 64.97 m against 61.82 m (+5.1%; with the border-point edges 61.02 m,
    // -1.3%). These bounds guard the measurement.
    assert!(total <= n * n);
    assert!(
        (1.0..1.10).contains(&(g / s)),
        "grid rmse {g} vs one patch {s}"
    );
    assert!(
        (1.0..1.10).contains(&(gp / sp)),
        "PDE grid rmse {gp} vs one patch {sp}"
    );
    assert!((0.95..1.0).contains(&(gp_plain / sp)), "{gp_plain} vs {sp}");
}

#[test]
fn layouts_refuse_the_wrong_shape() {
    let spacing = |c: &PointCloud| c.spacing().unwrap().median;
    // a grid on a closed object: no four clear corners
    let (blob, _) = read("blob_30k.ply", None);
    let e = scanfit::network::layout::grid::grid_labels(&blob, 3, 3, spacing(&blob))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("four clear corners") && e.contains("--layout cube"),
        "{e}"
    );
    // a grid on a sheet with a hole: where the hole is
    let (panel, _) = read("patch_20k.ply", None);
    let e = scanfit::network::layout::grid::grid_labels(&panel, 3, 3, spacing(&panel))
        .unwrap_err()
        .to_string();
    assert!(e.contains("1 hole(s)"), "{e}");
    // revolve on a sheet: no axis
    let (terrain, _) = read("terrain_50k.xyz", None);
    let e = scanfit::network::layout::revolve::revolve_labels(
        &terrain,
        4,
        2,
        AxisChoice::Principal,
        spacing(&terrain),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("no axis to revolve about") && e.contains("grid:RxC"),
        "{e}"
    );
}

#[test]
fn segmented_part_is_one_valid_solid() {
    // faces with more than four corners (the step's riser and the side
    // below it) are written as chains of edge uses
    let (cloud, _) = read("part_30k.ply", None);
    let mut cfg = ReconstructConfig::default();
    cfg.source = LabelSource::Segment(SegmentConfig::default());
    let r = run(&cloud, &cfg, &NoProgress).unwrap();
    let uses: Vec<usize> = r
        .sides
        .iter()
        .map(|s| s.iter().map(Vec::len).sum())
        .collect();
    println!(
        "part: edge uses per face {uses:?}, gap {}",
        r.totals.max_gap
    );
    assert_eq!(r.patches.len(), 8);
    assert_eq!(uses.iter().filter(|&&u| u > 4).count(), 2, "{uses:?}");
    assert!(r.totals.closed);
    assert!(r.totals.max_gap <= 1e-9 * r.totals.diagonal);
    let Some(occ) = occ_read(&r.complex, "part") else {
        return;
    };
    assert_eq!(occ["shells"], 1, "{occ}");
    assert_eq!(occ["solids"], 1, "{occ}");
    assert_eq!(occ["faces"], 8, "{occ}");
    assert_eq!(occ["valid"], true, "{occ}");
    assert_eq!(occ["free_edges"], 0, "{occ}");
    // OpenCASCADE's volume is scanfit's own quadrature of the same faces
    let (vo, v) = (
        occ["volume"].as_f64().unwrap(),
        r.complex.signed_volume().abs(),
    );
    // (scanfit's quadrature differs from OpenCASCADE's by 4.4e-4 here)
    assert!((vo - v).abs() < 1e-3 * v, "OpenCASCADE {vo} vs {v}");
}
