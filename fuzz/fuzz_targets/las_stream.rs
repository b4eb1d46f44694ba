//! Fuzz target: the streamed LAS/LAZ reader (`PointChunks`, small chunks,
//! the smallest pointwise LAZ window) against the whole-file reader
//! (`scanfit_io::fuzz::streamed_las_file`): they must agree bit for bit.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    scanfit_io::fuzz::streamed_las_file(data);
});
