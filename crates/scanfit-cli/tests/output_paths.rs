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

/// Every command that reads points, with a point input `P` and the
/// `-o`-like output it writes (a wrong extension is refused before any
/// work, after clap has taken every other option).
const COMMANDS: &[(&[&str], &str)] = &[
    (&["fit", "P"], "-o"),
    (&["mba", "P"], "-o"),
    (&["coons", "P"], "-o"),
    (&["turntable", "P"], "-o"),
    (&["reconstruct", "P"], "-o"),
    (&["report", "S", "P"], "-o"),
    (&["curve", "fit", "P"], "-o"),
    (&["curve", "compare", "P"], "-o"),
    (&["cloud", "normals", "P"], "-o"),
    (&["cloud", "hpr", "P", "--view", "0,0,9"], "-o"),
    (&["cloud", "boundary", "P"], "-o"),
    (&["cloud", "clean", "P", "--outliers"], "-o"),
    (&["cloud", "segment", "P"], "-o"),
];

/// Runs `args`, expecting exit 1 and "must end in" (the output check), so
/// clap accepted everything else.
fn parsed_then_refused(args: &[&str]) {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(err.contains("must end in"), "{args:?}: {err}");
}

#[test]
fn every_point_command_takes_format_and_drop_non_finite_and_checks_its_output() {
    let dir = tmpdir("output_paths", "every_command");
    let pts = dir.join("p.xyz");
    fs::write(&pts, "0 0 0\n1 0 0\n0 1 1\n").unwrap();
    let surf = dir.join("s.json");
    fs::write(&surf, "{}").unwrap();
    let bad = dir.join("out.foo");
    for (cmd, out) in COMMANDS {
        let mut args: Vec<&str> = cmd
            .iter()
            .map(|a| match *a {
                "P" => pts.to_str().unwrap(),
                "S" => surf.to_str().unwrap(),
                a => a,
            })
            .collect();
        args.extend([
            "--format",
            "text",
            "--drop-non-finite",
            out,
            bad.to_str().unwrap(),
        ]);
        parsed_then_refused(&args);
        assert!(!bad.exists());
    }
    // the other outputs of every command: the extension is checked as well
    let p = pts.to_str().unwrap();
    let b = bad.to_str().unwrap();
    for args in [
        vec!["fit", p, "--step", b],
        vec!["mba", p, "--iges", b],
        vec!["coons", p, "--mesh", b],
        vec!["turntable", p, "--png", b],
        vec!["reconstruct", p, "--deviation-png", b],
        vec!["fit", p, "--points-out", b],
        vec!["curve", "fit", p, "--svg", b],
        vec!["curve", "fit", p, "--step", b],
        vec!["curve", "compare", p, "--png", b],
        vec!["cloud", "boundary", p, "--png", b],
        vec!["cloud", "segment", p, "--png", b],
        vec!["export", surf.to_str().unwrap(), "--step", b],
        vec!["export", surf.to_str().unwrap(), "--iges", b],
    ] {
        parsed_then_refused(&args);
    }
}

#[test]
fn negative_numbers_are_taken_by_every_vector_option() {
    // each vector option with a leading minus, as the help shows it (no `=`)
    let dir = tmpdir("output_paths", "negative_vectors");
    let pts = dir.join("p.xyz");
    fs::write(&pts, "0 0 0\n1 0 0\n0 1 1\n").unwrap();
    let (p, b) = (pts.to_str().unwrap(), dir.join("o.foo"));
    let b = b.to_str().unwrap();
    for args in [
        vec!["fit", p, "--view", "-60,-35"],
        vec!["mba", p, "--view", "-60,35"],
        vec!["coons", p, "--view", "-1,-2"],
        vec![
            "turntable",
            p,
            "--axis",
            "-0.34,-0.5,0.8",
            "--view",
            "-60,35",
        ],
        vec!["reconstruct", p, "--view", "-60,35"],
        vec!["curve", "fit", p, "--end-tangents", "-1,0,0;0,-1,0"],
        vec![
            "cloud", "normals", p, "--hint", "-1,-1,-1", "--view", "-10,-5",
        ],
        vec![
            "cloud", "hpr", p, "--view", "-5,-5,-9", "--camera", "-60,-20",
        ],
        vec!["cloud", "boundary", p, "--view", "-60,35"],
        vec![
            "cloud",
            "clean",
            p,
            "--box",
            "-1,-1,-1,1,1,1",
            "--sphere",
            "-1,-2,-3,4",
        ],
        vec!["cloud", "segment", p, "--view", "-60,35"],
    ] {
        let mut a = args.clone();
        a.extend(["-o", b]);
        parsed_then_refused(&a);
    }
}

#[test]
fn every_command_with_two_outputs_of_one_kind_refuses_one_path_for_both() {
    let dir = tmpdir("output_paths", "twice_every");
    let pts = dir.join("p.xyz");
    fs::write(&pts, "0 0 0\n1 0 0\n0 1 1\n").unwrap();
    let p = pts.to_str().unwrap();
    let (a, b) = (dir.join("a.png"), dir.join(".").join("a.png"));
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    for cmd in [
        vec!["fit", p],
        vec!["mba", p],
        vec!["coons", p],
        vec!["turntable", p],
        vec!["reconstruct", p],
    ] {
        let mut args = cmd.clone();
        args.extend(["--png", a, "--deviation-png", b]);
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("given twice"), "{args:?}: {err}");
    }
}
