//! End-to-end tests of the typed options of `coons`, `turntable` and the
//! `cloud` tools: negative values where a value can be negative (`--axis
//! -0.34,0.91,0.24`, `--view -200,0,0`, `--camera -60,-20`, `--hint 0,0,-1`,
//! `--view -60,35`), values refused with the option named (status 1), and
//! the command printing exactly what the library call returns.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{examples, ok, run, tmpdir};

use std::fmt::Write as _;
use std::path::Path;

use scanfit::pipeline::coons::{run as coons, CoonsConfig, CoonsRoute};
use scanfit::progress::NoProgress;
use scanfit_io::{read_cloud, ReadOptions};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs a command that must fail with status 1 and returns its stderr.
fn refused(args: &[&str]) -> String {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    err
}

/// A curved 10 x 7 panel, z = 0.3 sin(x / 3) + 0.01 x y, on a 41 x 29 grid.
fn panel(path: &Path) {
    let mut text = String::from("x y z\n");
    for i in 0..=40 {
        for j in 0..=28 {
            let (x, y) = (i as f64 * 0.25, j as f64 * 0.25);
            writeln!(text, "{x} {y} {}", 0.3 * (x / 3.0).sin() + 0.01 * x * y).unwrap();
        }
    }
    std::fs::write(path, text).unwrap();
}

/// 2000 points spread evenly over the sphere of radius 10 about the origin.
fn sphere(path: &Path) {
    let mut text = String::new();
    let n = 2000;
    for i in 0..n {
        let z = 1.0 - (2 * i + 1) as f64 / n as f64;
        let r = (1.0 - z * z).sqrt();
        let t = i as f64 * 2.399_963_229_728_653;
        writeln!(
            text,
            "{} {} {}",
            10.0 * r * t.cos(),
            10.0 * r * t.sin(),
            10.0 * z
        )
        .unwrap();
    }
    std::fs::write(path, text).unwrap();
}

fn column(path: &Path, name: &str) -> Vec<f64> {
    read_cloud(path, &ReadOptions::default())
        .unwrap()
        .column(name)
        .unwrap()
        .to_vec()
}

#[test]
fn turntable_takes_a_negative_axis_as_given() {
    let input = examples().join("bottle_12k.ply");
    let given = [-0.342, 0.908, 0.243];
    let out = ok(&run(&[
        "turntable",
        s(&input),
        "--axis",
        "-0.342,0.908,0.243",
        "--layers",
        "20",
        "--ctrl",
        "24x20",
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let norm = given.iter().map(|x| x * x).sum::<f64>().sqrt();
    for (k, g) in given.iter().enumerate() {
        let a = v["axis"][k].as_f64().unwrap();
        assert!((a - g / norm).abs() < 1e-12, "{}", v["axis"]);
    }
    // the bottle's noise is 0.05; the fit stays near it with the given axis
    // (0.138 measured since the ends are decided from the data: the open
    // neck is fitted to its end, where the 0.12 of the fixed margin held)
    let q = &v["quality"];
    assert!(q["rmse_distance"].as_f64().unwrap() < 0.15, "{q}");
    // the same with the value attached, and refused values named
    let o = run(&["turntable", s(&input), "--axis=-1,0", "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--axis '-1,0' must be auto, x, y, z or a direction X,Y,Z"),
        "{err}"
    );
    let err = refused(&["turntable", s(&input), "--ends", "cap"]);
    assert!(
        err.contains("unknown --ends 'cap'; use exclude or extend"),
        "{err}"
    );
    let err = refused(&["turntable", s(&input), "--weight", "heavy"]);
    assert!(err.contains("use moon, aza04 or as05"), "{err}");
    let err = refused(&[
        "turntable",
        s(&input),
        "--compare-weights",
        "--compare-rounds",
        "0",
    ]);
    assert!(
        err.contains("--compare-rounds = 0: ")
            && err.contains("1 to 1000 rounds (the paper's tables show 5)")
            && !err.contains("compare_weights"),
        "{err}"
    );
}

#[test]
fn hpr_sees_the_near_half_from_a_negative_viewpoint() {
    let d = tmpdir("typed-cmd", "hpr");
    let input = d.join("sphere.xyz");
    sphere(&input);
    let (out, png) = (d.join("v.xyz"), d.join("v.png"));
    let report = ok(&run(&[
        "cloud",
        "hpr",
        s(&input),
        "--view",
        "-200,0,0",
        "--camera",
        "-60,-20",
        "-o",
        s(&out),
        "--png",
        s(&png),
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&report).unwrap();
    let visible = v["visible"].as_u64().unwrap();
    assert_eq!(v["viewpoint"][0].as_f64(), Some(-200.0));
    // seen from 20 radii away the cap with x < -r^2/d = -0.5 (950 points)
    // is visible; the operator keeps a little more, up to the great circle
    // (measured 1002)
    assert!((950..=1050).contains(&visible), "{visible}");
    assert_eq!(visible + v["hidden"].as_u64().unwrap(), 2000);
    // every visible point faces the viewpoint: x < 0 up to the rim
    let x: Vec<f64> = read_cloud(&out, &ReadOptions::default())
        .unwrap()
        .into_cloud()
        .unwrap()
        .points()
        .iter()
        .map(|p| p.x)
        .collect();
    assert_eq!(x.len() as u64, visible);
    assert!(
        x.iter().all(|&x| x < 0.6),
        "{:?}",
        x.iter().copied().fold(f64::MIN, f64::max)
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 5_000);
    let err = refused(&["cloud", "hpr", s(&input), "--view", "-200,0"]);
    assert!(
        err.contains("--view '-200,0' must be three finite numbers"),
        "{err}"
    );
    let err = refused(&[
        "cloud",
        "hpr",
        s(&input),
        "--view",
        "0,0,50",
        "--camera",
        "-60,-95",
    ]);
    assert!(err.contains("the elevation must lie in [-90, 90]"), "{err}");
}

#[test]
fn normals_follow_a_negative_hint_and_a_viewpoint_below() {
    let d = tmpdir("typed-cmd", "normals");
    let input = d.join("panel.xyz");
    panel(&input);
    let (up, down, below) = (d.join("up.xyz"), d.join("down.xyz"), d.join("below.xyz"));
    ok(&run(&[
        "cloud",
        "normals",
        s(&input),
        "-o",
        s(&up),
        "--quiet",
    ]));
    ok(&run(&[
        "cloud",
        "normals",
        s(&input),
        "--hint",
        "0,0,-1",
        "-o",
        s(&down),
        "--quiet",
    ]));
    let out = ok(&run(&[
        "cloud",
        "normals",
        s(&input),
        "--orient",
        "view:0,0,-50",
        "-o",
        s(&below),
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["orientation"], "view:0,0,-50");
    let (a, b, c) = (column(&up, "nz"), column(&down, "nz"), column(&below, "nz"));
    assert_eq!(a.len(), 41 * 29);
    // the panel is nearly flat: every normal is within 30 degrees of +-z
    assert!(
        a.iter().all(|&z| z > 0.85),
        "{:?}",
        a.iter().copied().fold(1.0, f64::min)
    );
    assert!(a.iter().zip(&b).all(|(x, y)| (x + y).abs() < 1e-12));
    assert!(a.iter().zip(&c).all(|(x, y)| (x + y).abs() < 1e-12));
    let err = refused(&["cloud", "normals", s(&input), "--orient", "view:1,2"]);
    assert!(
        err.contains("--orient view: '1,2' must be three finite numbers"),
        "{err}"
    );
    let err = refused(&["cloud", "normals", s(&input), "--orient", "sideways"]);
    assert!(
        err.contains("unknown --orient 'sideways'; use mst, view:X,Y,Z or none"),
        "{err}"
    );
}

#[test]
fn boundary_takes_a_negative_view_and_names_a_bad_corner() {
    let d = tmpdir("typed-cmd", "boundary");
    let input = d.join("panel.xyz");
    panel(&input);
    let png = d.join("b.png");
    let out = ok(&run(&[
        "cloud",
        "boundary",
        s(&input),
        "--view",
        "-60,35",
        "--png",
        s(&png),
        "--criterion",
        "curvature",
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // the grid's boundary: 2 x (40 + 28) points, four corners at the grid's corners
    assert_eq!(v["loops"][0]["indices"].as_array().unwrap().len(), 136);
    let mut corners: Vec<[i64; 2]> = v["corners"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            [
                c["point"][0].as_f64().unwrap() as i64,
                c["point"][1].as_f64().unwrap() as i64,
            ]
        })
        .collect();
    corners.sort();
    assert_eq!(corners, vec![[0, 0], [0, 7], [10, 0], [10, 7]]);
    assert!(std::fs::metadata(&png).unwrap().len() > 5_000);
    let err = refused(&["cloud", "boundary", s(&input), "--corner-at", "0,30,70,999"]);
    assert!(
        err.contains("--corner-at = 999: ")
            && err.contains("136 points")
            && !err.contains("corner_positions"),
        "{err}"
    );
    let err = refused(&["cloud", "boundary", s(&input), "--corner-at", "0,-3"]);
    assert!(
        err.contains("--corner-at '0,-3' must be positions"),
        "{err}"
    );
}

#[test]
fn coons_prints_what_the_library_returns_and_refuses_bad_values() {
    let d = tmpdir("typed-cmd", "coons");
    let input = d.join("panel.xyz");
    panel(&input);
    let png = d.join("c.png");
    let out = ok(&run(&[
        "coons",
        s(&input),
        "--pde",
        "4x4",
        "--view",
        "-60,35",
        "--png",
        s(&png),
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // the same call through the library gives the same numbers, bit for bit
    let cloud = read_cloud(&input, &ReadOptions::default())
        .unwrap()
        .into_cloud()
        .unwrap();
    let mut cfg = CoonsConfig::default();
    cfg.route = CoonsRoute::pde(4, 4);
    let r = coons(&cloud, &cfg, &NoProgress).unwrap();
    let q = r.assessment.quality;
    assert_eq!(v["fit_error"]["mean"].as_f64(), Some(q.at_parameters.mean));
    assert_eq!(v["orthogonal"]["rmse"].as_f64(), Some(q.orthogonal.rmse));
    assert_eq!(v["coons_error"]["max"].as_f64(), Some(r.coons_errors.max));
    assert_eq!(
        v["surface_to_points"]["rmse"].as_f64(),
        Some(q.samples_to_points.stats.rmse)
    );
    assert_eq!(v["parameters"]["method"], "closest");
    // a smooth noise-free panel: the PDE surface is within 1% of its height
    assert!(q.at_parameters.max < 0.01, "{:?}", q.at_parameters);
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    let f = s(&input);
    for (args, needle) in [
        (vec!["--sides", "5"], "unknown --sides '5'; use 4 or 3"),
        (
            vec!["--fit", "spline"],
            "unknown --fit 'spline'; use bspline or pde",
        ),
        (
            vec!["--params", "nearest"],
            "unknown --params 'nearest'; use grid or closest",
        ),
        (
            vec!["--curves", "spline"],
            "unknown --curves 'spline'; use lsq or interpolate",
        ),
        (
            vec!["--criterion", "pointy"],
            "unknown --criterion 'pointy'; use angle or curvature",
        ),
        (
            vec!["--corners", "1,x"],
            "--corners '1,x' must be `auto` or loop positions",
        ),
        (vec!["--ctrl", "20y"], "--ctrl '20y' must be N or NxM"),
        (
            vec!["--pde", "4x4", "--export-tolerance=-1"],
            "--export-tolerance = -1: the B-spline form of the PDE surface needs a positive, finite tolerance in data units (default 1e-4 x the diagonal)",
        ),
    ] {
        let mut all = vec!["coons", f];
        all.extend(&args);
        let err = refused(&all);
        assert!(err.contains(needle), "{args:?}: '{needle}' not in {err}");
    }
}
