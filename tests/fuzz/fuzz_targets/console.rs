//! Console bytes → line assembler → parser → settings (see fuzz_props::console).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_props::console::check(data);
});
