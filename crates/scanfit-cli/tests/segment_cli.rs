//! End-to-end tests of `scanfit cloud segment` and `scanfit reconstruct
//! --segment | --layout cube` on the shipped samples (issue 16).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{ok, run, tmpdir};

use std::path::{Path, PathBuf};

fn sample(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/data")
        .join(file)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn segment_writes_editable_labels_that_reconstruct_reads_back() {
    let d = tmpdir("segment", "part");
    let (out, png) = (d.join("labelled.ply"), d.join("segments.png"));
    let part = sample("part_30k.ply");
    let o = run(&[
        "cloud",
        "segment",
        s(&part),
        "-o",
        s(&out),
        "--png",
        s(&png),
        "--json",
        "-q",
    ]);
    let r: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(r["regions"].as_array().unwrap().len(), 8, "{r}");
    let total: u64 = r["regions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["points"].as_u64().unwrap())
        .sum();
    assert_eq!(total, 30_000);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    // the labelled file: the input's columns plus label and edge
    let info = ok(&run(&["cloud", "info", s(&out), "--json"]));
    let info: serde_json::Value = serde_json::from_str(&info).unwrap();
    let names: Vec<&str> = info["attributes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"true_face") && names.contains(&"label") && names.contains(&"edge"),
        "{names:?}"
    );
    // reconstruct reads the labels back: the 8 faces are its 8 patches
    let o = run(&["reconstruct", s(&out), "--json", "-q"]);
    let rec: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(rec["labels"], "label");
    assert_eq!(rec["totals"]["faces"], 8, "{}", rec["totals"]);
    // and so does reconstruct --segment, without the file
    let o = run(&["reconstruct", s(&part), "--segment", "--json", "-q"]);
    let seg: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(seg["totals"]["faces"], 8);
    assert_eq!(seg["totals"]["closed"], true);
}

#[test]
fn smooth_object_is_refused_for_segmentation_with_advice() {
    let d = tmpdir("segment", "smooth");
    let out = d.join("labelled.ply");
    let o = run(&[
        "cloud",
        "segment",
        s(&sample("blob_30k.ply")),
        "-o",
        s(&out),
        "-q",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--layout cube"), "{err}");
    assert!(!out.exists(), "no output after an error");
}

#[test]
fn layout_cube_gives_a_closed_shell_of_six_patches() {
    let d = tmpdir("segment", "cube");
    let step = d.join("blob.stp");
    let o = run(&[
        "reconstruct",
        s(&sample("blob_30k.ply")),
        "--layout",
        "cube",
        "--step",
        s(&step),
        "--json",
        "-q",
    ]);
    let r: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    assert_eq!(r["totals"]["faces"], 6);
    assert_eq!(r["totals"]["edges"], 12);
    assert_eq!(r["totals"]["corners"], 8);
    assert_eq!(r["totals"]["closed"], true);
    assert!(r["patches"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["sides"] == 4));
    let text = std::fs::read_to_string(&step).unwrap();
    assert!(text.contains("CLOSED_SHELL("));
    // --segment and --layout exclude each other
    let o = run(&[
        "reconstruct",
        s(&sample("blob_30k.ply")),
        "--layout",
        "cube",
        "--segment",
    ]);
    assert!(!o.status.success());
}
