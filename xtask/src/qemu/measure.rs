//! `cargo xtask qemu --measure`: the figures of the README's QEMU section,
//! from the emulated board itself: image size, instructions per command and
//! per second of holding (busy time under `-icount shift=0`, 1 instruction
//! per ns), the painted peak stack of each task, and what laser-app's logs
//! on the log channel cost (the same figures without them).

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

use super::machine::{Machine, MachineOptions};
use super::script::{parse_board_script, run_steps};
use crate::toolchain::{llvm_size_path, parse_berkeley_size};

/// Guest instructions per timer tick (25 MHz timer, 1 ns per instruction).
const INSTRUCTIONS_PER_TICK: u64 = 40;
/// Commands measured one by one.
const COMMANDS: [&str; 6] = [
    "version",
    "get dwell_ms",
    "status",
    "params",
    "help",
    "goto 5 5",
];
/// How long holding is measured.
const HOLD: Duration = Duration::from_secs(5);

/// One `@stats` report: timer ticks since boot, ticks asleep, stack text.
#[derive(Debug, Clone, PartialEq)]
pub struct Stats {
    /// Timer ticks since boot.
    pub ticks: u64,
    /// Ticks asleep in WFI.
    pub slept: u64,
    /// `name:bytes,…` (empty without stack painting).
    pub stack: String,
}

impl Stats {
    /// Parses `ticks=… slept=… stack=…`.
    pub fn parse(text: &str) -> Result<Self> {
        let field = |name: &str| {
            text.split_whitespace()
                .find_map(|w| w.strip_prefix(name)?.strip_prefix('='))
                .with_context(|| format!("no {name} in @stats {text:?}"))
        };
        Ok(Self {
            ticks: field("ticks")?.parse()?,
            slept: field("slept")?.parse()?,
            stack: field("stack")?.to_owned(),
        })
    }

    /// Instructions run between `earlier` and `self`.
    pub fn instructions_since(&self, earlier: &Stats) -> u64 {
        let busy = (self.ticks - earlier.ticks).saturating_sub(self.slept - earlier.slept);
        busy * INSTRUCTIONS_PER_TICK
    }

    /// Board seconds between `earlier` and `self`.
    pub fn seconds_since(&self, earlier: &Stats) -> f64 {
        (self.ticks - earlier.ticks) as f64 * INSTRUCTIONS_PER_TICK as f64 * 1e-9
    }
}

fn stats(machine: &mut Machine) -> Result<Stats> {
    Stats::parse(&machine.stats()?)
}

fn image_size(elf: &Path) -> Result<String> {
    let out = Command::new(llvm_size_path()?)
        .arg(elf)
        .output()
        .context("could not run llvm-size")?;
    let size = parse_berkeley_size(&String::from_utf8_lossy(&out.stdout))?;
    Ok(format!(
        "flash {} B (text {} + data {}), static RAM {} B (data {} + bss {})",
        size.flash_bytes(),
        size.text,
        size.data,
        size.ram_bytes(),
        size.data,
        size.bss
    ))
}

/// Holding and per-command instruction counts on a fresh board.
fn instructions(elf: &Path) -> Result<()> {
    let mut m = Machine::start(elf, &MachineOptions::default())?;
    std::thread::sleep(Duration::from_secs(1));
    let a = stats(&mut m)?;
    std::thread::sleep(HOLD);
    let b = stats(&mut m)?;
    let per_s = b.instructions_since(&a) as f64 / b.seconds_since(&a);
    println!("  holding (idle, health checks, LEDs): {per_s:.0} instructions/s");
    let empty = {
        let x = stats(&mut m)?;
        stats(&mut m)?.instructions_since(&x)
    };
    for command in COMMANDS {
        let before = stats(&mut m)?;
        m.type_line(command)?;
        if !m.replies_read(Instant::now() + Duration::from_secs(10)) {
            bail!("no reply to {command}");
        }
        let after = stats(&mut m)?;
        let background = (per_s * after.seconds_since(&before)) as u64;
        let cost = after
            .instructions_since(&before)
            .saturating_sub(empty + background);
        println!("  {command:<14} {cost:>8} instructions");
    }
    Ok(())
}

/// Peak stack per task over a grid pattern and the measured commands.
fn stack(elf: &Path) -> Result<()> {
    let mut m = Machine::start(elf, &MachineOptions::default())?;
    let mut script = String::from(
        "laser dwell\nset dwell_ms 50\nset grid.cols 2\nset grid.rows 2\npattern grid-full serpentine once\nwait 1500\nsave\n",
    );
    for c in COMMANDS {
        script.push_str(c);
        script.push('\n');
    }
    let steps = parse_board_script(&script)?;
    if !run_steps(&mut m, &steps, Instant::now() + Duration::from_secs(60))? {
        bail!("the stack workload did not finish");
    }
    let s = stats(&mut m)?;
    println!("  peak stack, bytes: {}", s.stack);
    Ok(())
}

/// Builds the image with `features` (`--no-default-features` first when
/// `no_default`); its path.
fn build(features: &[&str], no_default: bool) -> Result<std::path::PathBuf> {
    let mut args = vec!["build", "--release", "--target", crate::toolchain::TARGET];
    if no_default {
        args.push("--no-default-features");
    }
    let joined = features.join(",");
    if !features.is_empty() {
        args.extend(["--features", joined.as_str()]);
    }
    crate::bench_m4::cargo_in(super::MANIFEST, &args)?;
    Ok(crate::toolchain::target_dir()
        .join(crate::toolchain::TARGET)
        .join("release")
        .join("qemu-m4"))
}

/// Runs the measurements and prints them.
pub fn measure() -> Result<()> {
    crate::bench_m4::qemu::ensure_qemu()?;
    crate::toolchain::ensure_flip_link()?;
    for (title, features, no_default) in [
        ("with laser-app's logs (default)", &[][..], false),
        ("without laser-app's logs", &[][..], true),
    ] {
        let elf = build(features, no_default)?;
        println!("qemu-m4 {title}: {}", image_size(&elf)?);
        instructions(&elf)?;
    }
    for (title, no_default) in [("with logs", false), ("without logs", true)] {
        let elf = build(&["stack-paint"], no_default)?;
        println!("qemu-m4 with stack painting, {title}:");
        stack(&elf)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_reports_parse_and_count_busy_time_as_instructions() {
        let a = Stats::parse("ticks=1000 slept=900 stack=").unwrap();
        let b = Stats::parse("ticks=26000 slept=25000 stack=console:800,other:96").unwrap();
        assert_eq!(b.stack, "console:800,other:96");
        assert_eq!(b.instructions_since(&a), (25_000 - 24_100) * 40);
        assert!((b.seconds_since(&a) - 0.001).abs() < 1e-12);
        assert!(Stats::parse("ticks=1").is_err());
    }
}
