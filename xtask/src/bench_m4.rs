//! `cargo xtask bench-m4`: the project's hot paths on the Cortex-M4F
//! instruction set, with budgets.
//!
//! Builds `firmware/bench-m4` (release profile, the crates as the firmware
//! builds them; a workspace of its own, so its linker finds the MPS2
//! board's `memory.x`, not the workspace root's STM32F407 one) and runs it on QEMU's `mps2-an386` (Cortex-M4F) with
//! `-icount shift=0`: the virtual clock advances 1 ns per guest
//! instruction, so the board's 25 MHz timer ticks once per 40 instructions
//! (calibrated every run on an assembly loop of known length). Instruction
//! counts are exact up to one tick per window and deterministic;
//! microseconds are estimated at [`CLOCK_MHZ`](report::CLOCK_MHZ) with [`CPI`](report::CPI) cycles per
//! instruction. Not modelled: flash wait states (the ART accelerator hides
//! most), the VDIV/VSQRT latency (14 cycles each), bus contention with DMA.
//!
//! Besides chosen inputs, seeded random sweeps (`sweep.*` rows: 3 000
//! two-axis jumps, 200 strokes with close corners, in the same QEMU run,
//! one timer window per input) report their dearest input, and the
//! budgets apply to it (see `docs/bench-m4-sweeps.md`).

mod budgets;
mod gcode_rows;
mod pelco_rows;
pub(crate) mod qemu;
mod report;
mod stepper_rows;

use std::path::PathBuf;
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::toolchain::{TARGET, ensure_flip_link, target_dir, workspace_root};
use qemu::{ensure_qemu, run_qemu};
use report::{check, parse, print};

/// The bench's manifest, relative to the workspace root. It is a workspace
/// of its own (the root one excludes it): cargo runs its rustc, and so the
/// linker, in `firmware/bench-m4/`, where cortex-m-rt's `INCLUDE memory.x`
/// finds the MPS2 board's map before the root's STM32F407 one.
pub const MANIFEST: &str = "firmware/bench-m4/Cargo.toml";

/// Runs `cargo <args> --manifest-path firmware/bench-m4/Cargo.toml` (see
/// [`cargo_in`]).
pub fn cargo(args: &[&str]) -> Result<()> {
    cargo_in(MANIFEST, args)
}

/// Runs `cargo <args> --manifest-path <manifest>` in the workspace root (so
/// the root's `.cargo/config.toml` applies: target rustflags, flip-link)
/// with the root's target directory: for the workspaces of their own on
/// the MPS2 board (this bench, `firmware/qemu-m4`).
pub fn cargo_in(manifest: &str, args: &[&str]) -> Result<()> {
    let (command, rest) = args.split_first().context("cargo without a command")?;
    let target = target_dir();
    println!(
        "$ CARGO_TARGET_DIR={} cargo {command} --manifest-path {manifest} {}",
        target.display(),
        rest.join(" ")
    );
    let status = Command::new("cargo")
        .arg(command)
        .args(["--manifest-path", manifest])
        .args(rest)
        .env("CARGO_TARGET_DIR", &target)
        .current_dir(workspace_root())
        .status()
        .context("could not start `cargo`")?;
    if !status.success() {
        bail!(
            "`cargo {}` for {manifest} failed ({status})",
            args.join(" ")
        );
    }
    Ok(())
}

/// `cargo xtask bench-m4`: runs the benchmark on QEMU, prints and writes
/// its table, checks the budgets; returns the JSON table's path.
pub fn bench_m4() -> Result<PathBuf> {
    ensure_qemu()?;
    ensure_flip_link()?;
    cargo(&["build", "--release", "--target", TARGET])?;
    let elf = target_dir().join(TARGET).join("release").join("bench-m4");
    let out = run_qemu(&elf)?;
    let report = parse(&out)?;
    print(&report);
    let json = target_dir().join("bench-m4.json");
    std::fs::write(&json, serde_json::to_string_pretty(&report)?)
        .with_context(|| format!("could not write {}", json.display()))?;
    println!("table written to {}", json.display());
    check(&report)?;
    Ok(json)
}

#[cfg(test)]
mod tests;
