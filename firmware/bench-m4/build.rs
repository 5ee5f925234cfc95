//! Link setup for the MPS2 AN386 board: this crate's `memory.x` for
//! cortex-m-rt's `link.x`, and an empty `defmt.x` because the workspace's
//! `.cargo/config.toml` passes `-Tdefmt.x` for every thumbv7em binary and
//! the bench does not use defmt.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    fs::copy(dir.join("memory.x"), out.join("memory.x")).expect("copy memory.x to OUT_DIR");
    fs::write(
        out.join("defmt.x"),
        "/* bench-m4 links no defmt: intentionally empty */\n",
    )
    .expect("write defmt.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
