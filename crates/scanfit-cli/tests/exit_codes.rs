//! The exit codes the README documents, one run each: 0 success, 1 error,
//! (also a value an option refuses), 2 usage (unknown option or command,
//! missing argument), 141 closed stdout or stderr (broken pipe); and no panic message
//! in any of these cases.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::io::Read;
use std::process::{Command, Stdio};

use common::{examples, run, tmpdir};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_scanfit"))
}

fn no_panic(stderr: &[u8]) {
    let s = String::from_utf8_lossy(stderr);
    assert!(
        !s.contains("panicked") && !s.contains("RUST_BACKTRACE"),
        "{s}"
    );
}

#[test]
fn success_is_0_error_1_usage_2() {
    let data = examples().join("dataset1.csv");
    let o = run(&["curve", "fit", data.to_str().unwrap(), "-q"]);
    assert_eq!(o.status.code(), Some(0));
    no_panic(&o.stderr);

    let o = run(&["curve", "fit", "/nonexistent/points.csv", "-q"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.starts_with("error: /nonexistent/points.csv:"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");

    // a value the option refuses is bad input like any other (status 1)
    let o = run(&["curve", "fit", data.to_str().unwrap(), "--degree", "three"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("invalid value 'three'"));
    let o = run(&["no-such-command"]);
    assert_eq!(o.status.code(), Some(2));
    // --help succeeds, on stdout
    let o = run(&["--help"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stdout).contains("Usage:"));
}

#[test]
fn warnings_of_the_readers_are_printed() {
    let dir = tmpdir("exit", "warn");
    let pts = dir.join("scan.pts");
    std::fs::write(&pts, "5\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n").unwrap();
    let o = run(&["cloud", "info", pts.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning: ")
            && err.contains("scan.pts:1: the count line declares 5 points, but the file holds 4"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A pipe whose reading end is already closed, as the command's stdout:
/// the read end belongs to a child that exits without reading (`scanfit
/// --version`), and it has exited before this returns, so the first write
/// to the pipe fails with EPIPE however fast or slow either process is.
fn pipe_without_reader() -> Stdio {
    let mut reader = bin()
        .arg("--version")
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let write_end = reader.stdin.take().unwrap();
    assert!(reader.wait().unwrap().success());
    Stdio::from(write_end)
}

#[test]
fn closed_stdout_is_141_without_a_panic() {
    // the reader of stdout has gone before the command prints anything
    let data = examples().join("dataset5.csv");
    for args in [
        vec!["cloud", "info", data.to_str().unwrap(), "--json"],
        vec!["cloud", "info", data.to_str().unwrap()],
        vec!["--help"],
    ] {
        let mut child = bin()
            .args(&args)
            .stdout(pipe_without_reader())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut err = Vec::new();
        child.stderr.take().unwrap().read_to_end(&mut err).unwrap();
        let status = child.wait().unwrap();
        assert_eq!(
            status.code(),
            Some(141),
            "{args:?}: {}",
            String::from_utf8_lossy(&err)
        );
        assert!(
            err.is_empty(),
            "{args:?}: {}",
            String::from_utf8_lossy(&err)
        );
    }
}

#[test]
fn closed_stderr_never_panics() {
    // an error with nobody reading stderr: still exit 1, not a panic (101)
    let mut child = bin()
        .args(["curve", "fit", "/nonexistent/points.csv"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    assert_eq!(child.wait().unwrap().code(), Some(1));
    // a usage error likewise exits 2
    let mut child = bin()
        .args(["curve", "fit", "--no-such-option"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    assert_eq!(child.wait().unwrap().code(), Some(2));
    // a success that prints only on stdout is unaffected
    let data = examples().join("dataset1.csv");
    let mut child = bin()
        .args(["cloud", "info", data.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    let mut out = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    assert_eq!(child.wait().unwrap().code(), Some(0));
    assert!(out.contains("points"), "{out}");
    // stderr closed outright (not a pipe): the same
    let o = bin()
        .args(["curve", "fit", "/nonexistent/points.csv"])
        .stderr(Stdio::null())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
}

#[test]
fn an_output_given_twice_or_equal_to_the_input_is_refused_before_work() {
    let dir = tmpdir("exit", "paths");
    let doc = dir.join("c.json");
    std::fs::copy(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fuzz/corpus/curve_json/cubic.json"),
        &doc,
    )
    .unwrap();
    let out = dir.join("out.stp");
    let o = run(&[
        "export",
        doc.to_str().unwrap(),
        "--step",
        out.to_str().unwrap(),
        "--iges",
        dir.join("./out.stp").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("this output is given twice"), "{err}");
    assert!(!out.exists());
    let o = run(&[
        "export",
        doc.to_str().unwrap(),
        "--step",
        doc.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("this output is the input file"), "{err}");
    assert!(std::fs::read_to_string(&doc)
        .unwrap()
        .contains("bspline_curve"));
    // the same command with distinct outputs works
    let o = run(&[
        "export",
        doc.to_str().unwrap(),
        "--step",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
