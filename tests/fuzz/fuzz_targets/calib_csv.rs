//! The calibration CSV reader of `cargo xtask calib fit` (see fuzz_props::calib).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_props::calib::check(data);
});
