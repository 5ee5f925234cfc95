//! Property checks behind the fuzz targets, in one place: the cargo-fuzz
//! targets in `tests/fuzz/` call them on every generated input, and the
//! stable tests in `tests/corpus.rs` call them on every saved corpus and
//! regression input, so `cargo xtask test` re-checks what the fuzzer kept.
//!
//! Each check takes arbitrary bytes, panics when a property fails (the
//! message says which) and otherwise returns a summary of what the input
//! exercised, which the corpus tests use to prove that the saved seeds
//! reach every command word, frame code, record and CSV path.

pub mod calib;
pub mod console;
pub mod grbl;
pub mod pelco;
pub mod pelco_junk;
pub mod record;
pub mod servo;

/// Every fuzz target: the `[[bin]]` names in `tests/fuzz/Cargo.toml` and
/// the folders of `tests/fuzz/corpus/`. `console` runs [`console::check`],
/// `servo_protocol` [`servo::check`], `settings_record` [`record::check`],
/// `calib_csv` [`calib::check`], `grbl` [`grbl::check`], `pelco`
/// [`pelco::check`].
pub const TARGETS: [&str; 6] = [
    "console",
    "servo_protocol",
    "settings_record",
    "calib_csv",
    "grbl",
    "pelco",
];

/// Reads fields from fuzz input bytes: past the end every read is 0, so
/// any input (even empty) yields a value.
pub(crate) struct Bytes<'a> {
    rest: &'a [u8],
}

impl<'a> Bytes<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Self { rest: data }
    }

    pub(crate) fn array<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let n = N.min(self.rest.len());
        out[..n].copy_from_slice(&self.rest[..n]);
        self.rest = &self.rest[n..];
        out
    }

    pub(crate) fn u8(&mut self) -> u8 {
        self.array::<1>()[0]
    }

    pub(crate) fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.array())
    }

    pub(crate) fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.array())
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.rest.is_empty()
    }
}
