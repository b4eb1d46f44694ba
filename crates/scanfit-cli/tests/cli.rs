//! End-to-end tests of the `scanfit` binary: outputs, and clear errors (with a
//! non-zero exit and no output file) for every kind of bad input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_scanfit"))
}

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data")
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("scanfit-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn fit_writes_json_that_reads_back_and_interpolates() {
    let d = tmpdir("fit");
    let out = d.join("c.json");
    let input = examples().join("dataset1.csv");
    let o = run(&[
        "curve",
        "fit",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("max deviation") && stdout.contains("data units"),
        "{stdout}"
    );
    let (doc, curve) = scanfit_io::json::read_curve(&out).unwrap();
    let table = scanfit_io::read_points(&input).unwrap();
    let params = doc.params.unwrap();
    for (u, p) in params.iter().zip(&table.points) {
        assert!((curve.point(*u) - p).norm() < 1e-9);
    }
    assert_eq!(
        doc.provenance.unwrap().parameterization.as_deref(),
        Some("proposed")
    );
}

#[test]
fn fit_json_report_and_least_squares() {
    let input = examples().join("dataset6.csv");
    let report = |smooth: &str| {
        let o = run(&[
            "curve",
            "fit",
            input.to_str().unwrap(),
            "--ctrl",
            "15",
            "--smooth",
            smooth,
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let (plain, smooth) = (report("0"), report("1e-3"));
    assert_eq!(smooth["control_points"], 15);
    assert_eq!(smooth["fit"], "least squares");
    let q = |v: &serde_json::Value, k: &str| v["quality"][k].as_f64().unwrap();
    // 15 control points cannot follow 69 points exactly, but stay close
    assert!(q(&plain, "max_deviation") > 1e-3 && q(&plain, "max_deviation") < 1.0);
    // smoothing trades accuracy for less bending
    assert!(q(&smooth, "max_deviation") > q(&plain, "max_deviation"));
    assert!(q(&smooth, "max_curvature") < q(&plain, "max_curvature"));
}

#[test]
fn closed_fit_gives_periodic_curve() {
    let d = tmpdir("closed");
    let input = d.join("loop.xyz");
    let pts: String = (0..12)
        .map(|k| {
            let t = k as f64 / 12.0 * std::f64::consts::TAU;
            format!("{} {} 0\n", 3.0 * t.cos(), 2.0 * t.sin())
        })
        .collect();
    std::fs::write(&input, pts).unwrap();
    let out = d.join("loop.json");
    let o = run(&[
        "curve",
        "fit",
        input.to_str().unwrap(),
        "--closed",
        "--param",
        "centripetal",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (doc, curve) = scanfit_io::json::read_curve(&out).unwrap();
    assert!(doc.periodic && curve.is_periodic());
    assert!((curve.point(0.0) - curve.point(1.0)).norm() < 1e-12);
}

#[test]
fn compare_prints_every_method_and_writes_svg() {
    let d = tmpdir("compare");
    let svg = d.join("ds3.svg");
    let input = examples().join("dataset3.csv");
    let o = run(&[
        "curve",
        "compare",
        input.to_str().unwrap(),
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    for m in [
        "centripetal",
        "exponential",
        "uniform",
        "proposed",
        "chord",
        "hybrid",
        "universal",
    ] {
        assert!(stdout.contains(m), "{m} missing:\n{stdout}");
    }
    assert!(stdout.contains("dataset3.csv:5 and"), "{stdout}");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(text.matches("font-weight=\"bold\">").count(), 8); // title + 7 panels
    let o = run(&[
        "curve",
        "compare",
        input.to_str().unwrap(),
        "-o",
        svg.to_str().unwrap(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let hybrid = v["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["method"] == "hybrid")
        .unwrap();
    assert_eq!(hybrid["ok"], false);
}

/// Runs a fit on `content`, expects failure whose stderr contains `needle`,
/// and checks that no output file was created.
fn expect_error(name: &str, content: Option<&str>, extra: &[&str], needle: &str) {
    let d = tmpdir(name);
    let input = d.join(format!("{name}.csv"));
    if let Some(c) = content {
        std::fs::write(&input, c).unwrap();
    }
    let out = d.join("out.json");
    let mut args = vec![
        "curve",
        "fit",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--svg",
    ];
    let svg = d.join("out.svg");
    args.push(svg.to_str().unwrap());
    args.extend_from_slice(extra);
    let o = run(&args);
    let err = stderr(&o);
    assert!(!o.status.success(), "{name}: should fail");
    assert_eq!(o.status.code(), Some(1), "{name}");
    assert!(err.contains(needle), "{name}: '{needle}' not in:\n{err}");
    assert!(!err.contains("panicked"), "{name}: {err}");
    assert!(!out.exists() && !svg.exists(), "{name}: output written");
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(leftovers.len() <= 1, "{name}: stray files {leftovers:?}");
}

#[test]
fn bad_input_is_reported_clearly() {
    expect_error("missing", None, &[], "No such file");
    expect_error("empty", Some(""), &[], "no points found");
    expect_error("header_only", Some("x,y,z\n"), &[], "no points found");
    expect_error(
        "text",
        Some("x,y,z\n1,2,3\n4,five,6\n"),
        &[],
        "text.csv:3: value 2 ('five') is not a number",
    );
    expect_error(
        "nan",
        Some("1,2,3\n4,nan,6\n7,8,9\n"),
        &[],
        "nan.csv:2: value 2 is NaN",
    );
    expect_error(
        "inf",
        Some("1,2,3\n4,5,inf\n7,8,9\n"),
        &[],
        "nan.csv".replace("nan", "inf").as_str(),
    );
    expect_error(
        "ragged",
        Some("1,2,3\n4,5\n"),
        &[],
        "ragged.csv:2: 2 values found",
    );
    expect_error(
        "few",
        Some("0,0,0\n1,1,0\n2,0,0\n"),
        &[],
        "3 points given, but interpolation of degree 3 needs at least 4",
    );
    expect_error(
        "dup",
        Some("0,0,0\n1,1,0\n1,1,0\n2,0,0\n3,1,0\n"),
        &[],
        "points 1 and 2 coincide (distance 0e0); remove the duplicate (points 1 and 2 are at",
    );
    expect_error(
        "ctrl",
        Some("0,0,0\n1,1,0\n2,0,0\n3,1,0\n4,0,0\n"),
        &["--ctrl", "9"],
        "9 control points requested but only 5 data points",
    );
    expect_error(
        "method",
        Some("0,0,0\n1,1,0\n2,0,0\n3,1,0\n"),
        &["--param", "fancy"],
        "unknown parameterization 'fancy'",
    );
    expect_error("ext", Some("0,0,0"), &[], "");
}

#[test]
fn help_has_examples() {
    for sub in [
        &["curve", "fit", "--help"][..],
        &["curve", "compare", "--help"],
        &["--help"],
    ] {
        let o = run(sub);
        assert!(o.status.success());
        assert!(
            String::from_utf8_lossy(&o.stdout).contains("Examples:"),
            "{sub:?}"
        );
    }
}

#[test]
fn review_regressions() {
    // a good JSON target plus an unwritable SVG target: neither is written
    let d = tmpdir("group");
    let good = d.join("good.json");
    let input = examples().join("dataset1.csv");
    let o = run(&[
        "curve",
        "fit",
        input.to_str().unwrap(),
        "-o",
        good.to_str().unwrap(),
        "--svg",
        d.join("missing/f.svg").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(!good.exists(), "half of a failed run was written");
    assert_eq!(
        stderr(&o).matches("No such file").count(),
        1,
        "{}",
        stderr(&o)
    );

    expect_error(
        "typo",
        Some("0,O,0\n1,1,1\n2,0,0\n3,1,0\n"),
        &[],
        "typo.csv:1: value 2 ('O') is not a number",
    );
    expect_error(
        "huge",
        Some("0,0,0\n1,1,1e300\n2,0,0\n3,1,0\n"),
        &[],
        "magnitude 1e300",
    );
    expect_error(
        "negsmooth",
        Some("0,0,0\n1,1,0\n2,0,0\n3,1,0\n4,0,0\n"),
        &["--ctrl", "4", "--smooth", "-1"],
        "smoothing weight -1 must be finite and non-negative",
    );
    expect_error(
        "closedfew",
        Some("0,0,0\n1,0,0\n1,1,0\n0,1,0\n"),
        &["--closed"],
        "closed interpolation of degree 3 needs at least 7",
    );

    // --closed works with the default method (centripetal then)
    let sq = d.join("sq.csv");
    std::fs::write(&sq, "0,0,0\n1,0,0\n1,1,0\n0,1,0\n").unwrap();
    let o = run(&[
        "curve",
        "fit",
        sq.to_str().unwrap(),
        "--closed",
        "--degree",
        "1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("centripetal"));
}
