//! End-to-end tests of the `scanfit` binary: outputs, and clear errors (with a
//! non-zero exit and no output file) for every kind of bad input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

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

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The stdout of `scanfit COMMAND.. INPUT OPTIONS..`, which must succeed.
fn succeeds(command: &[&str], input: &Path, options: &[&str]) -> String {
    let mut args = command.to_vec();
    args.push(s(input));
    args.extend_from_slice(options);
    let o = run(&args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The JSON report of [`succeeds`] with `--json`.
fn json(command: &[&str], input: &Path, options: &[&str]) -> serde_json::Value {
    let mut options = options.to_vec();
    options.push("--json");
    serde_json::from_str(&succeeds(command, input, &options)).unwrap()
}

#[test]
fn fit_writes_json_that_reads_back_and_interpolates() {
    let d = tmpdir("fit");
    let out = d.join("c.json");
    let input = examples().join("dataset1.csv");
    let stdout = succeeds(&["curve", "fit"], &input, &["-o", s(&out)]);
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
        json(
            &["curve", "fit"],
            &input,
            &["--ctrl", "15", "--smooth", smooth],
        )
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
    succeeds(
        &["curve", "fit"],
        &input,
        &["--closed", "--param", "centripetal", "-o", s(&out)],
    );
    let (doc, curve) = scanfit_io::json::read_curve(&out).unwrap();
    assert!(doc.periodic && curve.is_periodic());
    assert!((curve.point(0.0) - curve.point(1.0)).norm() < 1e-12);
}

#[test]
fn compare_prints_every_method_and_writes_svg() {
    let d = tmpdir("compare");
    let svg = d.join("ds3.svg");
    let input = examples().join("dataset3.csv");
    let stdout = succeeds(&["curve", "compare"], &input, &["-o", s(&svg)]);
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
    let v = json(&["curve", "compare"], &input, &["-o", s(&svg)]);
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
    let stdout = succeeds(&["curve", "fit"], &sq, &["--closed", "--degree", "1"]);
    assert!(stdout.contains("centripetal"));
}

/// Writes `n` points of a smooth sheet, with a header, optionally with u, v columns.
fn sheet(path: &std::path::Path, n: usize, with_uv: bool) {
    let mut s = String::from(if with_uv { "x y z u v\n" } else { "x y z\n" });
    for k in 0..n {
        let (u, v) = (
            ((k * 7919) % n) as f64 / n as f64,
            ((k * 104729) % 997) as f64 / 996.0,
        );
        let (x, y, z) = (
            30.0 * u,
            20.0 * v,
            2.0 * (2.0 * u).sin() * (3.0 * v).cos() + u * v,
        );
        if with_uv {
            s += &format!("{x} {y} {z} {u} {v}\n");
        } else {
            s += &format!("{x} {y} {z}\n");
        }
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn surface_fit_writes_every_output() {
    let d = tmpdir("sfit");
    let input = d.join("sheet.xyz");
    sheet(&input, 3000, false);
    let (json, png, mesh, ply) = (
        d.join("s.json"),
        d.join("s.png"),
        d.join("s.obj"),
        d.join("p.ply"),
    );
    let o = run(&[
        "fit",
        input.to_str().unwrap(),
        "--ctrl",
        "12x10",
        "-o",
        json.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--mesh",
        mesh.to_str().unwrap(),
        "--points-out",
        ply.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("eq. 15") && out.contains("MBA eq. 17") && out.contains("fold-overs"),
        "{out}"
    );
    let (doc, s) = scanfit_io::json::read_surface(&json).unwrap();
    assert_eq!(s.counts(), (12, 10));
    let q = doc.quality.unwrap();
    assert!(q.rmse < 0.05 && q.fold_overs == 0, "{q:?}");
    assert!(q.max_distance <= q.max_error + 1e-12);
    let png_bytes = std::fs::read(&png).unwrap();
    assert_eq!(&png_bytes[1..4], b"PNG");
    let obj = std::fs::read_to_string(&mesh).unwrap();
    assert!(obj.lines().filter(|l| l.starts_with("f ")).count() > 1000);
    let ply_bytes = std::fs::read(&ply).unwrap();
    let header = String::from_utf8_lossy(&ply_bytes[..400]);
    assert!(header.contains("element vertex 3000") && header.contains("property double residual"));
}

#[test]
fn surface_fit_from_uv_columns_is_exact_for_representable_data() {
    let d = tmpdir("suv");
    let input = d.join("plane.xyz");
    // a bilinear-in-(u,v) sheet is represented exactly by any bicubic net
    let mut s = String::from("x,y,z,u,v\n");
    for k in 0..500 {
        let (u, v) = (
            ((k * 37) % 500) as f64 / 499.0,
            ((k * 91) % 499) as f64 / 498.0,
        );
        s += &format!("{},{},{},{u},{v}\n", 3.0 * u + v, 2.0 * v, 0.5 * u * v - u);
    }
    std::fs::write(&input, s).unwrap();
    let v = json(
        &["fit"],
        &input,
        &["--params", "uv-columns", "--ctrl", "6", "--smooth", "0"],
    );
    assert!(v["quality"]["max_error"].as_f64().unwrap() < 1e-9, "{v}");
    // correction rounds appear in the report
    let v = json(&["fit"], &input, &["--ctrl", "6", "--correct", "3"]);
    assert!(!v["quality"]["correction_rmse"]
        .as_array()
        .unwrap()
        .is_empty());
}

#[test]
fn surface_fit_bad_input() {
    let d = tmpdir("sbad");
    let small = d.join("small.xyz");
    sheet(&small, 50, true);
    let expect = |args: &[&str], needle: &str| {
        let o = run(args);
        assert!(!o.status.success(), "{args:?} should fail");
        let e = stderr(&o);
        assert!(
            e.contains(needle) && !e.contains("panicked"),
            "{args:?}: '{needle}' not in {e}"
        );
    };
    let f = small.to_str().unwrap();
    expect(
        &["fit", f, "--ctrl", "10x10", "--smooth", "0"],
        "50 points given, but a least-squares surface with 100 control points",
    );
    expect(
        &[
            "fit",
            f,
            "--params",
            "uv-columns",
            "--ctrl",
            "4",
            "--mesh",
            "x.stl",
        ],
        "must end in .obj or .ply",
    );
    expect(
        &["fit", f, "--periodic-u"],
        "--periodic-u needs parameters that go around",
    );
    expect(
        &["fit", f, "--ctrl", "axb"],
        "--ctrl 'axb' must be N or NxM",
    );
    let same_u = d.join("sameu.xyz");
    std::fs::write(
        &same_u,
        (0..40)
            .map(|k| format!("{k} {} 0 0.5 {}\n", k % 7, k as f64 / 39.0))
            .collect::<String>(),
    )
    .unwrap();
    expect(
        &[
            "fit",
            same_u.to_str().unwrap(),
            "--params",
            "uv-columns",
            "--ctrl",
            "4",
        ],
        "no columns named u and v",
    );
    let same_u2 = d.join("sameu2.xyz");
    std::fs::write(
        &same_u2,
        String::from("x y z u v\n")
            + &(0..40)
                .map(|k| format!("{k} {} 0 0.5 {}\n", k % 7, k as f64 / 39.0))
                .collect::<String>(),
    )
    .unwrap();
    expect(
        &[
            "fit",
            same_u2.to_str().unwrap(),
            "--params",
            "uv-columns",
            "--ctrl",
            "4",
            "--smooth",
            "0",
        ],
        "only 1 distinct u parameters",
    );
    let outside = d.join("outside.xyz");
    std::fs::write(
        &outside,
        String::from("x y z u v\n")
            + &(0..40)
                .map(|k| {
                    format!(
                        "{k} {} 0 {} {}\n",
                        k % 7,
                        1.5 - (k % 2) as f64,
                        k as f64 / 39.0
                    )
                })
                .collect::<String>(),
    )
    .unwrap();
    expect(
        &[
            "fit",
            outside.to_str().unwrap(),
            "--params",
            "uv-columns",
            "--ctrl",
            "4",
        ],
        "outside the domain",
    );
}

#[test]
fn surface_fit_cad_mesh_and_deviation_outputs() {
    let d = tmpdir("scad");
    let input = d.join("sheet.xyz");
    sheet(&input, 2000, false);
    let names = ["s.stp", "s.igs", "s.glb", "m.ply", "dev.png"];
    let paths: Vec<_> = names.iter().map(|n| d.join(n)).collect();
    let o = run(&[
        "fit",
        input.to_str().unwrap(),
        "--ctrl",
        "10",
        "--step",
        paths[0].to_str().unwrap(),
        "--iges",
        paths[1].to_str().unwrap(),
        "--mesh",
        paths[2].to_str().unwrap(),
        "--deviation-png",
        paths[4].to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&[
        "fit",
        input.to_str().unwrap(),
        "--ctrl",
        "10",
        "-q",
        "--mesh",
        paths[3].to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let step = std::fs::read_to_string(&paths[0]).unwrap();
    assert!(step.contains("ADVANCED_FACE") && step.contains("B_SPLINE_SURFACE_WITH_KNOTS"));
    let iges = std::fs::read_to_string(&paths[1]).unwrap();
    assert!(iges.lines().all(|l| l.len() == 80) && iges.contains("     128"));
    let glb = std::fs::read(&paths[2]).unwrap();
    assert_eq!(&glb[0..4], b"glTF");
    let ply = std::fs::read(&paths[3]).unwrap();
    let head = String::from_utf8_lossy(&ply[..600]);
    assert!(
        head.contains("property double deviation") && head.contains("property uchar red"),
        "{head}"
    );
    let png = std::fs::read(&paths[4]).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn report_writes_a_self_contained_page() {
    let d = tmpdir("report");
    let input = d.join("sheet.xyz");
    sheet(&input, 2000, false);
    let json = d.join("s.json");
    let o = run(&[
        "fit",
        input.to_str().unwrap(),
        "--ctrl",
        "10",
        "-q",
        "-o",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = d.join("r.html");
    let o = run(&[
        "report",
        json.to_str().unwrap(),
        input.to_str().unwrap(),
        "-o",
        html.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // the same surface and points as the fit: the same orthogonal RMSE
    let (doc, _) = scanfit_io::json::read_surface(&json).unwrap();
    let fit_rmse = doc.quality.unwrap().rmse_distance;
    assert!((v["rmse"].as_f64().unwrap() - fit_rmse).abs() < 1e-12 * (1.0 + fit_rmse));
    assert_eq!(
        v["histogram"]["counts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap())
            .sum::<u64>()
            + v["histogram"]["overflow"].as_u64().unwrap(),
        2000
    );
    let page = std::fs::read_to_string(&html).unwrap();
    assert_eq!(page.matches("data:image/png;base64,").count(), 3);
    assert!(page.contains("<svg") && page.contains("RMSE"));
    // a surface file that is not one is reported, nothing written
    let bad = d.join("bad.json");
    std::fs::write(&bad, "{}").unwrap();
    let o = run(&[
        "report",
        bad.to_str().unwrap(),
        input.to_str().unwrap(),
        "-o",
        d.join("x.html").to_str().unwrap(),
    ]);
    assert!(!o.status.success() && stderr(&o).contains("not a scanfit surface document"));
    assert!(!d.join("x.html").exists());
}

#[test]
fn curve_pictures_as_png() {
    let d = tmpdir("cpng");
    let (svg, png, fpng) = (d.join("c.svg"), d.join("c.png"), d.join("f.png"));
    let input = examples().join("dataset2.csv");
    let o = run(&[
        "curve",
        "compare",
        input.to_str().unwrap(),
        "-q",
        "-o",
        svg.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&[
        "curve",
        "fit",
        input.to_str().unwrap(),
        "--png",
        fpng.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for p in [&png, &fpng] {
        let bytes = std::fs::read(p).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert!(bytes.len() > 5000, "{} is suspiciously small", p.display());
    }
}

/// Franke's function on 20000 seeded points of the unit square (relief
/// 1.2): its best-fit plane is tilted and folded the default fit over
/// (13067 fold-overs in 199454 triangles at 10^5 points, refused as
/// "leaves the data"); the default fit now projects along z.
#[test]
fn surface_fit_of_a_height_field_of_large_relief_projects_along_z() {
    let d = tmpdir("sfranke");
    let input = d.join("franke.xyz");
    common::write_franke_xyz(&input, 20_000);
    let json = d.join("f.json");
    let o = run(&[
        "fit",
        input.to_str().unwrap(),
        "-o",
        json.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["projection"]["axis"], "z", "{v}");
    assert_eq!(v["projection"]["fold_shares"]["z"], 0.0, "{v}");
    assert!(
        v["projection"]["fold_shares"]["best-fit plane"]
            .as_f64()
            .unwrap()
            > 0.02,
        "{v}"
    );
    let q = &v["quality"];
    assert_eq!(q["fold_overs"], 0, "{q}");
    // relief 1.2: RMSE under 0.1% of it
    assert!(q["rmse"].as_f64().unwrap() < 1.2e-3, "{q}");
    let o = run(&["fit", input.to_str().unwrap(), "-o", json.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("projected along z"), "{out}");
}
