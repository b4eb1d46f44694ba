//! OpenCASCADE read-backs shared by the CAD tests (`cad_readback.rs`,
//! `layouts.rs`, `model_readback.rs`, `trim_units_readback.rs`): whether the
//! kernel is installed (its Python binding `OCP`, the cadquery-ocp wheel),
//! a loud notice of what was skipped when it is not (a failure when
//! `SCANFIT_REQUIRE_OCC` is set, as in CI, which installs it), and one run
//! of a check script of `tests/occ/`.
#![allow(dead_code)]

use std::io::Write;
use std::path::Path;
use std::process::Command;

/// Whether OpenCASCADE's Python binding can be imported.
pub fn available() -> bool {
    Command::new("python3")
        .args(["-c", "import OCP"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// Whether OpenCASCADE is missing. When it is, says what was `skipped`
/// (lines of text) on the process's stderr, not with `eprintln!`: the test
/// harness captures, and hides, the macros' output of a passing test. With
/// `SCANFIT_REQUIRE_OCC` set, a missing OpenCASCADE fails the test.
pub fn missing(skipped: &str) -> bool {
    if available() {
        return false;
    }
    let stars = "*".repeat(72);
    let lines = skipped.replace('\n', "\n* ");
    let msg = format!(
        "\n{stars}\n* OpenCASCADE (pip install cadquery-ocp) is NOT installed.\n* SKIPPED: {lines}\n{stars}\n"
    );
    std::io::stderr().write_all(msg.as_bytes()).ok();
    assert!(
        std::env::var_os("SCANFIT_REQUIRE_OCC").is_none(),
        "SCANFIT_REQUIRE_OCC is set but OpenCASCADE is missing (skipped: {skipped})"
    );
    true
}

/// Runs `tests/occ/SCRIPT` on `args` and prints its output under `what`;
/// fails the test (with that output) when the script fails. Returns its
/// standard output.
pub fn run(script: &str, args: &[&Path], what: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/occ")
        .join(script);
    let o = Command::new("python3")
        .arg(path)
        .args(args)
        .output()
        .expect("python3 runs");
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{what}: {out}{err}");
    assert!(
        o.status.success(),
        "{what}: OpenCASCADE ({script}) disagrees or failed:\n{out}\n{err}"
    );
    out
}
