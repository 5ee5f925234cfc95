//! The saved settings record (see fuzz_props::record).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_props::record::check(data);
});
