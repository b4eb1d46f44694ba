//! The commands refuse, before any work, an output given twice and an
//! output that is its own input, and leaves the files as they were.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::fs;

use common::{examples, run, tmpdir};

/// Runs `args`, expects exit 1 with `needle` in the message, and checks that
/// `untouched` still holds `before`.
fn refused(args: &[&str], needle: &str, untouched: &std::path::Path, before: &[u8]) {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: {err}");
    assert_eq!(
        fs::read(untouched).unwrap(),
        before,
        "{args:?} changed a file"
    );
}

#[test]
fn an_output_equal_to_the_input_is_refused_by_the_point_commands() {
    let dir = tmpdir("output_paths", "same_as_input");
    let ply = dir.join("patch.ply");
    fs::copy(examples().join("patch_20k.ply"), &ply).unwrap();
    let p = ply.to_str().unwrap();
    let ply_bytes = fs::read(&ply).unwrap();
    let same = dir.join(".").join("patch.ply");
    let s = same.to_str().unwrap();
    for args in [
        vec!["cloud", "normals", p, "-o", s, "-q"],
        vec!["cloud", "hpr", p, "--view", "0,0,200", "-o", s, "-q"],
        vec!["cloud", "boundary", p, "-o", s, "-q"],
        vec!["fit", p, "--points-out", s, "-q"],
        vec!["coons", p, "--points-out", s, "-q"],
    ] {
        refused(&args, "is the input", &ply, &ply_bytes);
    }
}

#[test]
fn an_output_given_twice_is_refused_before_any_work() {
    let dir = tmpdir("output_paths", "twice");
    let png = dir.join("a.png");
    fs::write(&png, b"old").unwrap();
    let p = png.to_str().unwrap();
    let again = dir.join(".").join("a.png");
    let a = again.to_str().unwrap();
    let terrain = examples().join("terrain_50k.xyz");
    let t = terrain.to_str().unwrap();
    refused(
        &[
            "fit",
            t,
            "--ctrl",
            "8x8",
            "--png",
            p,
            "--deviation-png",
            a,
            "-q",
        ],
        "given twice",
        &png,
        b"old",
    );
    refused(
        &[
            "mba",
            t,
            "--levels",
            "2",
            "--png",
            p,
            "--deviation-png",
            a,
            "-q",
        ],
        "given twice",
        &png,
        b"old",
    );
}
