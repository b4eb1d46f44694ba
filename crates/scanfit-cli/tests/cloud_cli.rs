//! End-to-end tests of `scanfit cloud ...`: outputs that read back with the
//! right numbers, pictures with content, and clear errors without output
//! files for bad input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{examples, ok, run, tmpdir};

use std::path::Path;

use scanfit::Vector3;
use scanfit_io::{read_cloud, ReadOptions};

/// Runs `scanfit cloud SUB INPUT EXTRA.. -o OUT --png PNG --json`, which
/// must succeed, and returns its JSON report.
fn cloud_json(
    sub: &str,
    input: &Path,
    extra: &[&str],
    out: &Path,
    png: &Path,
) -> serde_json::Value {
    let mut args = vec!["cloud", sub, input.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend([
        "-o",
        out.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--json",
    ]);
    serde_json::from_str(&ok(&run(&args))).unwrap()
}

/// Fraction of non-white pixels and whether any touches the image border.
fn png_coverage(path: &Path) -> (f64, bool) {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    let (w, h) = (info.width as usize, info.height as usize);
    let mut ink = 0usize;
    let mut border = false;
    // skip the legend rows at the top
    for y in 40..h {
        for x in 0..w {
            let k = (y * w + x) * 3;
            if buf[k..k + 3] != [255, 255, 255] {
                ink += 1;
                if x == 0 || x == w - 1 || y == h - 1 {
                    border = true;
                }
            }
        }
    }
    (ink as f64 / (w * (h - 40)) as f64, border)
}

#[test]
fn info_reports_counts_bbox_and_spacing_as_json() {
    let input = examples().join("patch_20k.ply");
    let out = ok(&run(&["cloud", "info", input.to_str().unwrap(), "--json"]));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["points"], 20000);
    let cloud = read_cloud(&input, &ReadOptions::default())
        .unwrap()
        .into_cloud()
        .unwrap();
    let (lo, hi) = cloud.bounding_box().unwrap();
    assert_eq!(v["bbox_min"][0].as_f64().unwrap(), lo.x);
    assert_eq!(v["bbox_max"][2].as_f64().unwrap(), hi.z);
    let s = cloud.spacing().unwrap();
    assert_eq!(v["spacing"]["median"].as_f64().unwrap(), s.median);
    // the table names its units and aligns
    let table = ok(&run(&["cloud", "info", input.to_str().unwrap()]));
    assert!(table.contains("20000 points") && table.contains("nearest-neighbour distance"));
}

#[test]
fn normals_of_a_closed_body_point_outwards() {
    let d = tmpdir("cloud", "normals");
    let (out, png) = (d.join("n.ply"), d.join("n.png"));
    let input = examples().join("blob_30k.ply");
    let v = cloud_json("normals", &input, &[], &out, &png);
    assert_eq!(v["components"], 1);
    assert_eq!(v["degenerate"], 0);
    let cloud = read_cloud(&out, &ReadOptions::default())
        .unwrap()
        .into_cloud()
        .unwrap();
    assert_eq!(cloud.len(), 30000);
    let normals = cloud.normals().unwrap();
    let c = cloud
        .points()
        .iter()
        .fold(Vector3::zeros(), |a, p| a + p.coords)
        / cloud.len() as f64;
    // the blob is star-shaped about its centroid: every normal points away from it
    let inward = cloud
        .points()
        .iter()
        .zip(&normals)
        .filter(|(p, n)| (p.coords - c).dot(n) < 0.0)
        .count();
    assert_eq!(inward, 0);
    assert!(normals.iter().all(|n| (n.norm() - 1.0).abs() < 1e-12));
    assert!(cloud.attribute("variation").is_some());
    let (ink, border) = png_coverage(&png);
    assert!(
        ink > 0.2 && !border,
        "coverage {ink}, touches border {border}"
    );
}

#[test]
fn hpr_keeps_the_near_side() {
    let d = tmpdir("cloud", "hpr");
    let (out, png) = (d.join("v.xyz"), d.join("v.png"));
    let input = examples().join("blob_30k.ply");
    let v = cloud_json("hpr", &input, &["--view", "0,0,200"], &out, &png);
    let visible = v["visible"].as_u64().unwrap() as usize;
    let table = read_cloud(&out, &ReadOptions::default()).unwrap();
    assert_eq!(table.points.len(), visible);
    // a third of a convex-ish body seen from a finite distance, all on the near side
    assert!((8000..15000).contains(&visible), "{visible}");
    assert!(table.points.iter().all(|p| p.z > -5.0));
    let idx = table.column("index").unwrap();
    let all = read_cloud(&input, &ReadOptions::default()).unwrap();
    for (p, &i) in table.points.iter().zip(idx) {
        assert_eq!(*p, all.points[i as usize]);
    }
    let (ink, border) = png_coverage(&png);
    assert!(
        ink > 0.2 && !border,
        "coverage {ink}, touches border {border}"
    );
}

#[test]
fn boundary_finds_the_four_corners_of_the_panel() {
    let d = tmpdir("cloud", "boundary");
    let (json, ply, png) = (d.join("b.json"), d.join("b.ply"), d.join("b.png"));
    let input = examples().join("patch_20k.ply");
    for (out, crit) in [(&json, "angle"), (&ply, "curvature")] {
        cloud_json("boundary", &input, &["--criterion", crit], out, &png);
    }
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    // the panel has a hole: two loops, the outer one counter-clockwise
    assert_eq!(v["loops"].as_array().unwrap().len(), 2);
    let outer = v["outer"].as_u64().unwrap() as usize;
    assert!(v["loops"][outer]["area"].as_f64().unwrap() > 0.0);
    // the panel's corners (make_clouds.py: uv = (0,0), (1,0), (1,1), (0,1))
    let truth = [[0.0, 0.0], [100.0, 0.0], [100.0, 70.0], [0.0, 70.0]];
    let corners = v["corners"].as_array().unwrap();
    assert_eq!(corners.len(), 4);
    for t in truth {
        let best = corners
            .iter()
            .map(|c| {
                let p = &c["point"];
                ((p[0].as_f64().unwrap() - t[0]).powi(2) + (p[1].as_f64().unwrap() - t[1]).powi(2))
                    .sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        // within two point spacings (0.64 each) of the true corner
        assert!(best < 1.3, "corner {t:?}: nearest found {best}");
    }
    // sides share their corners and cover the loop
    let sides = v["sides"].as_array().unwrap();
    let loop_len = v["loops"][outer]["indices"].as_array().unwrap().len();
    let total: usize = sides.iter().map(|s| s.as_array().unwrap().len() - 1).sum();
    assert_eq!(total, loop_len);
    for k in 0..4 {
        let s = sides[k].as_array().unwrap();
        let next = sides[(k + 1) % 4].as_array().unwrap();
        assert_eq!(s.last(), next.first());
    }
    // the PLY loop: in order, with corner flags and side numbers
    let t = read_cloud(&ply, &ReadOptions::default()).unwrap();
    assert_eq!(t.points.len(), loop_len);
    let corner = t.column("corner").unwrap();
    assert_eq!(corner.iter().filter(|&&c| c == 1.0).count(), 4);
    // side k starts at corner k and runs to the next corner (exclusive)
    let side = t.column("side").unwrap();
    let starts: Vec<usize> = (0..loop_len).filter(|&q| corner[q] == 1.0).collect();
    for (k, &q) in starts.iter().enumerate() {
        let first = side[q];
        let end = starts.get(k + 1).copied().unwrap_or(loop_len + starts[0]);
        assert!(
            (q..end).all(|r| side[r % loop_len] == first),
            "side of corner {k}"
        );
    }
    let mut firsts: Vec<f64> = starts.iter().map(|&q| side[q]).collect();
    firsts.sort_by(f64::total_cmp);
    assert_eq!(firsts, [0.0, 1.0, 2.0, 3.0]);
    let pos = t.column("position").unwrap();
    assert!(pos.iter().enumerate().all(|(k, &p)| p == k as f64));
    let (ink, border) = png_coverage(&png);
    assert!(
        ink > 0.2 && !border,
        "coverage {ink}, touches border {border}"
    );
}

/// `--corners 0` asks for the loops only: the JSON document holds empty
/// corner and side lists (it was refused for the null they were).
#[test]
fn boundary_without_corners_writes_empty_lists() {
    let d = tmpdir("cloud", "boundary_no_corners");
    let (json, png) = (d.join("b.json"), d.join("b.png"));
    let input = examples().join("patch_20k.ply");
    cloud_json("boundary", &input, &["--corners", "0"], &json, &png);
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(v["loops"].as_array().unwrap().len(), 2);
    assert_eq!(v["corners"].as_array().map(Vec::len), Some(0));
    assert_eq!(v["sides"].as_array().map(Vec::len), Some(0));
}

#[test]
fn cloud_commands_reject_bad_input_without_writing() {
    let d = tmpdir("cloud", "bad");
    let out = d.join("o.ply");
    let nan = d.join("nan.xyz");
    std::fs::write(&nan, "0 0 0\n1 0 0\nnan 1 0\n0 1 1\n1 1 1\n").unwrap();
    let trunc = d.join("trunc.ply");
    let mut bytes = std::fs::read(examples().join("patch_20k.ply")).unwrap();
    bytes.truncate(bytes.len() - 100);
    std::fs::write(&trunc, bytes).unwrap();
    let line = d.join("line.xyz");
    std::fs::write(&line, "0 0 0\n1 0 0\n2 0 0\n3 0 0\n4 0 0\n").unwrap();
    let blob = examples().join("blob_30k.ply");
    let stl = d.join("o.stl");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["info", "/no/such/file.ply"], "No such file"),
        (vec!["info", nan.to_str().unwrap()], "nan.xyz:3"),
        (vec!["info", trunc.to_str().unwrap()], "byte offset"),
        (
            vec![
                "normals",
                blob.to_str().unwrap(),
                "--k",
                "1",
                "-o",
                out.to_str().unwrap(),
            ],
            "k >= 2",
        ),
        (
            vec!["normals", blob.to_str().unwrap(), "--orient", "sideways"],
            "unknown --orient",
        ),
        (
            vec![
                "hpr",
                blob.to_str().unwrap(),
                "--view",
                "1,2",
                "-o",
                out.to_str().unwrap(),
            ],
            "three finite numbers",
        ),
        (
            vec![
                "hpr",
                line.to_str().unwrap(),
                "--view",
                "0,5,0",
                "-o",
                out.to_str().unwrap(),
            ],
            "hidden point removal",
        ),
        (
            vec![
                "boundary",
                line.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ],
            "boundary of",
        ),
        (
            vec![
                "boundary",
                blob.to_str().unwrap(),
                "-o",
                stl.to_str().unwrap(),
            ],
            "must end in .json or .ply or .xyz",
        ),
        (
            vec!["boundary", blob.to_str().unwrap(), "--criterion", "pointy"],
            "unknown --criterion",
        ),
        (
            vec!["info", blob.to_str().unwrap(), "--format", "e57"],
            "unknown --format",
        ),
    ];
    for (args, needle) in cases {
        let mut full = vec!["cloud"];
        full.extend(&args);
        let o = run(&full);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: '{needle}' not in {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote output");
    }
    // the documented way around non-finite values
    let o = run(&[
        "cloud",
        "info",
        nan.to_str().unwrap(),
        "--drop-non-finite",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(
        (v["points"].as_u64(), v["dropped_non_finite"].as_u64()),
        (Some(4), Some(1))
    );
}

#[test]
fn cloud_help_has_examples() {
    for sub in ["info", "normals", "hpr", "boundary"] {
        let o = run(&["cloud", sub, "--help"]);
        assert!(ok(&o).contains("Examples:"), "{sub}");
    }
}
