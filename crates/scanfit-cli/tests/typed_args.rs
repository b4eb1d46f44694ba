//! End-to-end tests of the typed command line: negative values where a
//! value can be negative, and typed parsers that refuse bad values with a
//! message naming the option (status 1, as for other bad input).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{examples, ok, run, tmpdir};

/// A small smooth sheet as XYZ text.
fn sheet(path: &std::path::Path) {
    let mut s = String::new();
    for i in 0..30 {
        for j in 0..30 {
            let (x, y) = (i as f64 / 29.0, j as f64 / 29.0);
            s += &format!("{x} {y} {}\n", 0.2 * (3.0 * x).sin() * y);
        }
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn negative_view_angles_are_accepted_as_the_help_shows() {
    let d = tmpdir("typed", "view");
    let input = d.join("s.xyz");
    sheet(&input);
    let png = d.join("s.png");
    let out = ok(&run(&[
        "fit",
        input.to_str().unwrap(),
        "--ctrl",
        "6",
        "--view",
        "-60,35",
        "--png",
        png.to_str().unwrap(),
    ]));
    assert!(out.contains("wrote"), "{out}");
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    // a negative elevation as well
    let o = run(&[
        "fit",
        input.to_str().unwrap(),
        "--ctrl",
        "6",
        "--view=-120,-20",
        "--png",
        png.to_str().unwrap(),
    ]);
    ok(&o);
}

#[test]
fn typed_values_are_refused_with_the_option_named() {
    let d = tmpdir("typed", "bad");
    let input = d.join("s.xyz");
    sheet(&input);
    let f = input.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["fit", f, "--view", "-60,95"],
            "elevation must lie in [-90, 90]",
        ),
        (vec!["fit", f, "--view", "west,35"], "--view azimuth 'west'"),
        (
            vec!["fit", f, "--ctrl", "ax2"],
            "--ctrl 'ax2' must be N or NxM",
        ),
        (vec!["fit", f, "--degree", "3x"], "--degree '3x'"),
    ];
    for (args, needle) in cases {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: '{needle}' not in {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    // an unknown option stays a usage error (clap's status 2)
    let o = run(&["fit", f, "--no-such-option"]);
    assert_eq!(o.status.code(), Some(2));
    let _ = examples();
}
