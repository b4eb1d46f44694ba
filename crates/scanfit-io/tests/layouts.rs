//! Patch layouts without hand labels (issue 16) on the shipped samples:
//! the creased part segmented into its true faces, the blob laid out as a
//! cube and reconstructed as a closed solid of the true volume (read back by
//! OpenCASCADE when it is installed, loudly skipped when not).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use scanfit::cloud::segment::{segment, SegmentConfig};
use scanfit::network::layout::{LabelSource, Layout};
use scanfit::pipeline::reconstruct::{run, ReconstructConfig};
use scanfit::progress::NoProgress;
use scanfit::PointCloud;
use scanfit_io::model::ModelDoc;
use scanfit_io::step_shell::step_shell_file;

fn data(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/data")
        .join(file)
}

/// The cloud of a shipped file and its column `name` (if asked).
fn read(file: &str, name: Option<&str>) -> (PointCloud, Vec<f64>) {
    let path = data(file);
    assert!(
        std::fs::metadata(&path).unwrap().len() < 1 << 20,
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

fn occ_available() -> bool {
    Command::new("python3")
        .args(["-c", "import OCP"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
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
    // the layout's parameters do not fold: at most 0.5% of a patch's points
    // (noise at the borders), per patch
    for p in &r.patches {
        println!(
            "patch {}: {} points, {} folded",
            p.id, p.points, p.fold_overs
        );
        assert!(
            p.fold_overs * 200 <= p.points,
            "patch {}: {} folded",
            p.id,
            p.fold_overs
        );
    }
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
    if !occ_available() {
        eprintln!("\n**************************************************************");
        eprintln!("* OpenCASCADE (pip install cadquery-ocp) is NOT installed:   *");
        eprintln!("* the blob's STEP solid was NOT read back by a CAD kernel     *");
        eprintln!("**************************************************************\n");
        assert!(
            std::env::var_os("SCANFIT_REQUIRE_OCC").is_none(),
            "SCANFIT_REQUIRE_OCC is set but OpenCASCADE is missing"
        );
        return;
    }
    let dir = std::env::temp_dir().join(format!("scanfit-layout-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (jp, sp) = (dir.join("blob.json"), dir.join("blob.stp"));
    std::fs::write(&jp, ModelDoc::new(model).to_json().unwrap()).unwrap();
    std::fs::write(&sp, &step.text).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/occ/check_model.py");
    let o = Command::new("python3")
        .arg(script)
        .arg(&jp)
        .arg(&sp)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    std::fs::remove_dir_all(&dir).ok();
    let occ: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    println!("OpenCASCADE: {occ}");
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
