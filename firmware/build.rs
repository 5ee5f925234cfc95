//! Puts the board's `memory.x` on the linker search path for cortex-m-rt's `link.x`.
//! (It lives here, not in the workspace root: the linker runs in the root and
//! would find a root `memory.x` first, also for firmware/bench-m4's board.)
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let memory_x = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("memory.x");
    fs::copy(&memory_x, out.join("memory.x")).expect("copy memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
}
