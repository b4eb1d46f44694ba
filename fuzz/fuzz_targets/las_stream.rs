//! Fuzz target: the streamed LAS/LAZ reader (`PointChunks`, small chunks,
//! the smallest pointwise LAZ window) against the whole-file reader
//! (`scanfit_io::fuzz::streamed_las_file`): they must agree bit for bit.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // a disagreement between two readers of the bytes is a finding
    if let Err(e) = scanfit_io::fuzz::streamed_las_file(data) {
        panic!("{e}");
    }
});
