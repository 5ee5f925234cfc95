//! Build, test, flash and size tasks: everything that drives cargo, rustup
//! and probe-rs.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

/// The firmware's compilation target (Cortex-M4F with hardware FPU).
pub const TARGET: &str = "thumbv7em-none-eabihf";
/// probe-rs chip name of the STM32F4DISCOVERY's MCU.
pub const CHIP: &str = "STM32F407VGTx";
/// Release-image budget for flash (text + data), bytes (SPEC §2: sectors
/// 0–6; the saved settings use sectors 10–11).
pub const FLASH_BUDGET_BYTES: u64 = 384 * 1024;
/// Release-image budget for static RAM (data + bss), bytes (SPEC §2).
pub const RAM_BUDGET_BYTES: u64 = 96 * 1024;
/// rustup components the project uses (llvm-tools provides `llvm-size`).
const COMPONENTS: [&str; 3] = ["rustfmt", "clippy", "llvm-tools"];
/// Crates that build for the host (everything but the firmware binary).
pub const HOST_PACKAGES: &[&str] = &[
    "kinematics-core",
    "galvo-planner",
    "fashionstar",
    "pelco",
    "laser-app",
    "galvo-dma",
    "laser-sim",
    "xtask",
    "camera-calib",
    "system-tests",
    "fuzz-props",
];
/// `no_std` crates that must also build for the target.
pub const TARGET_LIBRARIES: &[&str] = &[
    "kinematics-core",
    "galvo-planner",
    "fashionstar",
    "pelco",
    "laser-app",
    "galvo-dma",
];

/// Root of the workspace (the parent of `xtask/`).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// Runs a command in the workspace root, echoing it first; fails on a
/// non-zero exit.
pub fn run(program: &str, args: &[&str]) -> Result<()> {
    run_with_env(program, args, &[])
}

/// [`run`] with extra environment variables (`(name, value)` pairs).
pub fn run_with_env(program: &str, args: &[&str], env: &[(&str, &std::ffi::OsStr)]) -> Result<()> {
    println!("$ {program} {}", args.join(" "));
    let status = Command::new(program)
        .args(args)
        .envs(env.iter().copied())
        .current_dir(workspace_root())
        .status()
        .with_context(|| format!("could not start `{program}`"))?;
    if !status.success() {
        bail!("`{program} {}` failed ({status})", args.join(" "));
    }
    Ok(())
}

fn rustup_list(kind: &str) -> Result<String> {
    let out = Command::new("rustup")
        .args([kind, "list", "--installed"])
        .current_dir(workspace_root())
        .output()
        .context("`rustup` not found: install Rust with rustup (https://rustup.rs)")?;
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Installs the firmware target and the components listed in
/// `rust-toolchain.toml` when they are missing (RUSTUP_AUTO_INSTALL=0 means
/// rustup will not do it by itself).
pub fn ensure_toolchain() -> Result<()> {
    let targets = rustup_list("target")?;
    if !targets.lines().any(|l| l.trim() == TARGET) {
        run("rustup", &["target", "add", TARGET])?;
    }
    let components = rustup_list("component")?;
    for component in COMPONENTS {
        let installed = components
            .lines()
            .any(|l| l.trim().starts_with(&format!("{component}-")) || l.trim() == component);
        if !installed {
            run("rustup", &["component", "add", component])?;
        }
    }
    Ok(())
}

/// Installs flip-link, the firmware's linker wrapper (`.cargo/config.toml`:
/// stack below `.data`/`.bss`, so an overflow faults instead of corrupting
/// them), with `cargo install flip-link --locked` when it is not on `PATH`.
pub fn ensure_flip_link() -> Result<()> {
    // flip-link has no `--version`; whether it starts at all is the test.
    match Command::new("flip-link").output() {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            println!(
                "flip-link (the firmware's stack-overflow-protecting linker) is not installed: \
                 installing it with `cargo install flip-link --locked`"
            );
            run("cargo", &["install", "flip-link", "--locked"])
        }
        Err(e) => Err(e).context("could not start `flip-link`"),
        Ok(_) => Ok(()),
    }
}

/// Builds the release firmware and returns the path of the ELF image.
pub fn build_firmware() -> Result<PathBuf> {
    ensure_toolchain()?;
    ensure_flip_link()?;
    run(
        "cargo",
        &["build", "--release", "--target", TARGET, "-p", "firmware"],
    )?;
    Ok(target_dir().join(TARGET).join("release").join("firmware"))
}

/// Cargo's target directory: `CARGO_TARGET_DIR` when set (relative to the
/// workspace root), else `target/` in the workspace root.
pub fn target_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) if !dir.is_empty() => workspace_root().join(dir),
        _ => workspace_root().join("target"),
    }
}

/// Builds and flashes the firmware through probe-rs (`cargo run` uses the
/// runner configured in `.cargo/config.toml`).
pub fn flash() -> Result<()> {
    let probe_rs = Command::new("probe-rs").arg("--version").output();
    if probe_rs.is_err() {
        bail!(
            "probe-rs is not installed. Install it with\n  \
             cargo install probe-rs-tools --locked\n\
             (or see https://probe.rs/docs/getting-started/installation/), \
             connect the STM32F4DISCOVERY's ST-LINK USB port and run `cargo xtask flash` again."
        );
    }
    let elf = build_firmware()?;
    let elf = elf.to_string_lossy().into_owned();
    run("probe-rs", &["run", "--chip", CHIP, &elf])
}

/// Sections of a firmware image, bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageSize {
    pub text: u64,
    pub data: u64,
    pub bss: u64,
}

impl ImageSize {
    /// Bytes stored in flash (code, constants, initialised-data image).
    pub fn flash_bytes(&self) -> u64 {
        self.text + self.data
    }
    /// Bytes of statically allocated RAM (initialised data + zeroed data).
    pub fn ram_bytes(&self) -> u64 {
        self.data + self.bss
    }
}

/// Parses the Berkeley-format output of `llvm-size` (header line, then
/// `text data bss dec hex filename`).
pub fn parse_berkeley_size(output: &str) -> Result<ImageSize> {
    let line = output
        .lines()
        .nth(1)
        .context("llvm-size printed no size line")?;
    let fields: Vec<u64> = line
        .split_whitespace()
        .take(3)
        .map(str::parse)
        .collect::<Result<_, _>>()
        .with_context(|| format!("unexpected llvm-size line: {line:?}"))?;
    match fields.as_slice() {
        [text, data, bss] => Ok(ImageSize {
            text: *text,
            data: *data,
            bss: *bss,
        }),
        _ => bail!("unexpected llvm-size line: {line:?}"),
    }
}

pub fn llvm_size_path() -> Result<PathBuf> {
    let out = Command::new("rustc")
        .args(["--print", "sysroot"])
        .current_dir(workspace_root())
        .output()
        .context("rustc not found")?;
    let sysroot = String::from_utf8_lossy(&out.stdout).trim().to_owned();
    let host = Command::new("rustc")
        .args(["--print", "host-tuple"])
        .current_dir(workspace_root())
        .output()
        .context("rustc not found")?;
    let host = String::from_utf8_lossy(&host.stdout).trim().to_owned();
    let path = Path::new(&sysroot)
        .join("lib/rustlib")
        .join(host)
        .join("bin/llvm-size");
    if !path.exists() {
        bail!(
            "llvm-size not found at {}: run `rustup component add llvm-tools`",
            path.display()
        );
    }
    Ok(path)
}

/// `cargo xtask size`: builds the release image, prints text/data/bss and
/// its largest stack frames, and fails when it exceeds the flash or RAM
/// budget or a frame exceeds the frame budget.
pub fn size() -> Result<()> {
    // Always (re)build: a stale ELF would report an old size.
    let elf = build_firmware()?;
    let llvm_size = llvm_size_path()?;
    let out = Command::new(&llvm_size)
        .arg(&elf)
        .output()
        .context("could not run llvm-size")?;
    if !out.status.success() {
        bail!("llvm-size failed: {}", String::from_utf8_lossy(&out.stderr));
    }
    let size = parse_berkeley_size(&String::from_utf8_lossy(&out.stdout))?;
    println!(
        "firmware size: text {} B, data {} B, bss {} B",
        size.text, size.data, size.bss
    );
    println!(
        "  flash {:>7} B of {:>7} B budget ({:.1} %)",
        size.flash_bytes(),
        FLASH_BUDGET_BYTES,
        100.0 * size.flash_bytes() as f64 / FLASH_BUDGET_BYTES as f64
    );
    println!(
        "  RAM   {:>7} B of {:>7} B budget ({:.1} %)",
        size.ram_bytes(),
        RAM_BUDGET_BYTES,
        100.0 * size.ram_bytes() as f64 / RAM_BUDGET_BYTES as f64
    );
    crate::size_gcode::report(&elf, &llvm_size)?;
    check_budget(size)?;
    crate::size_stack::report(&elf, &llvm_size)
}

/// Fails with a clear message when the image is over budget.
pub fn check_budget(size: ImageSize) -> Result<()> {
    if size.flash_bytes() > FLASH_BUDGET_BYTES {
        bail!(
            "firmware flash use {} B exceeds the {} B budget by {} B",
            size.flash_bytes(),
            FLASH_BUDGET_BYTES,
            size.flash_bytes() - FLASH_BUDGET_BYTES
        );
    }
    if size.ram_bytes() > RAM_BUDGET_BYTES {
        bail!(
            "firmware static RAM use {} B exceeds the {} B budget by {} B",
            size.ram_bytes(),
            RAM_BUDGET_BYTES,
            size.ram_bytes() - RAM_BUDGET_BYTES
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_llvm_size_berkeley_output() {
        let out = "   text\t   data\t    bss\t    dec\t    hex\tfilename\n  41236\t     56\t  12044\t  53336\t   d058\tfirmware\n";
        let size = parse_berkeley_size(out).unwrap();
        assert_eq!(
            size,
            ImageSize {
                text: 41236,
                data: 56,
                bss: 12044
            }
        );
        assert_eq!(size.flash_bytes(), 41292);
        assert_eq!(size.ram_bytes(), 12100);
    }

    #[test]
    fn rejects_garbage_size_output() {
        assert!(parse_berkeley_size("").is_err());
        assert!(parse_berkeley_size("header\nnot numbers here\n").is_err());
    }

    #[test]
    fn budget_check_names_the_overrun() {
        let ok = ImageSize {
            text: 100_000,
            data: 1_000,
            bss: 60_000,
        };
        assert!(check_budget(ok).is_ok());
        let big_flash = ImageSize {
            text: FLASH_BUDGET_BYTES,
            data: 1,
            bss: 0,
        };
        let err = check_budget(big_flash).unwrap_err().to_string();
        assert!(err.contains("flash"), "{err}");
        let big_ram = ImageSize {
            text: 10,
            data: 0,
            bss: RAM_BUDGET_BYTES + 5,
        };
        let err = check_budget(big_ram).unwrap_err().to_string();
        assert!(err.contains("RAM") && err.contains("by 5 B"), "{err}");
    }
}
