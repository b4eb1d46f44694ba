//! `--chunk-points`: the streamed `fit` and `mba` write the in-memory
//! command's surface (the same JSON knots and control points; `mba`'s to
//! 1e-12 of the largest control value, as its in-memory level loop sums in
//! lattice-cell order and the streamed one in file order).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn scanfit(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_scanfit"))
        .args(args)
        .output()
        .expect("scanfit runs")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("scanfit-stream-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn surface(path: &Path) -> serde_json::Value {
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    serde_json::json!([doc["control_points"], doc["knots_u"], doc["knots_v"]])
}

/// The largest difference between two JSON lists of control points
/// `[x, y, z]`, relative to the largest magnitude of that coordinate in `b`.
fn relative(a: &serde_json::Value, b: &serde_json::Value) -> f64 {
    let numbers = |v: &serde_json::Value| -> Vec<[f64; 3]> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|p| {
                let p = p.as_array().unwrap();
                assert_eq!(p.len(), 3);
                [0, 1, 2].map(|k| p[k].as_f64().unwrap())
            })
            .collect()
    };
    let (x, y) = (numbers(a), numbers(b));
    assert_eq!(x.len(), y.len());
    (0..3)
        .map(|k| {
            let scale = y.iter().fold(0.0f64, |s, q| s.max(q[k].abs()));
            x.iter()
                .zip(&y)
                .fold(0.0f64, |w, (p, q)| w.max((p[k] - q[k]).abs()))
                / scale
        })
        .fold(0.0, f64::max)
}

/// The knots of two [`surface`]s within 1e-12 of each other.
fn knots_close(x: &serde_json::Value, y: &serde_json::Value, what: &str) {
    for j in [1, 2] {
        let (a, b) = (x[j].as_array().unwrap(), y[j].as_array().unwrap());
        assert_eq!(a.len(), b.len(), "{what}: knot counts");
        for (s, t) in a.iter().zip(b) {
            let (s, t) = (s.as_f64().unwrap(), t.as_f64().unwrap());
            assert!((s - t).abs() <= 1e-12, "{what}: knots {s} {t}");
        }
    }
}

fn ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn streamed_mba_writes_the_in_memory_surface() {
    let d = tmp("mba");
    let sample = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/data/terrain_50k.xyz"
    );
    let (a, b) = (d.join("a.json"), d.join("b.json"));
    let base = ["mba", sample, "--levels", "5", "--quiet", "-o"];
    ok(&scanfit(&[&base[..], &[a.to_str().unwrap()]].concat()));
    for chunk in ["7000", "50000"] {
        let out = scanfit(
            &[
                &base[..],
                &[b.to_str().unwrap(), "--chunk-points", chunk, "--json"],
            ]
            .concat(),
        );
        ok(&out);
        let (sa, sb) = (surface(&a), surface(&b));
        assert_eq!((&sa[1], &sa[2]), (&sb[1], &sb[2]), "knots, chunk {chunk}");
        let worst = relative(&sa[0], &sb[0]);
        assert!(worst <= 1e-12, "chunk {chunk}: {worst:e}");
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        // bounding box, frame, 5 levels, the last level's start (the default
        // --start fitted), measures
        assert_eq!(report["streamed"]["passes"], 9);
        assert_eq!(report["point_count"], 50_000);
    }
    // the mean start: the same surface in memory and streamed, one pass fewer
    let mean = [&base[..], &[a.to_str().unwrap(), "--start", "mean"]].concat();
    ok(&scanfit(&mean));
    let out = scanfit(
        &[
            &base[..],
            &[
                b.to_str().unwrap(),
                "--start",
                "mean",
                "--chunk-points",
                "7000",
                "--json",
            ],
        ]
        .concat(),
    );
    ok(&out);
    let (sa, sb) = (surface(&a), surface(&b));
    assert!(relative(&sa[0], &sb[0]) <= 1e-12);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["streamed"]["passes"], 8);
    // the adjustment starts from the mean; asking it for the fitted start is refused
    let e = scanfit(&[
        "mba", sample, "--adjust", "--start", "fitted", "--levels", "2",
    ]);
    assert!(!e.status.success());
    assert!(String::from_utf8_lossy(&e.stderr).contains("starts from the mean"));
    let e = scanfit(&["mba", sample, "--adjust", "--chunk-points", "1000"]);
    assert!(!e.status.success());
    assert!(String::from_utf8_lossy(&e.stderr).contains("--adjust"));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn streamed_fit_writes_the_in_memory_surface_bit_for_bit_with_given_parameters() {
    let d = tmp("fit");
    let input = d.join("patch.csv");
    let mut text = String::from("x,y,z,u,v\n");
    for k in 0..20_000 {
        let (u, v) = ((k % 157) as f64 / 156.0, (k / 157) as f64 / 127.0);
        text.push_str(&format!(
            "{},{},{},{u},{v}\n",
            30.0 * u,
            20.0 * v,
            (3.0 * u).sin() * (2.0 * v).cos()
        ));
    }
    std::fs::write(&input, text).unwrap();
    let (a, b) = (d.join("a.json"), d.join("b.json"));
    let input = input.to_str().unwrap();
    let base = [
        "fit",
        input,
        "--params",
        "uv-columns",
        "--knots",
        "uniform",
        "--ctrl",
        "12x9",
        "--quiet",
        "-o",
    ];
    ok(&scanfit(&[&base[..], &[a.to_str().unwrap()]].concat()));
    ok(&scanfit(
        &[&base[..], &[b.to_str().unwrap(), "--chunk-points", "3000"]].concat(),
    ));
    assert_eq!(surface(&a), surface(&b));
    // the per-point parameters are still refused, with the reason
    let e = scanfit(
        &[
            &base[..],
            &[
                b.to_str().unwrap(),
                "--chunk-points",
                "3000",
                "--points-out",
                "p.ply",
            ],
        ]
        .concat(),
    );
    assert!(!e.status.success());
    let msg = String::from_utf8_lossy(&e.stderr);
    assert!(
        msg.contains("--points-out") && msg.contains("all points at once"),
        "{msg}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn streamed_mba_says_in_one_line_that_it_is_untrimmed_and_how_to_trim() {
    let d = tmp("mba-trim");
    let sample = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/data/terrain_50k.xyz"
    );
    let out = d.join("s.json");
    let o = out.to_str().unwrap();
    // the default (trim on in memory): one note line, with the way to a
    // trimmed face
    let run = scanfit(&[
        "mba",
        sample,
        "--levels",
        "4",
        "--chunk-points",
        "20000",
        "-o",
        o,
    ]);
    ok(&run);
    let err = String::from_utf8_lossy(&run.stderr);
    let notes: Vec<&str> = err.lines().filter(|l| l.contains("trim")).collect();
    assert_eq!(notes.len(), 1, "{err}");
    assert!(
        notes[0].starts_with("note: the surface is NOT trimmed: ")
            && notes[0].contains("run without --chunk-points")
            && notes[0].contains("--no-trim silences"),
        "{err}"
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert!(doc.get("trim").is_none());
    // --no-trim: no note
    let run = scanfit(&[
        "mba",
        sample,
        "--levels",
        "4",
        "--chunk-points",
        "20000",
        "--no-trim",
        "-o",
        o,
    ]);
    ok(&run);
    assert!(!String::from_utf8_lossy(&run.stderr).contains("trim"));
    // --trim asked: refused before any work, with the same way out
    std::fs::remove_file(&out).unwrap();
    let run = scanfit(&["mba", sample, "--chunk-points", "20000", "--trim", "-o", o]);
    assert_eq!(run.status.code(), Some(1));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("--trim cannot be used with --chunk-points")
            && err.contains("run without --chunk-points"),
        "{err}"
    );
    assert!(!out.exists());
    // the thinning command the note suggests works as printed
    let thin = d.join("thin.ply");
    ok(&scanfit(&[
        "cloud",
        "clean",
        sample,
        "--voxel-spacings",
        "2",
        "-o",
        thin.to_str().unwrap(),
    ]));
    assert!(thin.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

/// A binary little-endian PLY of `x y z` doubles.
fn write_ply(path: &Path, points: &[[f64; 3]]) {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nend_header\n",
        points.len()
    )
    .into_bytes();
    for p in points {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn streamed_fit_with_the_plane_distribution_knots_and_correction_is_the_in_memory_fit() {
    let d = tmp("plane");
    let input = d.join("tilted.ply");
    // 10^5 points of a wavy sheet, unevenly spread, tilted and sheared far from the origin
    let mut state = 7u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let points: Vec<[f64; 3]> = (0..100_000)
        .map(|_| {
            let (s, t) = (next().powf(1.3) * 120.0, next() * 70.0);
            let h = 4.0 * (s / 17.0).sin() * (t / 11.0).cos() + 0.05 * next();
            [
                4.0e5 + 0.8 * s - 0.3 * t + 0.2 * h,
                6.1e6 + 0.5 * s + 0.9 * t - 0.1 * h,
                80.0 + 0.3 * s + 0.2 * t + 0.95 * h,
            ]
        })
        .collect();
    write_ply(&input, &points);
    let input = input.to_str().unwrap();
    for (k, extra) in [
        &[][..],
        &["--correct", "2"][..],
        &["--knots", "uniform", "--correct", "1"][..],
    ]
    .iter()
    .enumerate()
    {
        let (a, b) = (d.join(format!("a{k}.json")), d.join(format!("b{k}.json")));
        let base = ["fit", input, "--ctrl", "14x11", "--no-trim", "--quiet"];
        ok(&scanfit(
            &[&base[..], extra, &["-o", a.to_str().unwrap()]].concat(),
        ));
        let run = scanfit(
            &[
                &base[..],
                extra,
                &[
                    "-o",
                    b.to_str().unwrap(),
                    "--chunk-points",
                    "30000",
                    "--json",
                ],
            ]
            .concat(),
        );
        ok(&run);
        let (x, y) = (surface(&b), surface(&a));
        let worst = relative(&x[0], &y[0]);
        assert!(
            worst <= 1e-12,
            "{extra:?}: control points differ by {worst:e}"
        );
        knots_close(&x, &y, &format!("{extra:?}"));
        // the passes: box, plane x3, then per fit the knot rounds (none when
        // uniform), the equations and (when correcting) the errors; measuring
        let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        // the wavy sheet does not fold over its best-fit plane: kept
        assert_eq!(report["projection"]["axis"], "best-fit plane", "{report}");
        let passes = report["streamed"]["passes"].as_u64().unwrap();
        let doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&b).unwrap()).unwrap();
        let memory: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&a).unwrap()).unwrap();
        // (the document leaves the list out when there is no correction)
        let count = |d: &serde_json::Value| {
            d["quality"]["correction_rmse"]
                .as_array()
                .map_or(0, |a| a.len() as u64)
        };
        let rounds = count(&doc);
        assert_eq!(rounds, count(&memory));
        let fits = rounds.max(1);
        let per_fit = match k {
            0 => 2 + 1,
            1 => 2 + 1 + 1,
            _ => 1 + 1,
        };
        assert_eq!(passes, 1 + 3 + fits * per_fit + 1, "{extra:?}");
    }
    // --trim cannot be streamed; the plane's default (trimmed) gets a note
    let run = scanfit(&[
        "fit",
        input,
        "--chunk-points",
        "30000",
        "--trim",
        "-o",
        "t.json",
    ]);
    assert_eq!(run.status.code(), Some(1));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("--trim cannot be used with --chunk-points"),
        "{err}"
    );
    let o = d.join("note.json");
    let run = scanfit(&[
        "fit",
        input,
        "--ctrl",
        "6x6",
        "--chunk-points",
        "50000",
        "-o",
        o.to_str().unwrap(),
    ]);
    ok(&run);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("NOT trimmed") && err.contains("--no-trim"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// Franke's function on 20000 seeded points of the unit square (relief
/// 1.2), whose best-fit plane folds the bumps over: the streamed default fit
/// chooses the in-memory fit's projection (along z) from the same seeded
/// sample, gathered in its covariance pass, and writes its surface.
#[test]
fn streamed_fit_of_a_height_field_of_large_relief_projects_along_z_as_in_memory() {
    let d = tmp("franke");
    let input = d.join("franke.xyz");
    common::write_franke_xyz(&input, 20_000);
    let input = input.to_str().unwrap();
    let a = d.join("a.json");
    let memory = scanfit(&[
        "fit",
        input,
        "--no-trim",
        "-o",
        a.to_str().unwrap(),
        "--json",
    ]);
    ok(&memory);
    let memory: serde_json::Value = serde_json::from_slice(&memory.stdout).unwrap();
    assert_eq!(memory["projection"]["axis"], "z", "{memory}");
    for chunk in ["1777", "20000"] {
        let b = d.join(format!("b{chunk}.json"));
        let run = scanfit(&[
            "fit",
            input,
            "--no-trim",
            "-o",
            b.to_str().unwrap(),
            "--chunk-points",
            chunk,
            "--json",
        ]);
        ok(&run);
        let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        // the same choice from the same sample: shares equal to the bit
        assert_eq!(report["projection"]["axis"], "z", "{report}");
        assert_eq!(
            report["projection"]["fold_shares"],
            memory["projection"]["fold_shares"]
        );
        assert_eq!(report["projection"]["sampled"], 4000);
        let (x, y) = (surface(&b), surface(&a));
        let worst = relative(&x[0], &y[0]);
        assert!(
            worst <= 1e-12,
            "chunk {chunk}: control points differ by {worst:e}"
        );
        knots_close(&x, &y, &format!("chunk {chunk}"));
        // relief 1.2: orthogonal RMSE under 0.1% of it, as in memory
        let rmse = report["quality"]["rmse_distance"].as_f64().unwrap();
        assert!(rmse < 1.2e-3, "{rmse}");
    }
    // the table says which way it projected
    let run = scanfit(&[
        "fit",
        input,
        "--no-trim",
        "-o",
        a.to_str().unwrap(),
        "--chunk-points",
        "5000",
    ]);
    ok(&run);
    let out = String::from_utf8_lossy(&run.stdout);
    assert!(out.contains("projected along z"), "{out}");
    std::fs::remove_dir_all(&d).unwrap();
}
