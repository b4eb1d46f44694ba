//! End-to-end tests of `scanfit reconstruct` on a labelled can written by the
//! test (4 side sectors and 2 caps): the tables and JSON report, the pictures
//! and mesh, `--ignore`, and bad labels refused with no output file.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{ok, run, tmpdir};

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Deterministic noise uniform in `[-width / 2, width / 2)` (a 64-bit
/// linear congruential generator from `seed`).
fn uniform_noise(mut seed: u64, width: f64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        width * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    }
}

/// A closed can (radius 1, height 2) as a text file `x y z label`: side
/// sectors 0-3, bottom cap 10, top cap 11, deterministic noise 0.002.
/// `label` maps (point index, default label) to the written label text.
fn write_can(path: &Path, label: impl Fn(usize, i64) -> String) {
    write_can_sectors(path, 4, label)
}

/// [`write_can`] with `sectors` side sectors (labels `0..sectors`): with 6,
/// each cap has 6 corners and two of its sides run over two edges.
fn write_can_sectors(path: &Path, sectors: usize, label: impl Fn(usize, i64) -> String) {
    let mut noise = uniform_noise(17, 0.004);
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
            let l = ((t / (TAU / sectors as f64)) as i64).min(sectors as i64 - 1);
            writeln!(
                out,
                "{:.6} {:.6} {z:.6} {}",
                r * t.cos(),
                r * t.sin(),
                label(k, l)
            )
            .unwrap();
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
    assert!(
        out.contains("6 patches, 12 edges, 8 corners, closed"),
        "{out}"
    );
    assert!(out.contains("largest gap along an edge"), "{out}");
}

/// The JSON report of `reconstruct` with `extra` options on the can of
/// [`write_can`] with its own labels (in the temporary directory `name`).
fn can_json(name: &str, extra: &[&str]) -> serde_json::Value {
    let d = tmpdir("reconstruct", name);
    let input = d.join("can.xyz");
    write_can(&input, |_, l| l.to_string());
    let mut args = vec!["reconstruct", s(&input), "--json", "-q"];
    args.extend_from_slice(extra);
    serde_json::from_str(&ok(&run(&args))).unwrap()
}

#[test]
fn ignored_cap_leaves_an_open_can() {
    let j = can_json("ignore", &["--ignore", "11"]);
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
    let j = can_json("bspline", &["--fit", "bspline", "--ctrl", "6x6"]);
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
    assert!(
        e.contains("single patch") && e.contains("scanfit coons"),
        "{e}"
    );
}

#[test]
fn float_labels_are_refused() {
    let e = refused("float", |k, l| format!("{}.5", l + (k % 2) as i64), &[]);
    assert!(e.contains("integers") && e.contains("point 0"), "{e}");
}

#[test]
fn text_labels_are_refused() {
    let e = refused(
        "text",
        |_, l| if l == 11 { "lid".into() } else { l.to_string() },
        &[],
    );
    assert!(e.contains("lid"), "{e}");
}

#[test]
fn tiny_patch_is_named() {
    let e = refused(
        "tiny",
        |k, l| if k < 5 { "42".into() } else { l.to_string() },
        &[],
    );
    assert!(
        e.contains("patch 42 has 5 points") && e.contains("--ignore 42"),
        "{e}"
    );
}

#[test]
fn missing_label_attribute_is_named() {
    let e = refused("noattr", |_, l| l.to_string(), &["--labels", "segment"]);
    assert!(e.contains("'segment'") && e.contains("label"), "{e}");
}

/// `reconstruct INPUT -o m.json --step m.stp --iges m.igs --json` in `dir`:
/// the JSON report and the three paths.
fn model_outputs(input: &Path, dir: &Path) -> (serde_json::Value, [PathBuf; 3]) {
    let files = ["m.json", "m.stp", "m.igs"].map(|f| dir.join(f));
    let out = ok(&run(&[
        "reconstruct",
        s(input),
        "-o",
        s(&files[0]),
        "--step",
        s(&files[1]),
        "--iges",
        s(&files[2]),
        "--json",
        "-q",
    ]));
    (serde_json::from_str(&out).unwrap(), files)
}

fn occ_available() -> bool {
    std::process::Command::new("python3")
        .args(["-c", "import OCP"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// The OpenCASCADE read-back of a model (scanfit-io's `check_model.py`), or
/// `None`, loudly, without OpenCASCADE (a failure with SCANFIT_REQUIRE_OCC=1).
fn occ_check(json: &Path, step: &Path) -> Option<serde_json::Value> {
    if !occ_available() {
        eprintln!("\n*****************************************************************");
        eprintln!("* OpenCASCADE (pip install cadquery-ocp) is NOT installed: the  *");
        eprintln!("* reconstructed STEP shell was NOT checked by a CAD kernel       *");
        eprintln!("*****************************************************************\n");
        assert!(
            std::env::var_os("SCANFIT_REQUIRE_OCC").is_none(),
            "SCANFIT_REQUIRE_OCC is set but OpenCASCADE is missing"
        );
        return None;
    }
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scanfit-io/tests/occ/check_model.py");
    let o = std::process::Command::new("python3")
        .arg(script)
        .arg(json)
        .arg(step)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "check_model.py: {out} {}",
        String::from_utf8_lossy(&o.stderr)
    );
    println!("OpenCASCADE: {out}");
    Some(serde_json::from_str(&out).unwrap())
}

#[test]
fn vessel_is_one_valid_solid_of_the_true_volume() {
    let d = tmpdir("reconstruct", "vessel");
    let input = common::examples().join("vessel_30k.ply");
    let truth: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(common::examples().join("vessel_30k.json")).unwrap(),
    )
    .unwrap();
    let (r, [json, step, iges]) = model_outputs(&input, &d);
    let t = &r["totals"];
    assert_eq!(t["faces"], 14);
    assert_eq!(t["closed"], true);
    let diag = t["diagonal"].as_f64().unwrap();
    assert!(t["max_gap"].as_f64().unwrap() <= 1e-9 * diag, "{t}");
    // the fit error at the noise level (sigma 0.037, creases at the rims)
    let sigma = truth["noise_sigma"].as_f64().unwrap();
    assert!(
        t["orthogonal"]["rmse"].as_f64().unwrap() < 2.5 * sigma,
        "{t}"
    );
    // the model document: closed, sewn, the volume in its report
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(doc["schema"], "scanfit-model/1");
    assert_eq!(doc["closed"], true);
    assert_eq!(doc["patches"].as_array().unwrap().len(), 14);
    let text = std::fs::read_to_string(&step).unwrap();
    assert!(text.contains("CLOSED_SHELL(") && text.contains("MANIFOLD_SOLID_BREP("));
    assert_eq!(text.matches("EDGE_CURVE(").count(), 28);
    assert_eq!(text.matches("ADVANCED_FACE(").count(), 14);
    assert!(std::fs::read_to_string(&iges).unwrap().lines().count() > 100);
    let truth_volume = truth["true_volume_mesh"].as_f64().unwrap();
    if let Some(occ) = occ_check(&json, &step) {
        assert_eq!(occ["shells"], 1);
        assert_eq!(occ["solids"], 1);
        assert_eq!(occ["faces"], 14);
        assert_eq!(occ["valid"], true, "{occ}");
        assert_eq!(occ["free_edges"], 0, "{occ}");
        let v = occ["volume"].as_f64().unwrap();
        assert!(
            (v / truth_volume - 1.0).abs() < 0.01,
            "volume {v} vs {truth_volume}"
        );
        assert!(
            occ["max_face_diff"].as_f64().unwrap() < 1e-9 * diag,
            "{occ}"
        );
    }
}

/// A cap with 6 corners (a can of 6 sectors) is a four-sided patch two of
/// whose sides run over two edges each: the model, STEP and IGES files hold
/// those chains, the STEP face loops list all 6 edges and share them with
/// the sectors, and OpenCASCADE reads one valid solid with no free edge.
#[test]
fn caps_with_six_corners_are_written_as_one_solid() {
    let d = tmpdir("reconstruct", "six");
    let input = d.join("can6.xyz");
    write_can_sectors(&input, 6, |_, l| l.to_string());
    let (r, [json, step, iges]) = model_outputs(&input, &d);
    let t = &r["totals"];
    assert_eq!(
        (t["faces"].as_u64(), t["edges"].as_u64()),
        (Some(8), Some(18))
    );
    let diag = t["diagonal"].as_f64().unwrap();
    assert!(t["max_gap"].as_f64().unwrap() <= 1e-9 * diag, "{t}");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for p in doc["patches"].as_array().unwrap() {
        let chains = p["sides"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| s.is_array())
            .map(|s| s.as_array().unwrap().len())
            .collect::<Vec<_>>();
        let want: Vec<usize> = if p["id"].as_i64().unwrap() >= 10 {
            vec![2, 2]
        } else {
            vec![]
        };
        assert_eq!(chains, want, "patch {}", p["id"]);
    }
    assert!(doc["report"]["totals"]["max_gap"].as_f64().unwrap() <= 1e-9 * diag);
    let text = std::fs::read_to_string(&step).unwrap();
    assert!(text.contains("CLOSED_SHELL(") && text.contains("MANIFOLD_SOLID_BREP("));
    assert_eq!(text.matches("EDGE_CURVE(").count(), 18);
    assert_eq!(text.matches("VERTEX_POINT(").count(), 12);
    // every edge is used by two face loops: 36 oriented edges
    assert_eq!(text.matches("ORIENTED_EDGE(").count(), 36);
    // `report` on the written model: the reconstruction's orthogonal RMSE
    // per patch (the same surfaces, the same points by label)
    let rep: serde_json::Value =
        serde_json::from_str(&ok(&run(&["report", s(&json), s(&input), "--json", "-q"]))).unwrap();
    assert_eq!(rep["assignment"]["labels"], "label");
    for (a, b) in rep["patches"]
        .as_array()
        .unwrap()
        .iter()
        .zip(r["patches"].as_array().unwrap())
    {
        assert_eq!(a["id"], b["id"]);
        assert_eq!(a["points"], b["points"]);
        let (x, y) = (
            a["orthogonal"]["rmse"].as_f64().unwrap(),
            b["orthogonal"]["rmse"].as_f64().unwrap(),
        );
        assert!((x - y).abs() <= 1e-9 * y, "patch {}: {x} vs {y}", a["id"]);
    }
    assert_eq!(rep["edges"].as_array().unwrap().len(), 18);
    assert!(rep["totals"]["max_gap"].as_f64().unwrap() <= 1e-9 * diag);
    let table = ok(&run(&["report", s(&json), s(&input), "-q"]));
    assert!(
        table.contains("points assigned by the label attribute 'label'")
            && table.contains("orth rmse")
            && table.contains("max normal angle (deg)"),
        "{table}"
    );
    let igs = std::fs::read_to_string(&iges).unwrap();
    assert_eq!(igs.lines().filter(|l| l.starts_with("128,")).count(), 8);
    if let Some(occ) = occ_check(&json, &step) {
        assert_eq!(occ["shells"], 1);
        assert_eq!(occ["solids"], 1);
        assert_eq!(occ["faces"], 8);
        assert_eq!(occ["valid"], true, "{occ}");
        assert_eq!(occ["free_edges"], 0, "{occ}");
        let v = occ["volume"].as_f64().unwrap();
        // pi r^2 h of the can, the 6-sector polygonal rims cost well under 1%
        assert!((v / (2.0 * PI) - 1.0).abs() < 0.01, "volume {v}");
        assert!(
            occ["max_face_diff"].as_f64().unwrap() < 1e-9 * diag,
            "{occ}"
        );
    }
}

#[test]
fn umbrella_is_one_open_shell_of_three_sided_panels() {
    let d = tmpdir("reconstruct", "umbrella");
    let input = common::examples().join("umbrella_20k.ply");
    let (r, [json, step, _]) = model_outputs(&input, &d);
    assert_eq!(r["totals"]["faces"], 8);
    assert_eq!(r["totals"]["corners"], 9);
    assert_eq!(r["totals"]["edges"], 16);
    assert_eq!(r["totals"]["closed"], false);
    assert!(r["patches"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["sides"] == 3));
    let diag = r["totals"]["diagonal"].as_f64().unwrap();
    assert!(r["totals"]["max_gap"].as_f64().unwrap() <= 1e-9 * diag);
    let text = std::fs::read_to_string(&step).unwrap();
    assert!(text.contains("OPEN_SHELL("));
    if let Some(occ) = occ_check(&json, &step) {
        assert_eq!(occ["shells"], 1);
        assert_eq!(occ["faces"], 8);
        assert_eq!(occ["valid"], true, "{occ}");
        // free edges only on the rim: the 8 rim edges
        assert_eq!(occ["free_edges"], 8, "{occ}");
        assert!(
            occ["max_face_diff"].as_f64().unwrap() < 1e-9 * diag,
            "{occ}"
        );
    }
}

#[test]
fn can_as_revolve_layout() {
    // the file's labels are replaced by 4 sectors x 2 bands and 4 three-sided
    // patches on each flat cap (closed ends, decided from the data)
    let j = can_json("revolve", &["--layout", "revolve:4x2", "--axis", "z"]);
    let t = &j["totals"];
    assert_eq!(t["faces"], 16, "{t}");
    let layout = j["layout"].as_str().unwrap();
    assert!(
        layout.contains("low end closed") && layout.contains("high end closed"),
        "{layout}"
    );
    assert_eq!(t["closed"], true);
    assert_eq!(t["corners"], 2 + 3 * 4);
    assert!(t["max_gap"].as_f64().unwrap() <= 1e-9 * t["diagonal"].as_f64().unwrap());
    let patches = j["patches"].as_array().unwrap();
    let three = patches.iter().filter(|p| p["sides"] == 3).count();
    assert_eq!(three, 8);
    for p in patches {
        let (f, n) = (
            p["fold_overs"].as_u64().unwrap(),
            p["points"].as_u64().unwrap(),
        );
        assert!(f * 200 <= n, "{p}");
    }
    // the crease at the rims costs more than the noise (sigma 0.00115)
    assert!(t["orthogonal"]["rmse"].as_f64().unwrap() < 0.01, "{t}");
}

#[test]
fn layout_values_are_checked() {
    let e = refused(
        "layout-value",
        |_, l| l.to_string(),
        &["--layout", "grid:3"],
    );
    assert!(e.contains("grid:RxC") && e.contains("revolve:SxL"), "{e}");
    let e = refused(
        "axis-alone",
        |_, l| l.to_string(),
        &["--layout", "cube", "--axis", "z"],
    );
    assert!(
        e.contains("--axis sets the axis of --layout revolve"),
        "{e}"
    );
    let e = refused(
        "two-sectors",
        |_, l| l.to_string(),
        &["--layout", "revolve:2x2", "--axis", "z"],
    );
    assert!(e.contains("3 to 360 sectors"), "{e}");
    // a grid on a closed can: no four-sided sheet
    let e = refused(
        "grid-on-can",
        |_, l| l.to_string(),
        &["--layout", "grid:2x2"],
    );
    assert!(e.contains("grid layout needs a sheet"), "{e}");
}

/// A square sheet `[0, 2]^2` on a gentle dome as `x y z label` (quarters
/// 0-3), uniform noise 0.02 wide; quarter 3 thinned to every third row and
/// column over `[1.1, 1.9]^2`, where a 12 x 12 least-squares net flies off.
fn write_sheet_with_a_sparse_quarter(path: &Path) {
    let mut noise = uniform_noise(5, 0.02);
    let n = 60;
    let mut out = String::from("x y z label\n");
    for i in 0..n {
        for j in 0..n {
            let (x, y) = ((i as f64 + 0.5) / 30.0, (j as f64 + 0.5) / 30.0);
            let l = u8::from(x > 1.0) + 2 * u8::from(y > 1.0);
            let inner = (x - 1.5).abs() < 0.4 && (y - 1.5).abs() < 0.4;
            if l == 3 && inner && (i % 3 != 0 || j % 3 != 0) {
                continue;
            }
            let z = 0.1 * (x * (2.0 - x) + y * (2.0 - y)) + noise();
            writeln!(out, "{x:.6} {y:.6} {z:.6} {l}").unwrap();
        }
    }
    std::fs::write(path, out).unwrap();
}

/// A patch that leaves its data is refused in one line naming it and the
/// fixes (as fit, mba, coons and turntable refuse theirs), nothing written;
/// `--allow-extrapolation` writes it and reports how far it left.
#[test]
fn a_patch_that_leaves_its_data_is_refused_by_name() {
    let d = tmpdir("reconstruct", "leaves");
    let input = d.join("sheet.xyz");
    write_sheet_with_a_sparse_quarter(&input);
    let model = d.join("m.json");
    let args = [
        "reconstruct",
        s(&input),
        "--fit",
        "bspline",
        "--ctrl",
        "12x12",
        "-o",
        s(&model),
        "-q",
    ];
    let o = run(&args);
    assert!(!o.status.success());
    assert!(!model.exists(), "a model was written");
    let e = String::from_utf8_lossy(&o.stderr);
    let line = e.lines().find(|l| l.contains("leaves the data")).unwrap();
    assert!(
        line.contains("patch 3: the surface leaves the data")
            && line.contains("--ctrl, now 12x12")
            && line.contains("--allow-extrapolation"),
        "{e}"
    );
    let mut allowed = args.to_vec();
    allowed.extend(["--allow-extrapolation", "--json"]);
    let j: serde_json::Value = serde_json::from_str(&ok(&run(&allowed))).unwrap();
    assert!(model.exists());
    for p in j["patches"].as_array().unwrap() {
        let (out, limit) = (
            p["outside_box"].as_f64().unwrap(),
            p["outside_box_limit"].as_f64().unwrap(),
        );
        assert_eq!(p["leaves_data"], p["id"] == 3, "{p}");
        assert_eq!(out > limit, p["id"] == 3, "{p}");
    }
}
