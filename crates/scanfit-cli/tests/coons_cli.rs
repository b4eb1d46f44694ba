//! End-to-end tests of `scanfit coons`: both routes on the sample panel, the
//! outputs read back with the right numbers, a three-sided patch, and clear
//! errors without output files.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{ok, run, tmpdir};

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use scanfit_io::json::read_surface;
use scanfit_io::{read_cloud, ReadOptions};

fn patch() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data/patch_20k.ply")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn pde_route_on_the_panel() {
    let d = tmpdir("coons", "pde");
    let (json, png, pts) = (d.join("s.json"), d.join("s.png"), d.join("p.ply"));
    let out = ok(&run(&[
        "coons",
        s(&patch()),
        "--pde",
        "5x5",
        "-o",
        s(&json),
        "--png",
        s(&png),
        "--points-out",
        s(&pts),
        "--json",
    ]));
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    // the panel's corners are the images of the unit square's corners
    // (make_clouds.py): (0|100 + 0, 0|70 + 0) in x, y up to the noise
    let mut corners: Vec<[i64; 2]> = r["corners"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let p = c["point"].as_array().unwrap();
            [
                (p[0].as_f64().unwrap() / 10.0).round() as i64,
                (p[1].as_f64().unwrap() / 10.0).round() as i64,
            ]
        })
        .collect();
    corners.sort();
    assert_eq!(corners, vec![[0, 0], [0, 7], [10, 0], [10, 7]]);
    // noise is 0.05% of the diagonal per coordinate (sigma ~0.064): the PDE
    // surface sits at the noise level, and improves on the Coons patch
    let (coons, fit) = (
        r["coons_error"]["mean"].as_f64().unwrap(),
        r["fit_error"]["mean"].as_f64().unwrap(),
    );
    assert!(fit < 0.06 && fit < 0.85 * coons, "{coons} {fit}");
    assert!(r["orthogonal"]["mean"].as_f64().unwrap() < 0.06);
    let outside = r["parameters"]["outside"].as_u64().unwrap();
    assert!(outside < 400, "{outside}");
    let (doc, surface) = read_surface(&json).unwrap();
    assert!(doc.provenance.unwrap().operation.contains("PDE"));
    assert_eq!(surface.degrees(), (3, 3));
    let cloud = read_cloud(&pts, &ReadOptions::default()).unwrap();
    let outside_col = cloud.column("outside").unwrap();
    assert_eq!(
        outside_col.iter().filter(|&&o| o == 1.0).count() as u64,
        outside
    );
    assert!(cloud
        .column("u")
        .unwrap()
        .iter()
        .all(|u| (0.0..=1.0).contains(u)));
    assert!(std::fs::metadata(&png).unwrap().len() > 20_000);
}

#[test]
fn bspline_route_with_given_corners_and_table() {
    let d = tmpdir("coons", "bspline");
    let first = ok(&run(&["coons", s(&patch()), "--json", "--quiet"]));
    let r: serde_json::Value = serde_json::from_str(&first).unwrap();
    let pos: Vec<String> = r["corners"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["position"].to_string())
        .collect();
    let step = d.join("s.stp");
    let out = ok(&run(&[
        "coons",
        s(&patch()),
        "--corners",
        &pos.join(","),
        "--fit",
        "bspline",
        "--ctrl",
        "12x12",
        "--params",
        "closest",
        "--step",
        s(&step),
    ]));
    assert!(out.contains("Coons patch |P - S_c(u,v)| (eq. 15)"), "{out}");
    assert!(out.contains("12 x 12 control points"), "{out}");
    let row = out
        .lines()
        .find(|l| l.starts_with("B-spline surface |P - S(u,v)|"))
        .unwrap();
    let mean: f64 = row.split_whitespace().nth(7).unwrap().parse().unwrap();
    assert!(mean < 0.06, "{row}");
    assert!(std::fs::read_to_string(&step)
        .unwrap()
        .contains("B_SPLINE_SURFACE_WITH_KNOTS"));
}

#[test]
fn three_sided_patch() {
    let d = tmpdir("coons", "three");
    // a curved triangle: corners (0,0), (10,0), (0,10), sampled on a grid
    let mut text = String::from("x y z\n");
    for i in 0..=60 {
        for j in 0..=(60 - i) {
            let (x, y) = (i as f64 / 6.0, j as f64 / 6.0);
            writeln!(text, "{x} {y} {}", 0.02 * (x * x + y * y)).unwrap();
        }
    }
    let input = d.join("tri.xyz");
    std::fs::write(&input, text).unwrap();
    let out = ok(&run(&[
        "coons",
        s(&input),
        "--sides",
        "3",
        "--pde",
        "4x4",
        "--json",
    ]));
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(r["corners"].as_array().unwrap().len(), 3);
    assert!(r["fit_error"]["max"].as_f64().unwrap() < 0.01, "{r}");
}

#[test]
fn clear_errors_and_no_output() {
    let d = tmpdir("coons", "errors");
    // a disk has no corners
    let mut text = String::new();
    for r in 1..=15 {
        let k = 6 * r;
        for a in 0..k {
            let t = a as f64 / k as f64 * std::f64::consts::TAU;
            writeln!(text, "{} {} 0", r as f64 * t.cos(), r as f64 * t.sin()).unwrap();
        }
    }
    let disk = d.join("disk.xyz");
    std::fs::write(&disk, text).unwrap();
    let json = d.join("s.json");
    let o = run(&["coons", s(&disk), "-o", s(&json)]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("not clearly corners") && e.contains("--force-corners"),
        "{e}"
    );
    assert!(!json.exists());
    let o = run(&["coons", s(&patch()), "--fit", "bspline", "--pde", "5x5"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("exclude each other"));
    let o = run(&["coons", s(&patch()), "--corners", "1,2,3"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--sides is 4"));
    let o = run(&["coons", s(&patch()), "--pde", "5x5", "-o", "x.stl"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains(".json"));
    let o = run(&["coons", "--help"]);
    assert!(ok(&o).contains("scanfit coons examples/data/patch_20k.ply --pde 5x5"));
}
