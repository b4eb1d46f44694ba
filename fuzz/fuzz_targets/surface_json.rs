//! Fuzz target: the surface JSON document reader.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    scanfit_io::fuzz::surface_document(data);
});
