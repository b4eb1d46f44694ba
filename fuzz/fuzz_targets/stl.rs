//! Fuzz target: the stl reader (`scanfit_io::fuzz::point_file` with a `.stl` name).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    scanfit_io::fuzz::point_file("f.stl", data);
});
