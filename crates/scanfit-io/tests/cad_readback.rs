//! CAD files read back by a real CAD kernel: OpenCASCADE (the cadquery-ocp
//! wheel) loads the STEP and IGES files and its surfaces and curves must evaluate equal
//! to scanfit's at sample parameters to 1e-9 (`tests/occ/check_cad.py`).
//! Without OpenCASCADE the test says so loudly; with `SCANFIT_REQUIRE_OCC=1`
//! (set by CI, which installs it) a missing OpenCASCADE is a failure.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use scanfit::bspline::{Curve, KnotVector, Surface};
use scanfit::Point3;
use scanfit_io::iges::iges_file;
use scanfit_io::step::{step_file, CadItem};

#[path = "support/occ.rs"]
mod occ;

fn surfaces() -> (Surface, Surface) {
    let ku = KnotVector::new(vec![0., 0., 0., 0., 0.3, 0.55, 1., 1., 1., 1.], 3).unwrap();
    let kv = KnotVector::new(vec![0., 0., 0., 0.4, 1., 1., 1.], 2).unwrap();
    let mut c = Vec::new();
    let mut w = Vec::new();
    for i in 0..6 {
        for j in 0..4 {
            let (x, y) = (i as f64 * 1.7, j as f64 * 2.3);
            c.push(Point3::new(
                x + 0.2 * y,
                y,
                (x * 0.4).sin() * 3.0 + 0.1 * x * y,
            ));
            w.push(1.0 + 0.3 * ((i + 2 * j) % 3) as f64);
        }
    }
    let plain = Surface::new(ku.clone(), kv.clone(), c.clone()).unwrap();
    let moved: Vec<Point3> = c
        .iter()
        .map(|p| p + nalgebra::Vector3::new(20.0, 0.0, 0.0))
        .collect();
    let rational = Surface::with_options(ku, kv, moved, Some(w), false, false).unwrap();
    (plain, rational)
}

fn curve() -> Curve {
    let kv = KnotVector::new(vec![0., 0., 0., 0., 0.25, 0.7, 1., 1., 1., 1.], 3).unwrap();
    let c = (0..6)
        .map(|k| Point3::new(k as f64, (k as f64 * 1.1).cos(), -2.0))
        .collect();
    Curve::new(kv, c).unwrap()
}

/// A cylinder-like surface periodic in u, and a closed periodic curve.
fn periodic_items() -> (Surface, Curve) {
    let p = 3;
    let nd = 8;
    let ku = KnotVector::uniform_periodic(p, nd).unwrap();
    let kv = KnotVector::uniform_clamped(2, 4).unwrap();
    let mut c = Vec::new();
    for i in 0..nd + p {
        let a = (i % nd) as f64 / nd as f64 * std::f64::consts::TAU;
        for j in 0..4 {
            c.push(Point3::new(
                40.0 + a.cos() * (2.0 + 0.1 * j as f64),
                a.sin(),
                j as f64,
            ));
        }
    }
    let s = Surface::with_options(ku, kv, c, None, true, false).unwrap();
    let kc = KnotVector::uniform_periodic(3, 6).unwrap();
    let mut q: Vec<Point3> = (0..6)
        .map(|k| {
            let a = k as f64 / 6.0 * std::f64::consts::TAU;
            Point3::new(a.cos() * 3.0, 10.0 + a.sin(), 0.5)
        })
        .collect();
    for j in 0..3 {
        q.push(q[j]);
    }
    (s, Curve::new_periodic(kc, q, None).unwrap())
}

#[test]
fn step_and_iges_read_back_by_opencascade() {
    let dir = std::env::temp_dir().join(format!("scanfit-cad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (s1, s2) = surfaces();
    let c = curve();
    let (s3, c2) = periodic_items();
    let items = [
        CadItem::Surface(&s1),
        CadItem::Surface(&s2),
        CadItem::Surface(&s3),
        CadItem::Curve(&c),
        CadItem::Curve(&c2),
    ];
    let text = step_file(&items, "scanfit test").unwrap();
    // structural checks that need no CAD kernel
    assert!(text.starts_with("ISO-10303-21;") && text.ends_with("END-ISO-10303-21;\n"));
    assert_eq!(text.matches("ADVANCED_FACE(").count(), 3);
    assert_eq!(text.matches("RATIONAL_B_SPLINE_SURFACE(").count(), 1);
    let step = dir.join("t.stp");
    std::fs::write(&step, &text).unwrap();
    let iges = dir.join("t.igs");
    std::fs::write(&iges, iges_file(&items, "scanfit test").unwrap()).unwrap();
    let mut samples = serde_json::json!({"surfaces": [], "curves": []});
    for s in [&s1, &s2, &s3] {
        let pts: Vec<[f64; 5]> = (0..=6)
            .flat_map(|i| (0..=6).map(move |j| (i as f64 / 6.0, j as f64 / 6.0)))
            .map(|(u, v)| {
                let p = s.point(u, v);
                [u, v, p.x, p.y, p.z]
            })
            .collect();
        samples["surfaces"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!(pts));
    }
    for cc in [&c, &c2] {
        let cp: Vec<[f64; 4]> = (0..=20)
            .map(|k| {
                let t = k as f64 / 20.0;
                let p = cc.point(t);
                [t, p.x, p.y, p.z]
            })
            .collect();
        samples["curves"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!(cp));
    }
    let sp = dir.join("samples.json");
    std::fs::write(&sp, samples.to_string()).unwrap();
    // the checks OpenCASCADE would make: every sample of every item, in each
    // of the two files
    let files = 2;
    let surface_samples: usize = samples["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_array().unwrap().len())
        .sum();
    let curve_samples: usize = samples["curves"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_array().unwrap().len())
        .sum();
    let occ_checks = files * (surface_samples + curve_samples + 2);
    let skipped = format!(
        "{occ_checks} of the {} checks of this test: the read-back by a CAD kernel of\n\
         {files} files x ({surface_samples} surface + {curve_samples} curve samples + 2 entity counts).\n\
         Only the 3 structural checks of the STEP text ran.",
        occ_checks + 3
    );
    if occ::missing(&skipped) {
        return;
    }
    let out = occ::run("check_cad.py", &[&sp, &step, &iges], "CAD read-back");
    assert_eq!(out.matches("3 faces, 2 curves").count(), 2, "{out}");
    std::fs::remove_dir_all(&dir).ok();
}
