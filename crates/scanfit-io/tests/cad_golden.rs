//! Golden STEP and IGES files: the smallest curve and surface (a straight
//! line of degree 1, a bilinear patch of degree 1 x 1, and a rational
//! quarter circle), written and compared with files under
//! `tests/data/cad/` that were checked by hand against ISO 10303-42/-21
//! and IGES 5.3 (see `tests/data/cad/README.md` for what was checked).
//! `SCANFIT_BLESS=1 cargo test -p scanfit-io --test cad_golden` rewrites them
//! (then check them by hand again).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use scanfit::bspline::{Curve, KnotVector, Surface};
use scanfit::Point3;
use scanfit_io::iges::iges_file;
use scanfit_io::step::{step_file, CadItem};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/cad")
}

/// The file with the tool version replaced, so a release does not break the test.
fn normalise(s: &str) -> String {
    s.replace(env!("CARGO_PKG_VERSION"), "VERSION")
}

fn check(name: &str, text: &str) {
    let path = dir().join(name);
    let text = normalise(text);
    if std::env::var_os("SCANFIT_BLESS").is_some() {
        std::fs::write(&path, &text).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}; run with SCANFIT_BLESS=1 once", path.display()));
    assert_eq!(text, want, "{name} differs from the golden file");
}

fn line() -> Curve {
    Curve::new(
        KnotVector::new(vec![0.0, 0.0, 1.0, 1.0], 1).unwrap(),
        vec![Point3::new(0.0, 0.0, 0.0), Point3::new(10.0, 0.0, 0.0)],
    )
    .unwrap()
}

fn patch() -> Surface {
    let k = KnotVector::new(vec![0.0, 0.0, 1.0, 1.0], 1).unwrap();
    Surface::new(
        k.clone(),
        k,
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(0.0, 5.0, 0.0),
            Point3::new(10.0, 0.0, 0.0),
            Point3::new(10.0, 5.0, 2.0),
        ],
    )
    .unwrap()
}

fn quarter_circle() -> Curve {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    Curve::new_rational(
        KnotVector::new(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], 2).unwrap(),
        vec![
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        vec![1.0, w, 1.0],
    )
    .unwrap()
}

#[test]
fn step_line_and_patch_match_the_golden_files() {
    let (l, p, q) = (line(), patch(), quarter_circle());
    check(
        "line.stp",
        &step_file(&[CadItem::Curve(&l)], "line").unwrap(),
    );
    check(
        "patch.stp",
        &step_file(&[CadItem::Surface(&p)], "patch").unwrap(),
    );
    check(
        "quarter_circle.stp",
        &step_file(&[CadItem::Curve(&q)], "quarter_circle").unwrap(),
    );
    // several items in one file (a multi-patch result)
    check(
        "line_and_patch.stp",
        &step_file(&[CadItem::Curve(&l), CadItem::Surface(&p)], "both").unwrap(),
    );
}

#[test]
fn iges_line_and_patch_match_the_golden_files() {
    let (l, p, q) = (line(), patch(), quarter_circle());
    check(
        "line.igs",
        &iges_file(&[CadItem::Curve(&l)], "line").unwrap(),
    );
    check(
        "patch.igs",
        &iges_file(&[CadItem::Surface(&p)], "patch").unwrap(),
    );
    check(
        "quarter_circle.igs",
        &iges_file(&[CadItem::Curve(&q)], "quarter_circle").unwrap(),
    );
    check(
        "line_and_patch.igs",
        &iges_file(&[CadItem::Curve(&l), CadItem::Surface(&p)], "both").unwrap(),
    );
}
