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
        if !m.replies_read(Instant::now() + Duration::from_secs(60)) {
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

/// The galvo loop on the board's DAC stream (feature `galvo-dac`):
/// instructions per board second holding and marking the tuning figure,
/// underruns, and how fast board time runs against the host clock.
fn galvo(elf: &Path) -> Result<()> {
    let mut m = Machine::start(elf, &MachineOptions::default())?;
    let deadline = Instant::now() + Duration::from_secs(60);
    let steps = parse_board_script("target galvo\nwait 500\n")?;
    if !run_steps(&mut m, &steps, deadline)? {
        bail!("target galvo did not answer");
    }
    let (host_a, a) = (Instant::now(), stats(&mut m)?);
    std::thread::sleep(HOLD);
    let (host_b, b) = (Instant::now(), stats(&mut m)?);
    let board_s = b.seconds_since(&a);
    println!(
        "  galvo holding at 100 kHz: {:.0} instructions per board second; board time ran at {:.0} % of host time",
        b.instructions_since(&a) as f64 / board_s,
        100.0 * board_s / (host_b - host_a).as_secs_f64()
    );
    let steps = parse_board_script("pattern tuning 0 0 8 once\n")?;
    let c = stats(&mut m)?;
    if !run_steps(&mut m, &steps, deadline)? || !super::script::wait_until_idle(&mut m, deadline)? {
        bail!("the tuning figure did not finish");
    }
    let d = stats(&mut m)?;
    println!(
        "  galvo marking the tuning figure: {:.0} instructions per board second over {:.2} s",
        d.instructions_since(&c) as f64 / d.seconds_since(&c),
        d.seconds_since(&c)
    );
    let before = m.terminal.0.lock().map(|t| t.lines.len()).unwrap_or(0);
    let steps = parse_board_script("galvo status\n")?;
    run_steps(&mut m, &steps, deadline)?;
    let lines = m
        .terminal
        .0
        .lock()
        .map(|t| t.lines.clone())
        .unwrap_or_default();
    for (_, line) in lines.iter().skip(before) {
        if line.starts_with("worst refill") {
            println!("  {line} (cycles: instructions)");
        }
        if line.starts_with("underruns") {
            println!("  {line}");
            if !line.starts_with("underruns: 0,") {
                bail!("the galvo loop underran on the emulated M4: {line}");
            }
        }
    }
    if !d.stack.is_empty() {
        println!("  peak stack, bytes: {}", d.stack);
    }
    Ok(())
}

/// Runs the measurements and prints them.
pub fn measure() -> Result<()> {
    for (title, features, no_default) in [
        ("with laser-app's logs (default)", &[][..], false),
        ("without laser-app's logs", &[][..], true),
    ] {
        let elf = super::image::build_image_with(features, no_default)?;
        println!("qemu-m4 {title}: {}", image_size(&elf)?);
        instructions(&elf)?;
    }
    let elf = super::image::build_image_with(&["galvo-dac"], false)?;
    println!("qemu-m4 with the galvo DAC stream: {}", image_size(&elf)?);
    galvo(&elf)?;
    let elf = super::image::build_image_with(&["galvo-dac", "stack-paint"], false)?;
    println!(
        "qemu-m4 with the galvo DAC stream and stack painting (instructions include the painting):"
    );
    galvo(&elf)?;
    for (title, no_default) in [("with logs", false), ("without logs", true)] {
        let elf = super::image::build_image_with(&["stack-paint"], no_default)?;
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
