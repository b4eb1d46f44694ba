//! Fuzz target: the pcd reader (`scanfit_io::fuzz_point_file` with a `.pcd` name).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // a disagreement between two readers of the bytes is a finding
    if let Err(e) = scanfit_io::fuzz::point_file("f.pcd", data) {
        panic!("{e}");
    }
});
