//! End-to-end tests of `scanfit cloud clean`, `--remove-outliers`, meshes as
//! input, format detection by content and CLI words in reader errors.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{ok, run, tmpdir};

use std::fmt::Write as _;
use std::path::Path;

use scanfit_io::{read_cloud, ReadOptions};

/// A wavy sheet on a jittered 100 x 100 grid over [0, 1]^2 with a `label`
/// column (its index), then `strays` points 0.15 to 0.6 above it.
fn sheet(path: &Path, strays: usize) {
    let mut s = 12345u64;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut t = String::from("x y z label\n");
    for i in 0..10_000 {
        let x = ((i / 100) as f64 + 0.3 * (rnd() - 0.5)) / 99.0;
        let y = ((i % 100) as f64 + 0.3 * (rnd() - 0.5)) / 99.0;
        let z = 0.1 * (3.0 * x).sin() * (2.0 * y).cos();
        writeln!(t, "{x} {y} {z} {i}").unwrap();
    }
    for k in 0..strays {
        let (x, y, z) = (rnd(), rnd(), 0.15 + 0.45 * rnd());
        writeln!(t, "{x} {y} {z} {}", 10_000 + k).unwrap();
    }
    std::fs::write(path, t).unwrap();
}

#[test]
fn clean_removes_the_planted_strays_and_keeps_attributes() {
    let d = tmpdir("clean", "strays");
    let input = d.join("sheet.xyz");
    sheet(&input, 107);
    let out = d.join("clean.ply");
    let o = run(&[
        "cloud",
        "clean",
        input.to_str().unwrap(),
        "--outliers",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    let j: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(j["points"], 10_107);
    assert_eq!(j["removed"], 107);
    assert_eq!(j["steps"][0]["operation"], "outliers");
    let c = read_cloud(&out, &ReadOptions::default())
        .unwrap()
        .into_cloud()
        .unwrap();
    let label = c.attribute("label").unwrap();
    assert_eq!(label.len(), 10_000);
    assert!(label.iter().enumerate().all(|(i, &l)| l == i as f64));
    // crop with negative numbers, then voxels; the table names every step
    let o = run(&[
        "cloud",
        "clean",
        input.to_str().unwrap(),
        "--box",
        "-1,-1,-1,0.5,2,2",
        "--outliers",
        "--voxel",
        "0.05",
        "-o",
        out.to_str().unwrap(),
    ]);
    let text = ok(&o);
    for step in ["crop box", "outliers", "voxels", "kept "] {
        assert!(text.contains(step), "{text}");
    }
    // --remove-outliers on a surface command says what it removed
    let o = run(&[
        "mba",
        input.to_str().unwrap(),
        "--remove-outliers",
        "--levels",
        "3",
    ]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        err.contains("note: --remove-outliers removed 107 of 10107 points"),
        "{err}"
    );
    // nothing asked: an error before reading
    let o = run(&[
        "cloud",
        "clean",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nothing to do"));
}

#[test]
fn voxel_count_is_exact_on_a_lattice() {
    let d = tmpdir("clean", "voxels");
    let input = d.join("lattice.csv");
    let mut t = String::new();
    for i in 0..1800 {
        writeln!(t, "{},{},{}", i % 30, (i / 30) % 20, i / 600).unwrap();
    }
    std::fs::write(&input, t).unwrap();
    let out = d.join("thin.xyz");
    let o = run(&[
        "cloud",
        "clean",
        input.to_str().unwrap(),
        "--voxel",
        "2",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    let j: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(j["kept"], 300);
    // relative: 2 spacings of 1
    let o = run(&[
        "cloud",
        "clean",
        input.to_str().unwrap(),
        "--voxel-spacings",
        "2",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    let j: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(j["kept"], 300);
}

#[test]
fn reader_errors_speak_cli_and_content_wins_over_a_text_name() {
    let d = tmpdir("clean", "advice");
    let nan = d.join("nan.xyz");
    std::fs::write(&nan, "0 0 0\n1 nan 1\n2 2 2\n").unwrap();
    let o = run(&["cloud", "info", nan.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        err.contains("--drop-non-finite") && !err.contains("ReadOptions"),
        "{err}"
    );
    let odd = d.join("scan.dat");
    std::fs::write(&odd, "0 0 0\n").unwrap();
    let o = run(&["cloud", "info", odd.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        err.contains("--format") && !err.contains("ReadOptions"),
        "{err}"
    );
    // a PLY named .xyz is read as PLY, with a warning
    let ply = d.join("points.xyz");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
    )
    .unwrap();
    let o = run(&["cloud", "info", ply.to_str().unwrap(), "--json"]);
    let j: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(j["points"], 3);
    assert!(String::from_utf8_lossy(&o.stderr).contains("the content is PLY"));
    // an STL mesh: its welded vertices with normals
    let stl = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus/stl/tetra_ascii.stl");
    let o = run(&["cloud", "info", stl.to_str().unwrap(), "--json"]);
    let j: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(j["points"], 4);
    let names: Vec<&str> = j["attributes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["nx", "ny", "nz"]);
}
