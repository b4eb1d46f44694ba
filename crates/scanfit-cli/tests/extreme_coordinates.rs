//! Issue 14 item 6: results far from the origin equal those at the origin,
//! and no JSON output holds a `null` or a non-finite number.
//!
//! Each pipeline runs on a shipped sample moved by `o` = 1e6, 1e10 and 1e15
//! in x, y and z (`P = fl(S + o)`), and at the origin on the same data moved
//! back (`S' = P - o`, exact by Sterbenz's lemma): the two inputs carry
//! exactly the same information, so the outputs must agree to rounding.
//! Asserted bound on every control point (of the surface, curve or model
//! document written with `-o`):
//!
//! `|(c_P - o) - c_S'| <= 1e-9 * diagonal + |o| * eps`
//!
//! (rounding of the computation at the data's own scale, plus moving the
//! result back, which rounds at the input's own resolution: `|o| eps` is
//! 0.22 at 1e15, where a double resolves 0.125; the measured differences
//! are half a unit in the last place of `o`, 0.0625 at 1e15). And where the
//! origin run has no unconverged point inversions, the far one has none
//! either.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data")
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("scanfit-extreme-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `sample` moved by `shift` as CSV (shortest round-trip numbers,
/// extra columns kept); returns the path and the diagonal.
fn write_shifted(sample: &str, offset: f64, back: bool, out: &Path) -> f64 {
    let t = scanfit_io::read_points(&examples().join(sample)).unwrap();
    let mut text = t.columns.join(",") + "\n";
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (i, p) in t.points.iter().enumerate() {
        let mut row = Vec::new();
        for k in 0..3 {
            let far = p[k] + offset;
            // S' = fl(S + o) - o is exact (Sterbenz), the origin twin of P
            let v = if back { far - offset } else { far };
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
            row.push(format!("{v:?}"));
        }
        for c in &t.extra {
            row.push(format!("{:?}", c[i]));
        }
        text += &(row.join(",") + "\n");
    }
    std::fs::write(out, text).unwrap();
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// Every control point below `v`, model space into `space` and the trim
/// loops' parameter-space curves (`uv`, which do not move with the data)
/// into `uv`.
fn collect_control_points(v: &Value, space: &mut Vec<[f64; 3]>, uv: &mut Vec<[f64; 3]>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                if k == "control_points" {
                    if let Value::Array(rows) = x {
                        for r in rows {
                            if let Some(a) = r.as_array().filter(|a| a.len() == 3) {
                                space.push([0, 1, 2].map(|j| a[j].as_f64().unwrap()));
                            }
                        }
                    }
                } else if k == "uv" {
                    collect_control_points(x, uv, &mut Vec::new());
                } else {
                    collect_control_points(x, space, uv);
                }
            }
        }
        Value::Array(a) => a.iter().for_each(|x| collect_control_points(x, space, uv)),
        _ => {}
    }
}

/// Every `unconverged` count in a report.
fn unconverged(v: &Value, out: &mut Vec<u64>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                match (k.as_str(), x.as_u64()) {
                    ("unconverged", Some(n)) => out.push(n),
                    _ => unconverged(x, out),
                }
            }
        }
        Value::Array(a) => a.iter().for_each(|x| unconverged(x, out)),
        _ => {}
    }
}

/// Parses JSON text and fails on `null` (a JSON writer's NaN or infinity)
/// anywhere; numbers out of the f64 range fail to parse.
fn strict_json(text: &str, what: &str) -> Value {
    fn nulls(v: &Value, at: &str, found: &mut Vec<String>) {
        match v {
            Value::Null => found.push(at.to_string()),
            Value::Array(a) => a
                .iter()
                .enumerate()
                .for_each(|(k, x)| nulls(x, &format!("{at}[{k}]"), found)),
            Value::Object(m) => m
                .iter()
                .for_each(|(k, x)| nulls(x, &format!("{at}.{k}"), found)),
            Value::Number(n) if !n.as_f64().is_some_and(f64::is_finite) => {
                found.push(format!("{at} = {n}"))
            }
            _ => {}
        }
    }
    let v: Value = serde_json::from_str(text).unwrap_or_else(|e| panic!("{what}: not JSON: {e}"));
    let mut found = Vec::new();
    nulls(&v, "", &mut found);
    assert!(found.is_empty(), "{what}: null or non-finite at {found:?}");
    v
}

/// Runs `args` with `{in}` and `{out}` replaced; returns the --json report
/// and the `-o` document, both checked by [`strict_json`].
fn run(args: &[&str], input: &Path, out: &Path) -> (Value, Value) {
    let args: Vec<String> = args
        .iter()
        .map(|a| match *a {
            "{in}" => input.display().to_string(),
            "{out}" => out.display().to_string(),
            a => a.to_string(),
        })
        .collect();
    let o = Command::new(env!("CARGO_BIN_EXE_scanfit"))
        .args(&args)
        .output()
        .unwrap();
    let what = format!("scanfit {}", args.join(" "));
    assert!(
        o.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let report = strict_json(&String::from_utf8_lossy(&o.stdout), &what);
    let doc = strict_json(
        &std::fs::read_to_string(out).unwrap(),
        &format!("{what}: -o"),
    );
    (report, doc)
}

/// One pipeline at the three offsets against its origin twins.
fn same_far_away(name: &str, sample: &str, args: &[&str]) {
    let d = tmpdir(name);
    for offset in [1e6, 1e10, 1e15] {
        let (near_in, far_in) = (
            d.join(format!("near{offset:e}.csv")),
            d.join(format!("far{offset:e}.csv")),
        );
        let diagonal = write_shifted(sample, offset, true, &near_in);
        write_shifted(sample, offset, false, &far_in);
        let (near_rep, near_doc) = run(args, &near_in, &d.join("near.json"));
        let (far_rep, far_doc) = run(args, &far_in, &d.join("far.json"));
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let (mut a_uv, mut b_uv) = (Vec::new(), Vec::new());
        collect_control_points(&near_doc, &mut a, &mut a_uv);
        collect_control_points(&far_doc, &mut b, &mut b_uv);
        assert_eq!(a_uv.len(), b_uv.len(), "{name} at {offset:e}: trim curves");
        let worst_uv = a_uv
            .iter()
            .zip(&b_uv)
            .flat_map(|(p, q)| (0..3).map(move |k| (q[k] - p[k]).abs()))
            .fold(0.0, f64::max);
        assert!(
            worst_uv <= 1e-9,
            "{name} at {offset:e}: trim curves in (u, v) differ by {worst_uv:e}"
        );
        assert!(
            !a.is_empty() && a.len() == b.len(),
            "{name} at {offset:e}: {} vs {} control points",
            a.len(),
            b.len()
        );
        let bound = 1e-9 * diagonal + offset * f64::EPSILON;
        let worst = a
            .iter()
            .zip(&b)
            .flat_map(|(p, q)| (0..3).map(move |k| ((q[k] - offset) - p[k]).abs()))
            .fold(0.0, f64::max);
        assert!(
            worst <= bound,
            "{name} at {offset:e}: control points differ by {worst:e} > {bound:e}"
        );
        let (mut un, mut uf) = (Vec::new(), Vec::new());
        unconverged(&near_rep, &mut un);
        unconverged(&far_rep, &mut uf);
        assert_eq!(un.len(), uf.len(), "{name}");
        for (n, f) in un.iter().zip(&uf) {
            assert!(
                *n > 0 || *f == 0,
                "{name} at {offset:e}: {f} unconverged, none at the origin"
            );
        }
        eprintln!("{name} at {offset:e}: control points within {worst:.3e} (bound {bound:.3e}), unconverged {uf:?} (origin {un:?})");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn fit_is_the_same_far_away() {
    same_far_away(
        "fit",
        "patch_20k.ply",
        &[
            "fit", "{in}", "--ctrl", "12x12", "-o", "{out}", "--json", "-q",
        ],
    );
}

#[test]
fn mba_is_the_same_far_away() {
    same_far_away(
        "mba",
        "terrain_50k.xyz",
        &[
            "mba", "{in}", "--levels", "5", "-o", "{out}", "--json", "-q",
        ],
    );
}

#[test]
fn coons_is_the_same_far_away() {
    same_far_away(
        "coons",
        "patch_20k.ply",
        &["coons", "{in}", "-o", "{out}", "--json", "-q"],
    );
}

#[test]
fn coons_pde_is_the_same_far_away() {
    same_far_away(
        "pde",
        "patch_20k.ply",
        &[
            "coons", "{in}", "--pde", "5x5", "-o", "{out}", "--json", "-q",
        ],
    );
}

#[test]
fn turntable_is_the_same_far_away() {
    same_far_away(
        "turntable",
        "bottle_12k.ply",
        &["turntable", "{in}", "-o", "{out}", "--json", "-q"],
    );
}

#[test]
fn reconstruct_is_the_same_far_away() {
    same_far_away(
        "reconstruct",
        "vessel_30k.ply",
        &["reconstruct", "{in}", "-o", "{out}", "--json", "-q"],
    );
}

#[test]
fn curve_fit_is_the_same_far_away() {
    same_far_away(
        "curve",
        "dataset6.csv",
        &[
            "curve", "fit", "{in}", "--ctrl", "20", "-o", "{out}", "--json", "-q",
        ],
    );
}

/// Runs `args` and returns its standard output, which must be strict JSON.
fn json_of(args: &[&str]) -> Value {
    let o = Command::new(env!("CARGO_BIN_EXE_scanfit"))
        .args(args)
        .output()
        .unwrap();
    let what = format!("scanfit {}", args.join(" "));
    assert!(
        o.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    strict_json(&String::from_utf8_lossy(&o.stdout), &what)
}

/// The commands and options the pipeline tests above do not run, with
/// `--json` (and `-o` where it writes JSON), on samples at the origin and
/// moved by 1e10: every output is strict JSON (no `null`, all numbers finite).
/// The pipeline tests above scan the outputs of fit, mba, coons (both
/// routes), turntable, reconstruct and curve fit the same way.
#[test]
fn every_json_output_is_finite_and_has_no_null() {
    let d = tmpdir("scan");
    let far = d.join("patch_far.csv");
    write_shifted("patch_20k.ply", 1e10, false, &far);
    let ds = examples().join("dataset6.csv");
    let patch = examples().join("patch_20k.ply");
    let bottle = examples().join("bottle_12k.ply");
    let terrain = examples().join("terrain_50k.xyz");
    let s = |p: &Path| p.display().to_string();
    let o = |n: &str| d.join(n).display().to_string();
    for (input, view) in [(s(&patch), "50,50,500"), (s(&far), "1e10,1e10,10000000500")] {
        for cmd in [
            vec!["cloud", "info", &input, "--json"],
            vec![
                "cloud",
                "normals",
                &input,
                "-o",
                &o("n.ply"),
                "--json",
                "-q",
            ],
            vec![
                "cloud",
                "hpr",
                &input,
                "--view",
                view,
                "-o",
                &o("h.ply"),
                "--json",
                "-q",
            ],
            vec!["cloud", "boundary", &input, "--json", "-q"],
            vec![
                "fit",
                &input,
                "--ctrl",
                "10x10",
                "--correct",
                "2",
                "-o",
                &o("s.json"),
                "--json",
                "-q",
            ],
        ] {
            json_of(&cmd);
        }
        let b = o("b.json");
        json_of(&["cloud", "boundary", &input, "-o", &b, "--json", "-q"]);
        strict_json(&std::fs::read_to_string(&b).unwrap(), "cloud boundary -o");
        let surf = o("s.json");
        strict_json(&std::fs::read_to_string(&surf).unwrap(), "fit -o");
        json_of(&["report", &surf, &input, "--json"]);
    }
    json_of(&["curve", "compare", &s(&ds), "-o", &o("cmp.svg"), "--json"]);
    json_of(&[
        "mba",
        &s(&terrain),
        "--levels",
        "4",
        "--adjust",
        "--json",
        "-q",
    ]);
    json_of(&[
        "turntable",
        &s(&bottle),
        "--compare-weights",
        "--compare-rounds",
        "2",
        "--json",
        "-q",
    ]);
    let _ = std::fs::remove_dir_all(&d);
}
