//! Link setup for the MPS2 AN386 board: this crate's `memory.x` and
//! `device.x` for cortex-m-rt's `link.x`, and an empty `defmt.x` because the
//! workspace's `.cargo/config.toml` passes `-Tdefmt.x` for every thumbv7em
//! binary and this board logs plain text (see `firmware/bench-m4/build.rs`
//! for why the linker finds these files and not the workspace root's).
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for file in ["memory.x", "device.x"] {
        fs::copy(dir.join(file), out.join(file)).expect("copy the link script to OUT_DIR");
        println!("cargo:rerun-if-changed={file}");
    }
    // With `defmt-log` the defmt crate's own defmt.x is the one to find.
    if env::var_os("CARGO_FEATURE_DEFMT_LOG").is_none() {
        fs::write(
            out.join("defmt.x"),
            "/* qemu-m4 links no defmt: intentionally empty */\n",
        )
        .expect("write defmt.x to OUT_DIR");
    }
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=build.rs");
}
