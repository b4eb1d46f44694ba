//! Fuzz target: the laz reader (`scanfit_io::fuzz_point_file` with a `.laz` name).
//!
//! With `SCANFIT_FUZZ_LAST=FILE` in the environment every input is written
//! to FILE before it is read, so an input that kills the process in a way
//! libFuzzer cannot catch (a stack overflow, which aborts before libFuzzer
//! can save it) is still on disk afterwards.
#![no_main]

use std::sync::OnceLock;

static LAST: OnceLock<Option<std::path::PathBuf>> = OnceLock::new();

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Some(path) = LAST.get_or_init(|| std::env::var_os("SCANFIT_FUZZ_LAST").map(Into::into)) {
        let _ = std::fs::write(path, data);
    }
    // a disagreement between two readers of the bytes is a finding
    if let Err(e) = scanfit_io::fuzz::point_file("f.laz", data) {
        panic!("{e}");
    }
});
