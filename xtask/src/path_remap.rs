//! Panic locations in the firmware name crates.io sources by their path in
//! the registry. That path holds `CARGO_HOME`, so the image's size would
//! depend on the machine that built it (≈ 1.4 KB between `/root/.cargo`
//! and a longer home). Every target build that xtask starts remaps the
//! registry's source folders to a fixed short prefix, computed here from
//! the real `CARGO_HOME`, so `cargo xtask size` reports the same figure on
//! any machine.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// Cargo's environment variable for extra rustc flags on the firmware
/// target (merged with `.cargo/config.toml`'s `rustflags`).
pub const TARGET_RUSTFLAGS_VAR: &str = "CARGO_TARGET_THUMBV7EM_NONE_EABIHF_RUSTFLAGS";

/// The prefix registry sources get in the image.
const REGISTRY_PREFIX: &str = "crates.io";
/// The prefix everything else under `CARGO_HOME` (git checkouts) gets.
const HOME_PREFIX: &str = "cargo-home";

/// `CARGO_HOME` as cargo resolves it: the variable when set (relative to
/// the current directory), else `$HOME/.cargo`.
pub fn cargo_home(cargo_home_var: Option<OsString>, home: Option<PathBuf>) -> Option<PathBuf> {
    match cargo_home_var {
        Some(dir) if !dir.is_empty() => {
            let dir = PathBuf::from(dir);
            if dir.is_absolute() {
                Some(dir)
            } else {
                std::env::current_dir().ok().map(|cwd| cwd.join(dir))
            }
        }
        _ => home.map(|h| h.join(".cargo")),
    }
}

/// The `--remap-path-prefix` flags for `cargo_home` with the registry
/// folders `registries` (names under `registry/src`, e.g.
/// `index.crates.io-1949cf8c6b5b557f`). rustc applies the last matching
/// mapping, so the general one comes first. `None` when a path holds
/// whitespace (cargo splits the variable on it).
pub fn remap_flags(cargo_home: &Path, registries: &[String]) -> Option<Vec<String>> {
    let home = cargo_home.to_str()?.trim_end_matches('/');
    if home.is_empty() || home.contains(char::is_whitespace) {
        return None;
    }
    let mut flags = vec![format!("--remap-path-prefix={home}={HOME_PREFIX}")];
    for name in registries {
        if name.contains(char::is_whitespace) {
            return None;
        }
        flags.push(format!(
            "--remap-path-prefix={home}/registry/src/{name}={REGISTRY_PREFIX}"
        ));
    }
    Some(flags)
}

/// Names of the registries cargo knows (folders under `registry/index`,
/// `registry/cache` or `registry/src`), sorted, without repeats.
pub fn registry_names(cargo_home: &Path) -> Vec<String> {
    let mut names: Vec<String> = ["index", "cache", "src"]
        .iter()
        .filter_map(|dir| std::fs::read_dir(cargo_home.join("registry").join(dir)).ok())
        .flatten()
        .filter_map(Result::ok)
        .filter(|entry| entry.path().is_dir())
        .filter_map(|entry| entry.file_name().into_string().ok())
        .collect();
    names.sort();
    names.dedup();
    names
}

/// Appends the remap flags to [`TARGET_RUSTFLAGS_VAR`] for every cargo
/// that xtask starts. Runs `cargo fetch` first so that the registry folders
/// exist on a fresh machine (the flags, and so the build, are then the same
/// on the first run as on every later one).
pub fn apply() -> anyhow::Result<()> {
    let Some(home) = cargo_home(
        std::env::var_os("CARGO_HOME"),
        std::env::var_os("HOME").map(PathBuf::from),
    ) else {
        eprintln!("warning: no CARGO_HOME or HOME: firmware panic paths are not remapped");
        return Ok(());
    };
    if registry_names(&home).is_empty() {
        crate::toolchain::run("cargo", &["fetch", "--quiet"])?;
    }
    let Some(flags) = remap_flags(&home, &registry_names(&home)) else {
        eprintln!(
            "warning: CARGO_HOME {} holds whitespace: firmware panic paths are not remapped \
             (the image is larger than on other machines)",
            home.display()
        );
        return Ok(());
    };
    let mut value = std::env::var(TARGET_RUSTFLAGS_VAR).unwrap_or_default();
    for flag in flags {
        if !value.split_whitespace().any(|f| f == flag) {
            if !value.is_empty() {
                value.push(' ');
            }
            value.push_str(&flag);
        }
    }
    // SAFETY: called once at the start of `main`, before any thread exists.
    unsafe { std::env::set_var(TARGET_RUSTFLAGS_VAR, value) };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cargo_home_follows_the_variable_then_home() {
        assert_eq!(
            cargo_home(Some("/opt/cargo".into()), Some("/home/a".into())),
            Some(PathBuf::from("/opt/cargo"))
        );
        assert_eq!(
            cargo_home(None, Some("/home/a".into())),
            Some(PathBuf::from("/home/a/.cargo"))
        );
        assert_eq!(
            cargo_home(Some("".into()), Some("/home/a".into())),
            Some(PathBuf::from("/home/a/.cargo"))
        );
        assert_eq!(cargo_home(None, None), None);
    }

    #[test]
    fn every_home_maps_registry_sources_to_the_same_prefix() {
        let names = vec!["index.crates.io-1949cf8c6b5b557f".to_owned()];
        for home in ["/root/.cargo", "/home/someone/with/a/long/path/.cargo/"] {
            let flags = remap_flags(Path::new(home), &names).unwrap();
            let home = home.trim_end_matches('/');
            assert_eq!(
                flags,
                vec![
                    format!("--remap-path-prefix={home}=cargo-home"),
                    format!(
                        "--remap-path-prefix={home}/registry/src/index.crates.io-1949cf8c6b5b557f=crates.io"
                    ),
                ]
            );
        }
    }

    #[test]
    fn whitespace_in_the_home_is_refused() {
        assert_eq!(remap_flags(Path::new("/home/my user/.cargo"), &[]), None);
        assert_eq!(remap_flags(Path::new("/"), &[]), None);
    }

    #[test]
    fn registry_names_come_from_the_registry_folders() {
        let home = std::env::temp_dir().join(format!("xtask-remap-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&home);
        std::fs::create_dir_all(home.join("registry/index/index.crates.io-aaa")).unwrap();
        std::fs::create_dir_all(home.join("registry/src/index.crates.io-aaa")).unwrap();
        std::fs::create_dir_all(home.join("registry/cache/other-bbb")).unwrap();
        std::fs::write(home.join("registry/src/stray-file"), b"").unwrap();
        let names = registry_names(&home);
        std::fs::remove_dir_all(&home).unwrap();
        assert_eq!(names, vec!["index.crates.io-aaa", "other-bbb"]);
    }
}
