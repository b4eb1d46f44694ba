//! Deterministic parallelism end to end: every pipeline run with
//! `--threads 1` and `--threads 2` writes byte-identical files (the library
//! sums normal equations and lattices over fixed chunks merged in a fixed
//! order, `scanfit::par`). Files rather than stdout are compared: the reports
//! carry wall times.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::Path;

use common::{examples, ok, run, tmpdir};

/// Runs `args` once per thread count (`{in}` in an argument is replaced by
/// `examples/data/<input>`, `{out}` by the run's own directory), and asserts
/// that the files named in `outputs` are equal byte for byte and not empty.
fn same_bytes(name: &str, input: &str, args: &[&str], outputs: &[&str]) {
    let d = tmpdir("threads", name);
    let input = examples().join(input);
    let dirs: Vec<_> = ["1", "2"]
        .iter()
        .map(|t| {
            let dir = d.join(format!("t{t}"));
            std::fs::create_dir_all(&dir).unwrap();
            let mut a: Vec<String> = vec!["--threads".into(), (*t).into()];
            a.extend(args.iter().map(|x| {
                x.replace("{in}", input.to_str().unwrap())
                    .replace("{out}", dir.to_str().unwrap())
            }));
            let refs: Vec<&str> = a.iter().map(String::as_str).collect();
            ok(&run(&refs));
            dir
        })
        .collect();
    for f in outputs {
        let read = |dir: &Path| std::fs::read(dir.join(f)).unwrap();
        let (one, two) = (read(&dirs[0]), read(&dirs[1]));
        assert!(!one.is_empty(), "{name}: {f} is empty");
        assert!(
            one == two,
            "{name}: {f} differs between --threads 1 and --threads 2 ({} vs {} bytes)",
            one.len(),
            two.len()
        );
    }
}

#[test]
fn curve_fit_is_bit_identical() {
    same_bytes(
        "curve",
        "dataset6.csv",
        &[
            "curve",
            "fit",
            "{in}",
            "--quiet",
            "--ctrl",
            "20",
            "-o",
            "{out}/c.json",
        ],
        &["c.json"],
    );
}

#[test]
fn surface_fit_is_bit_identical() {
    // 50 000 points: several assembly chunks, merged in parallel
    same_bytes(
        "fit",
        "terrain_50k.xyz",
        &[
            "fit",
            "{in}",
            "--quiet",
            "--ctrl",
            "40x40",
            "-o",
            "{out}/s.json",
            "--points-out",
            "{out}/p.ply",
        ],
        &["s.json", "p.ply"],
    );
}

#[test]
fn mba_with_adjustment_is_bit_identical() {
    same_bytes(
        "mba",
        "terrain_50k.xyz",
        &[
            "mba",
            "{in}",
            "--quiet",
            "--levels",
            "6",
            "--adjust",
            "-o",
            "{out}/m.json",
        ],
        &["m.json"],
    );
}

#[test]
fn coons_pde_is_bit_identical() {
    same_bytes(
        "coons",
        "patch_20k.ply",
        &[
            "coons",
            "{in}",
            "--quiet",
            "--pde",
            "5x5",
            "-o",
            "{out}/c.json",
            "--points-out",
            "{out}/p.ply",
        ],
        &["c.json", "p.ply"],
    );
}

#[test]
fn turntable_is_bit_identical() {
    same_bytes(
        "turntable",
        "bottle_12k.ply",
        &[
            "turntable",
            "{in}",
            "--quiet",
            "-o",
            "{out}/t.json",
            "--points-out",
            "{out}/p.ply",
        ],
        &["t.json", "p.ply"],
    );
}

#[test]
fn cloud_normals_are_bit_identical() {
    same_bytes(
        "normals",
        "blob_30k.ply",
        &["cloud", "normals", "{in}", "--quiet", "-o", "{out}/n.ply"],
        &["n.ply"],
    );
}
