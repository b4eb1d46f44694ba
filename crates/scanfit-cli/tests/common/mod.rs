//! Helpers shared by the end-to-end tests of the `scanfit` binary.

#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The shipped sample data (`examples/data`).
pub fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data")
}

/// A fresh, empty temporary directory for one test (`suite` keeps the test
/// files apart, the process id keeps parallel runs apart).
pub fn tmpdir(suite: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("scanfit-{suite}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the binary with `args`.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scanfit"))
        .args(args)
        .output()
        .unwrap()
}

/// The stdout of a run that must have succeeded (its stderr otherwise).
pub fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Franke's function (relief 1.2) on `n` seeded uniform points of the unit
/// square ([`scanfit::testdata::scattered`], seed 29), written to `path` as
/// `x y z` text (shortest round-trip numbers: read back exactly). Its
/// best-fit plane is tilted and folds the bumps over.
pub fn write_franke_xyz(path: &Path, n: usize) {
    let pts = scanfit::testdata::scattered(n, 29, [0.0, 0.0, 1.0, 1.0], scanfit::testdata::franke);
    let text: String = pts
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(path, text).unwrap();
}
