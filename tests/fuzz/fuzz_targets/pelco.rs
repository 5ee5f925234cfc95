//! PELCO-D / PELCO-P streaming decoder and encoders (see fuzz_props::pelco).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_props::pelco::check(data);
});
