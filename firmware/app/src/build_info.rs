//! What was built: version, git revision, profile and target.

/// Crate version (from Cargo.toml).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// `git describe --always --dirty` at build time, or "unknown".
pub const GIT_REV: &str = env!("LASER_GIT_REV");
/// Cargo profile the firmware was built with (`release` / `debug`).
pub const PROFILE: &str = env!("LASER_BUILD_PROFILE");
/// Target triple the firmware was built for.
pub const TARGET: &str = env!("LASER_BUILD_TARGET");
/// Product name shown by `version`.
pub const PRODUCT: &str = "laser-pointer";
