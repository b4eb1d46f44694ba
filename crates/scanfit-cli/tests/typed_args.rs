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

#[test]
fn library_errors_carry_their_point_and_option() {
    let d = tmpdir("typed", "context");
    let input = d.join("s.xyz");
    sheet(&input);
    let f = input.to_str().unwrap();
    // a point the library refuses: its line in the file is named (from the
    // error's point index, not from its text)
    let huge = d.join("huge.xyz");
    let mut text = std::fs::read_to_string(&input).unwrap();
    text = text.replacen("0 0 0\n", "0 0 1e300\n", 1);
    std::fs::write(&huge, text).unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["fit", huge.to_str().unwrap(), "--ctrl", "6"],
            "point 0 has a coordinate of magnitude 1e300",
        ),
        (vec!["fit", huge.to_str().unwrap(), "--ctrl", "6"], "huge.xyz:1)"),
        (
            vec!["fit", f, "--ctrl", "6", "--smooth", "-1"],
            "s.xyz: --smooth = -1: ",
        ),
        (
            vec!["mba", f, "--adjust", "--alpha", "-1"],
            "s.xyz: --alpha = -1: the adjustment's alpha must be a positive number (the paper uses 1.49)\n",
        ),
        (vec!["mba", f, "--base", "0x2"], "s.xyz: --base = 0 x 2: "),
    ];
    for (args, needle) in cases {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: '{needle}' not in {err}");
    }
}

#[test]
fn fit_reports_the_surface_samples_far_from_the_data() {
    // data on an L-shaped region: the fitted surface spans the whole square,
    // a quarter of it with no points (the surface-to-points direction sees it)
    let d = tmpdir("typed", "lshape");
    let input = d.join("l.xyz");
    let mut s = String::new();
    for i in 0..40 {
        for j in 0..40 {
            if i >= 20 && j >= 20 {
                continue;
            }
            let (x, y) = (i as f64 / 39.0, j as f64 / 39.0);
            s += &format!("{x} {y} {}\n", 0.1 * x * y);
        }
    }
    std::fs::write(&input, s).unwrap();
    // (smoothing holds the control points over the empty quarter)
    let fit = |trim: &str| -> serde_json::Value {
        let out = ok(&run(&[
            "fit",
            input.to_str().unwrap(),
            "--ctrl",
            "6",
            "--smooth",
            "1e-6",
            trim,
            "--json",
        ]));
        serde_json::from_str(&out).unwrap()
    };
    // trimmed (the default) to the L, the face has no sample far from it
    let t = fit("--trim");
    assert!(t["trim"]["outer"].as_u64().unwrap() > 100, "{t}");
    assert_eq!(t["samples_to_points"]["far_share"].as_f64().unwrap(), 0.0);
    // the untrimmed rectangle spans the empty quarter
    let v = fit("--no-trim");
    let far = v["samples_to_points"]["far_share"].as_f64().unwrap();
    // samples farther than 3 spacings (3/39) from the L: x, y > 20/39 + 3/39
    // roughly, (1 - 23/39)^2 = 0.17 of the square
    assert!(far > 0.12 && far < 0.2, "{far}");
    let spacing = v["samples_to_points"]["point_spacing"].as_f64().unwrap();
    // the grid step, a little more in 3D where z rises
    assert!(spacing > 1.0 / 39.0 && spacing < 1.01 / 39.0, "{spacing}");
    // points to surface: the fit is good where the points are
    assert!(v["quality"]["max_distance"].as_f64().unwrap() < 0.01);
}

#[test]
fn fit_takes_the_shared_input_group() {
    let d = tmpdir("typed", "input");
    let input = d.join("s.xyz");
    sheet(&input);
    let nan = d.join("nan.txt");
    let text = std::fs::read_to_string(&input).unwrap();
    std::fs::write(&nan, text.replacen("0 0 0\n", "0 0 nan\n", 1)).unwrap();
    let n = nan.to_str().unwrap();
    // refused by default, with its line
    let o = run(&["fit", n, "--ctrl", "6"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nan.txt:1"));
    // dropped on request, told once
    let o = run(&["fit", n, "--ctrl", "6", "--drop-non-finite"]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let out = ok(&o);
    assert_eq!(
        err.matches("1 points with NaN or infinite coordinates dropped")
            .count(),
        1,
        "{err}"
    );
    assert!(out.contains("899 points"), "{out}");
    let o = run(&["fit", n, "--format", "e57"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("unknown --format 'e57'; use ply, pcd, las")
    );
}

#[test]
fn curve_and_report_take_the_shared_input_group() {
    let dir = tmpdir("typed_args", "curve_input_group");
    // data set 1 with a NaN row in the middle, under a name without a known
    // extension: --format text reads it, --drop-non-finite drops the row
    let text = std::fs::read_to_string(examples().join("dataset1.csv")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(3, "nan,1,0");
    let data = dir.join("d1.points");
    std::fs::write(&data, lines.join("\n")).unwrap();
    let d = data.to_str().unwrap();
    let o = run(&["curve", "fit", d, "-q"]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = run(&["curve", "fit", d, "--format", "text", "-q"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("is NaN"));
    let o = run(&[
        "curve",
        "fit",
        d,
        "--format",
        "text",
        "--drop-non-finite",
        "-q",
    ]);
    let out = ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.matches("1 points with NaN").count(), 1, "{err}");
    let full = run(&[
        "curve",
        "fit",
        examples().join("dataset1.csv").to_str().unwrap(),
        "-q",
    ]);
    // the same curve as from the clean file: the tables agree line for line
    // after the header (which names the input file)
    let skip = |s: &str| s.lines().skip(1).collect::<Vec<_>>().join("\n");
    assert_eq!(skip(&out), skip(&ok(&full)));
}

#[test]
fn reconstruct_options_are_typed() {
    let v = examples().join("vessel_30k.ply");
    let v = v.to_str().unwrap();
    for (args, needle) in [
        (vec!["--fit", "nurbs"], "--fit"),
        (vec!["--pde", "5by5"], "--pde"),
        (vec!["--ctrl", "0x8", "--fit", "bspline"], "--ctrl"),
        (vec!["--ignore", "1,two"], "--ignore"),
    ] {
        let mut all = vec!["reconstruct", v, "-q"];
        all.extend(args.iter().copied());
        let o = run(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{all:?}: {err}");
        assert!(err.contains(needle), "{all:?}: {err}");
    }
    // a negative id in --ignore is a value, not a flag
    let o = run(&["reconstruct", v, "-q", "--ignore", "-5,13", "--json"]);
    let out = ok(&o);
    assert!(out.contains("\"patches\""), "{out}");
}

/// A library setting refused with the command-line option named first (the
/// library's own field name nowhere), the value and the library's hint
/// after it, advice last.
#[test]
fn setting_errors_name_the_option_first() {
    let d = tmpdir("typed", "option-first");
    let input = d.join("s.xyz");
    sheet(&input);
    let f = input.to_str().unwrap();
    // (arguments, what the message starts with after `error: <context>: `,
    // the library's field name that must not show)
    let cases: Vec<(Vec<&str>, &str, &str)> = vec![
        (
            vec!["fit", f, "--ctrl", "6", "--smooth", "-1"],
            "--smooth = -1: smoothing weight -1 must be finite and non-negative",
            "smoothing =",
        ),
        (
            vec!["mba", f, "--tolerance", "-1"],
            "--tolerance = -1: the MBA tolerance must be",
            ": tolerance",
        ),
        (
            vec!["mba", f, "--levels", "40"],
            "--levels = 40: 40 levels on a ",
            "max_levels",
        ),
        (
            vec!["cloud", "segment", f, "--angle", "95"],
            "--angle = 95: an angle in (0, 90) degrees",
            "max_angle_deg",
        ),
        (
            vec!["cloud", "segment", f, "--min-cell", "0"],
            "--min-cell = 0: a positive number of point spacings",
            "min_cell",
        ),
        (
            vec!["coons", f, "--pde", "4x4", "--export-tolerance=-1"],
            "--export-tolerance = -1: the B-spline form",
            "export_tolerance",
        ),
    ];
    for (args, start, field) in cases {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        // the option opens the message: only the context (the file, the
        // step) comes before it
        let at = err
            .find(start)
            .unwrap_or_else(|| panic!("{args:?}: '{start}' not in {err}"));
        let before = &err[..at];
        assert!(
            before.starts_with("error: ") && !before.contains(" = "),
            "{args:?}: {err}"
        );
        assert!(!err.contains(field), "{args:?}: '{field}' in {err}");
        assert!(!err.contains("(option "), "{args:?}: {err}");
    }
}
