//! Issue 14 item 5: a control net larger than the machine or the data can
//! handle is refused before any work, with an estimate of the memory it
//! would take and the largest net that fits, and no output is written
//! (`fit --ctrl 1000x1000` on 900 points used to run 105 s and 5.4 GB
//! before failing, suggesting smoothing that was given).

mod common;

use common::{run, tmpdir};

type TestResult = Result<(), Box<dyn std::error::Error>>;

/// A 30 x 30 sheet of points as XYZ text.
fn sheet(path: &std::path::Path) -> std::io::Result<()> {
    let mut s = String::new();
    for i in 0..30 {
        for j in 0..30 {
            let (x, y) = (f64::from(i) / 29.0, f64::from(j) / 29.0);
            s += &format!("{x} {y} {}\n", 0.2 * (3.0 * x).sin() * y);
        }
    }
    std::fs::write(path, s)
}

/// `scanfit fit` on the sheet with `--ctrl NET` and the `extra` options,
/// written to a JSON document: its stderr and exit code, and whether the
/// document was written.
fn fit(
    name: &str,
    net: &str,
    extra: &[&str],
) -> Result<(String, Option<i32>, bool), Box<dyn std::error::Error>> {
    let d = tmpdir("net_limits", name);
    let input = d.join("s.xyz");
    sheet(&input)?;
    let out = d.join("s.json");
    let (i, o) = (input.to_string_lossy(), out.to_string_lossy());
    let mut args = vec!["fit", &i, "--ctrl", net, "-o", &o];
    args.extend_from_slice(extra);
    let r = run(&args);
    let err = String::from_utf8_lossy(&r.stderr).into_owned();
    Ok((err, r.status.code(), out.exists()))
}

#[test]
fn a_net_beyond_the_memory_limit_is_refused_with_its_estimate() -> TestResult {
    let (err, code, written) = fit("memory", "1000x1000", &["--smooth", "0.001"])?;
    assert_eq!(code, Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "one error line: {err}");
    // the net, its memory, the limit and the largest square net that fits.
    // The documented estimate (`scanfit::fit::surface::memory_estimate`) of
    // a k x k net of degrees 3 x 3 is 8 (2 k^2 (7 x 7 + 3) + 4 k^3) = 832 k^2
    // + 32 k^3 bytes: 3.28e10 = 30.6 GiB for k = 1000; under 4 GiB up to
    // k = 503 (4.283e9 bytes; k = 504 takes 4.308e9 > 4.295e9)
    for part in [
        "--ctrl = 1000 x 1000",
        "a 1000 x 1000 net of degrees 3 x 3 needs about 30.6 GiB for its normal equations",
        "(limit 4 GiB)",
        "use at most 503 x 503 control points",
    ] {
        assert!(err.contains(part), "'{part}' missing: {err}");
    }
    // smoothing was given: it is not the advice
    assert!(!err.contains("smooth"), "{err}");
    assert!(!written, "no output after a refusal");
    Ok(())
}

#[test]
fn a_net_beyond_the_control_point_limit_is_refused() -> TestResult {
    let (err, code, written) = fit("count", "4096x4096", &[])?;
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("a 4096 x 4096 control net of degrees 3 x 3 is beyond the limits"),
        "{err}"
    );
    assert!(!written);
    Ok(())
}
