//! The board's image: `firmware/qemu-m4` built for the target with a
//! feature set.

use std::path::PathBuf;

use anyhow::{Context, Result};

use crate::toolchain::{TARGET, ensure_flip_link, target_dir};

/// The board's manifest, relative to the workspace root (a workspace of its
/// own, like the bench's).
pub const MANIFEST: &str = "firmware/qemu-m4/Cargo.toml";

/// Builds the board's release image with the default features; its path.
pub fn build_image() -> Result<PathBuf> {
    build_image_with(&[], false)
}

/// Builds the board's release image with `features` (after
/// `--no-default-features` when `no_default`); its path (a copy named
/// after the features).
pub fn build_image_with(features: &[&str], no_default: bool) -> Result<PathBuf> {
    crate::bench_m4::qemu::ensure_qemu()?;
    ensure_flip_link()?;
    let mut args = vec!["build", "--release", "--target", TARGET];
    if no_default {
        args.push("--no-default-features");
    }
    let joined = features.join(",");
    if !features.is_empty() {
        args.extend(["--features", joined.as_str()]);
    }
    crate::bench_m4::cargo_in(MANIFEST, &args)?;
    let built = target_dir().join(TARGET).join("release").join("qemu-m4");
    // Cargo writes every feature set to the same file: keep a copy per
    // set, so images built one after the other (`--scenarios`) stay apart.
    let mut name = String::from("qemu-m4-");
    name.push_str(if no_default { "no-default" } else { "default" });
    for feature in features {
        name.push('-');
        name.push_str(feature);
    }
    let copy = built.with_file_name(name);
    std::fs::copy(&built, &copy)
        .with_context(|| format!("cannot copy {} to {}", built.display(), copy.display()))?;
    Ok(copy)
}
