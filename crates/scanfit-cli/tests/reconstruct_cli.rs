//! End-to-end tests of `scanfit reconstruct` on a labelled can written by the
//! test (4 side sectors and 2 caps): the tables and JSON report, the pictures
//! and mesh, `--ignore`, and bad labels refused with no output file.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{ok, run, tmpdir};

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A closed can (radius 1, height 2) as a text file `x y z label`: side
/// sectors 0-3, bottom cap 10, top cap 11, deterministic noise 0.002.
/// `label` maps (point index, default label) to the written label text.
fn write_can(path: &Path, label: impl Fn(usize, i64) -> String) {
    let mut seed = 17u64;
    let mut noise = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        0.004 * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    };
    let h = 0.035;
    let mut out = String::from("x y z label\n");
    let mut k = 0;
    let nt = (TAU / h).round() as usize;
    let nz = (2.0 / h).round() as usize;
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64 * TAU;
        for j in 0..nz {
            let z = (j as f64 + 0.5) / nz as f64 * 2.0;
            let r = 1.0 + noise();
            let l = ((t / (PI / 2.0)) as i64).min(3);
            writeln!(out, "{:.6} {:.6} {z:.6} {}", r * t.cos(), r * t.sin(), label(k, l)).unwrap();
            k += 1;
        }
    }
    let n = (2.0 / h).round() as i64;
    for (z, l) in [(0.0, 10), (2.0, 11)] {
        for i in -n..=n {
            for j in -n..=n {
                let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                if x * x + y * y < (1.0 - 0.5 * h) * (1.0 - 0.5 * h) {
                    writeln!(out, "{x:.6} {y:.6} {:.6} {}", z + noise(), label(k, l)).unwrap();
                    k += 1;
                }
            }
        }
    }
    std::fs::write(path, out).unwrap();
}

#[test]
fn can_report_pictures_and_mesh() {
    let d = tmpdir("reconstruct", "can");
    let input = d.join("can.xyz");
    write_can(&input, |_, l| l.to_string());
    let (png, dev, glb) = (d.join("can.png"), d.join("dev.png"), d.join("can.glb"));
    let out = ok(&run(&[
        "reconstruct",
        s(&input),
        "--png",
        s(&png),
        "--deviation-png",
        s(&dev),
        "--mesh",
        s(&glb),
        "--json",
        "-q",
    ]));
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let t = &j["totals"];
    assert_eq!(t["faces"], 6);
    assert_eq!(t["edges"], 12);
    assert_eq!(t["corners"], 8);
    assert_eq!(t["closed"], true);
    let diag = t["diagonal"].as_f64().unwrap();
    assert!(t["max_gap"].as_f64().unwrap() <= 1e-9 * diag, "{t}");
    // noise uniform in +-0.002 (sigma 0.00115); the crease at the rims costs more
    assert!(t["orthogonal"]["rmse"].as_f64().unwrap() < 0.006, "{t}");
    assert_eq!(j["labels"], "label");
    for e in j["edges"].as_array().unwrap() {
        assert!(e["patches"][1].is_number(), "{e}");
    }
    for f in [&png, &dev] {
        let bytes = std::fs::read(f).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        let dec = png::Decoder::new(std::io::Cursor::new(bytes));
        let info = dec.read_info().unwrap();
        assert_eq!((info.info().width, info.info().height), (1200, 900));
    }
    assert_eq!(&std::fs::read(&glb).unwrap()[0..4], b"glTF");
    // the tables name every patch and the largest gap
    let out = ok(&run(&["reconstruct", s(&input), "-q"]));
    assert!(out.contains("6 patches, 12 edges, 8 corners, closed"), "{out}");
    assert!(out.contains("largest gap along an edge"), "{out}");
}

#[test]
fn ignored_cap_leaves_an_open_can() {
    let d = tmpdir("reconstruct", "ignore");
    let input = d.join("can.xyz");
    write_can(&input, |_, l| l.to_string());
    let out = ok(&run(&["reconstruct", s(&input), "--ignore", "11", "--json", "-q"]));
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["totals"]["faces"], 5);
    assert_eq!(j["totals"]["closed"], false);
    let free = j["edges"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["patches"][1].is_null())
        .count();
    assert_eq!(free, 4);
    assert!(j["ignored_points"].as_u64().unwrap() > 1000);
}

#[test]
fn bspline_route() {
    let d = tmpdir("reconstruct", "bspline");
    let input = d.join("can.xyz");
    write_can(&input, |_, l| l.to_string());
    let out = ok(&run(&[
        "reconstruct", s(&input), "--fit", "bspline", "--ctrl", "6x6", "--json", "-q",
    ]));
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let t = &j["totals"];
    assert!(t["max_gap"].as_f64().unwrap() <= 1e-9 * t["diagonal"].as_f64().unwrap());
    assert!(t["orthogonal"]["rmse"].as_f64().unwrap() < 0.006, "{t}");
}

/// Runs a failing reconstruction that asks for a PNG; returns stderr and
/// checks that no file was written.
fn refused(name: &str, label: impl Fn(usize, i64) -> String, extra: &[&str]) -> String {
    let d = tmpdir("reconstruct", name);
    let input = d.join("can.xyz");
    write_can(&input, label);
    let png = d.join("out.png");
    let mut args = vec!["reconstruct", s(&input), "--png", s(&png), "-q"];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(!o.status.success());
    assert!(!png.exists(), "an output file was written");
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn one_label_points_to_coons() {
    let e = refused("single", |_, _| "3".into(), &[]);
    assert!(e.contains("single patch") && e.contains("scanfit coons"), "{e}");
}

#[test]
fn float_labels_are_refused() {
    let e = refused("float", |k, l| format!("{}.5", l + (k % 2) as i64), &[]);
    assert!(e.contains("integers") && e.contains("point 0"), "{e}");
}

#[test]
fn text_labels_are_refused() {
    let e = refused("text", |_, l| if l == 11 { "lid".into() } else { l.to_string() }, &[]);
    assert!(e.contains("lid"), "{e}");
}

#[test]
fn tiny_patch_is_named() {
    let e = refused("tiny", |k, l| if k < 5 { "42".into() } else { l.to_string() }, &[]);
    assert!(e.contains("patch 42 has 5 points") && e.contains("--ignore 42"), "{e}");
}

#[test]
fn missing_label_attribute_is_named() {
    let e = refused("noattr", |_, l| l.to_string(), &["--labels", "segment"]);
    assert!(e.contains("'segment'") && e.contains("label"), "{e}");
}
