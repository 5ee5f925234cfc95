//! FashionStar request/response decoders and encoders (see fuzz_props::servo).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_props::servo::check(data);
});
