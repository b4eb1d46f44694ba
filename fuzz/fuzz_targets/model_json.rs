//! Fuzz target: the model JSON document reader (multi-patch models).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    scanfit_io::fuzz::model_document(data);
});
