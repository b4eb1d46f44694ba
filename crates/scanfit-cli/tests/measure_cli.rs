//! End-to-end tests of `--measure full|sample|none` (issue 18): what the
//! surface commands report with each choice.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{examples, ok, run, tmpdir};

/// `scanfit fit` on the 50 000-point terrain with `extra` options, as JSON.
fn fit(extra: &[&str]) -> serde_json::Value {
    let input = examples().join("terrain_50k.xyz");
    let mut args = vec!["fit", input.to_str().unwrap(), "--ctrl", "16x16", "--json"];
    args.extend_from_slice(extra);
    serde_json::from_str(&ok(&run(&args))).unwrap()
}

#[test]
fn sample_equals_full_below_the_sample_size_and_none_measures_only_the_errors() {
    // 50 000 points are below the 200 000 of the sample: the same figures
    let (sample, full) = (fit(&[]), fit(&["--measure", "full"]));
    assert_eq!(sample["measure"]["mode"], "sample");
    assert_eq!(sample["measure"]["sampled"], false);
    assert_eq!(full["measure"]["mode"], "full");
    assert_eq!(sample["quality"], full["quality"]);
    assert_eq!(sample["samples_to_points"], full["samples_to_points"]);
    assert!(sample["quality"]["triangles"].as_u64().unwrap() > 90_000);
    // none: the errors at the parameters unchanged, the rest not measured
    let none = fit(&["--measure", "none"]);
    assert_eq!(none["measure"]["mode"], "none");
    assert_eq!(none["quality"]["rmse"], sample["quality"]["rmse"]);
    assert_eq!(none["quality"]["max_error"], sample["quality"]["max_error"]);
    assert_eq!(none["quality"]["triangles"], 0);
    assert_eq!(none["quality"]["rmse_distance"], 0.0);
    assert_eq!(none["samples_to_points"]["leaves_data"], false);
}

#[test]
fn none_refuses_outputs_that_show_orthogonal_distances() {
    let d = tmpdir("measure", "none");
    let input = examples().join("terrain_50k.xyz");
    let png = d.join("dev.png");
    let o = run(&[
        "fit",
        input.to_str().unwrap(),
        "--measure",
        "none",
        "--deviation-png",
        png.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--measure none leaves out"), "{err}");
    assert!(!png.exists());
    // the text report says what was not measured
    let out = ok(&run(&["fit", input.to_str().unwrap(), "--measure", "none"]));
    assert!(out.contains("not measured"), "{out}");
}
