//! The surface-to-points measures of a trimmed face cover the face, not its
//! parameter rectangle: a dome sampled on a disc (made here), whose fitted
//! rectangle's corners run far from the data, through `fit` (trimmed by
//! default with plane parameters) and `report` of the saved surface with
//! and without its `trim` section.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::Path;

use common::{ok, run, tmpdir};
use serde_json::Value;

/// A dome z = 8 (1 - r^2) over the disc of radius 9.7 on a grid of step
/// 1/3 (2661 points).
fn dome(path: &Path) {
    let mut s = String::new();
    for i in 0..=60 {
        for j in 0..=60 {
            let (x, y) = (-1.0 + i as f64 / 30.0, -1.0 + j as f64 / 30.0);
            let r2 = x * x + y * y;
            if r2 < 0.97 * 0.97 {
                s.push_str(&format!("{} {} {}\n", 10.0 * x, 10.0 * y, 8.0 * (1.0 - r2)));
            }
        }
    }
    std::fs::write(path, s).unwrap();
}

fn json(args: &[&str]) -> Value {
    serde_json::from_str(&ok(&run(args))).unwrap()
}

/// (max sample distance, share beyond 3 spacings, samples outside the box)
/// in point spacings, and the sample count.
fn samples(v: &Value) -> (f64, f64, f64, u64) {
    let s = &v["samples_to_points"];
    let spacing = s["point_spacing"].as_f64().unwrap();
    assert!(spacing > 0.3 && spacing < 0.4, "{s}");
    (
        s["max"].as_f64().unwrap() / spacing,
        s["far_share"].as_f64().unwrap(),
        s["outside_box"].as_f64().unwrap() / spacing,
        s["samples"].as_u64().unwrap(),
    )
}

#[test]
fn fit_and_report_measure_the_trimmed_face_only() {
    let d = tmpdir("trimmed-measure", "dome");
    let input = d.join("dome.xyz");
    dome(&input);
    let p = |f: &str| d.join(f).to_str().unwrap().to_string();
    let (inp, surf) = (p("dome.xyz"), p("dome.json"));
    // fit: trimmed by default; on the face every sample is within about a
    // spacing of the data
    let f = json(&["fit", &inp, "-o", &surf, "--json", "-q"]);
    assert_eq!(f["trim"]["trimmed"], true);
    let (max, far, out, n) = samples(&f);
    assert!(max < 1.5 && far == 0.0 && out < 0.5, "{f}");
    // untrimmed, the rectangle's corners are 20 spacings from the data
    let u = json(&[
        "fit",
        &inp,
        "--no-trim",
        "-o",
        &p("rect.json"),
        "--json",
        "-q",
    ]);
    let (umax, ufar, uout, un) = samples(&u);
    assert!(umax > 15.0 && ufar > 0.1 && uout > 10.0, "{u}");
    // the face's samples are the rectangle's inside the outline (about
    // pi/4 of them) plus the outline's crossings of the grid lines
    let share = n as f64 / un as f64;
    assert!(share > 0.75 && share < 0.92, "{share}");
    // report of the saved trimmed surface measures the face ...
    let r = json(&["report", &surf, &inp, "-o", &p("r.html"), "--json", "-q"]);
    assert_eq!(r["trim"]["trimmed"], true);
    let (rmax, rfar, _, rn) = samples(&r);
    assert!(rmax < 1.5 && rfar == 0.0, "{r}");
    assert_eq!(rn, n);
    // ... and the same surface without its "trim" section the rectangle
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&surf).unwrap()).unwrap();
    doc.as_object_mut().unwrap().remove("trim").unwrap();
    let bare = p("bare.json");
    std::fs::write(&bare, doc.to_string()).unwrap();
    let b = json(&["report", &bare, &inp, "-o", &p("b.html"), "--json", "-q"]);
    assert_eq!(b["trim"]["trimmed"], false);
    let (bmax, bfar, _, bn) = samples(&b);
    assert!(bmax > 15.0 && bfar > 0.1, "{b}");
    assert_eq!(bn, un);
    // the text report says where the samples were taken
    let text = ok(&run(&["report", &surf, &inp, "-o", &p("t.html"), "-q"]));
    assert!(text.contains("samples on the trimmed face"), "{text}");
    std::fs::remove_dir_all(&d).ok();
}
