//! Fuzz target: the curve JSON document reader.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    scanfit_io::fuzz::curve_document(data);
});
