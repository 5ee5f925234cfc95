//! Console bytes → realtime filter → line assembly → G-code parser / `$`
//! commands (see fuzz_props::grbl).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_props::grbl::check(data);
});
