//! Trimmed faces and declared units read back by a real CAD kernel:
//! OpenCASCADE (the cadquery-ocp wheel) loads the STEP and IGES files
//! through `tests/occ/check_faces.py`, which reports each face's validity
//! (`BRepCheck_Analyzer`), its number of wires and its area (`BRepGProp`),
//! the bounding box in millimetres and the STEP file's declared units.
//!
//! * a curved panel with a round hole, fitted over its rectangle: the face
//!   keeps its rectangle and has the hole (two wires); an elliptic panel
//!   with a hole: a trimmed outer curve and the hole (two wires). The face's
//!   area agrees with scanfit's trimmed mesh within 1%, and with the area
//!   the data covers (the rectangle or ellipse less the hole, computed here
//!   in closed form) within the alpha shape's sampling;
//! * a 1 x 2 x 0 square written in each unit comes back as `1 x 2` times
//!   the unit in millimetres (OpenCASCADE converts on read), and the STEP
//!   reader names the declared unit.
//!
//! Without OpenCASCADE the test says so loudly; with `SCANFIT_REQUIRE_OCC=1`
//! (set by CI, which installs it) a missing OpenCASCADE is a failure.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use scanfit::bspline::{KnotVector, Mesh, Surface};
use scanfit::cloud::boundary::{boundary_loops, BoundaryConfig};
use scanfit::fit::surface::{fit_surface, SurfaceFitConfig};
use scanfit::trim::{trim_surface, TrimConfig, TrimmedSurface};
use scanfit::Point3;
use scanfit_io::iges::iges_file_with;
use scanfit_io::step::{step_file_with, CadItem};
use scanfit_io::units::{CadOptions, LengthUnit};

#[path = "support/occ.rs"]
mod occ;

/// Runs check_faces.py on `files`; None (after saying so loudly) without OpenCASCADE.
fn read_back(files: &[PathBuf], what: &str) -> Option<Vec<serde_json::Value>> {
    let skipped = format!(
        "the read-back by a CAD kernel of {} files ({what}).",
        files.len()
    );
    if occ::missing(&skipped) {
        return None;
    }
    let args: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let out = occ::run("check_faces.py", &args, what);
    Some(
        out.lines()
            .filter(|l| l.starts_with('{'))
            .map(|l| serde_json::from_str(l).unwrap())
            .collect(),
    )
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("scanfit-trim-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn mesh_area(m: &Mesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.vertices[i as usize]);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum()
}

/// A gently curved panel sampled on a 1 mm grid over `[0, 100] x [0, 60]`
/// where `keep(x, y)`, fitted with plane parameters and trimmed by its
/// alpha-shape loops.
fn panel(keep: impl Fn(f64, f64) -> bool) -> TrimmedSurface {
    let mut pts = Vec::new();
    let mut uv = Vec::new();
    for i in 0..=100 {
        for j in 0..=60 {
            let (x, y) = (i as f64, j as f64);
            if keep(x, y) {
                pts.push(Point3::new(x, y, 4.0 * (x / 30.0).sin() + 0.001 * x * y));
                uv.push([x / 100.0, y / 60.0]);
            }
        }
    }
    let cfg = SurfaceFitConfig {
        ctrl: (10, 8),
        ..SurfaceFitConfig::default()
    };
    let s = fit_surface(&pts, &uv, &cfg).unwrap();
    let b = boundary_loops(&pts, &BoundaryConfig::default()).unwrap();
    trim_surface(&s, &uv, &b, &TrimConfig::default()).unwrap()
}

/// Writes `t` as STEP and IGES, reads both back and checks one valid face
/// with `wires` wires whose area is the mesh's within 1%; returns the mesh area.
fn check_trimmed(t: &TrimmedSurface, name: &str, wires: usize) -> f64 {
    let d = dir(name);
    let item = [CadItem::Trimmed(t)];
    let step = step_file_with(&item, name, &CadOptions::default()).unwrap();
    // structural checks that need no CAD kernel
    assert_eq!(step.matches("ADVANCED_FACE(").count(), 1);
    assert_eq!(step.matches("FACE_BOUND(").count(), wires - 1);
    assert_eq!(step.matches("FACE_OUTER_BOUND(").count(), 1);
    assert_eq!(step.matches("PCURVE(").count(), t.curves().count());
    let iges = iges_file_with(&item, name, &CadOptions::default()).unwrap();
    let de: Vec<&str> = iges.lines().filter(|l| &l[72..73] == "D").collect();
    assert_eq!(de.iter().filter(|l| l.starts_with("     144")).count(), 2);
    assert_eq!(
        de.iter().filter(|l| l.starts_with("     142")).count(),
        2 * t.curves().count()
    );
    let (sp, ip) = (d.join("t.stp"), d.join("t.igs"));
    std::fs::write(&sp, step).unwrap();
    std::fs::write(&ip, iges).unwrap();
    let mesh = mesh_area(&t.surface_mesh());
    println!("{name}: trimmed mesh area {mesh}");
    if let Some(r) = read_back(&[sp, ip], name) {
        for (file, kind) in r.iter().zip(["STEP", "IGES"]) {
            let faces = file["faces"].as_array().unwrap();
            assert_eq!(faces.len(), 1, "{kind}: {file}");
            let f = &faces[0];
            assert_eq!(f["valid"], true, "{kind}: {file}");
            assert_eq!(
                f["wires"].as_u64().unwrap() as usize,
                wires,
                "{kind}: {file}"
            );
            let area = f["area"].as_f64().unwrap();
            assert!(
                (area - mesh).abs() < 0.01 * mesh,
                "{kind}: OpenCASCADE's face area {area} vs the mesh's {mesh}"
            );
        }
    }
    std::fs::remove_dir_all(&d).ok();
    mesh
}

trait SurfaceMesh {
    fn surface_mesh(&self) -> Mesh;
}

impl SurfaceMesh for TrimmedSurface {
    fn surface_mesh(&self) -> Mesh {
        self.tessellate(200, 120)
    }
}

#[test]
fn a_holed_panel_reads_back_as_a_face_with_a_hole() {
    let hole = |x: f64, y: f64| (x - 50.0).hypot(y - 30.0) > 12.0;
    let t = panel(hole);
    assert!(t.outer.is_none(), "the rectangle is kept");
    assert_eq!(t.holes.len(), 1);
    let area = check_trimmed(&t, "holed panel", 2);
    // the data cover 100 x 60 less the hole (the surface is curved: its
    // area is a few per mille above the flat one); the alpha-shape loop
    // runs through the grid points just outside the circle
    let flat = 6000.0 - std::f64::consts::PI * 144.0;
    assert!(area > flat && area < 1.02 * flat, "{area} vs {flat}");
}

#[test]
fn an_elliptic_panel_with_a_hole_trims_its_outline() {
    let keep = |x: f64, y: f64| {
        ((x - 50.0) / 50.0).hypot((y - 30.0) / 30.0) <= 1.0 && (x - 60.0).hypot(y - 30.0) > 8.0
    };
    let t = panel(keep);
    assert!(t.outer.is_some(), "the rounded outline is trimmed");
    assert_eq!(t.holes.len(), 1);
    let area = check_trimmed(&t, "elliptic panel", 2);
    let flat = std::f64::consts::PI * (50.0 * 30.0 - 64.0);
    assert!((area - flat).abs() < 0.03 * flat, "{area} vs {flat}");
}

#[test]
fn declared_units_are_read_back_by_opencascade() {
    let k = KnotVector::uniform_clamped(1, 2).unwrap();
    let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
    let s = Surface::new(
        k.clone(),
        k,
        vec![p(0., 0.), p(0., 2.), p(1., 0.), p(1., 2.)],
    )
    .unwrap();
    let d = dir("units");
    let mut files = Vec::new();
    for u in LengthUnit::ALL {
        let o = CadOptions::with_units(u);
        let sp = d.join(format!("{u}.stp"));
        let ip = d.join(format!("{u}.igs"));
        let step = step_file_with(&[CadItem::Surface(&s)], "square", &o).unwrap();
        let iges = iges_file_with(&[CadItem::Surface(&s)], "square", &o).unwrap();
        // the coordinates are never scaled
        assert!(step.contains("CARTESIAN_POINT('',(1.0,2.0,0.0))"), "{u}");
        std::fs::write(&sp, step).unwrap();
        std::fs::write(&ip, iges).unwrap();
        files.extend([sp, ip]);
    }
    let Some(r) = read_back(&files, "units") else {
        return;
    };
    // the names OpenCASCADE's STEP reader gives the declared length unit
    let names = ["millimetre", "centimetre", "metre", "inch", "foot"];
    for (k, u) in LengthUnit::ALL.iter().enumerate() {
        let (st, ig) = (&r[2 * k], &r[2 * k + 1]);
        let units: Vec<String> = st["units"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_str().unwrap().to_lowercase())
            .collect();
        assert_eq!(units, [names[k]], "{u}: {st}");
        for f in [st, ig] {
            let b: Vec<f64> = f["bbox"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            let mm = u.millimetres();
            // OpenCASCADE's bounding box adds its tolerance gap
            let (dx, dy) = (b[3] - b[0], b[4] - b[1]);
            assert!(
                (dx - mm).abs() < 1e-3 * mm,
                "{u}: x extent {dx} vs {mm}: {f}"
            );
            assert!(
                (dy - 2.0 * mm).abs() < 1e-3 * mm,
                "{u}: y extent {dy} vs {}: {f}",
                2.0 * mm
            );
        }
    }
    std::fs::remove_dir_all(&d).ok();
}
