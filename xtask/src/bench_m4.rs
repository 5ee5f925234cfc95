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
//! microseconds are estimated at [`CLOCK_MHZ`] with [`CPI`] cycles per
//! instruction. Not modelled: flash wait states (the ART accelerator hides
//! most), the VDIV/VSQRT latency (14 cycles each), bus contention with DMA.

use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use serde::Serialize;

use crate::toolchain::{TARGET, ensure_flip_link, run, target_dir, workspace_root};

/// STM32F407 core clock, MHz.
pub const CLOCK_MHZ: f64 = 168.0;
/// Cycles per instruction assumed for the estimate.
pub const CPI: f64 = 1.3;
/// Instructions per timer tick the board model implies (1 ns per
/// instruction, 25 MHz timer); the calibration must agree within 0.5 %.
const NOMINAL_INSTRUCTIONS_PER_TICK: f64 = 40.0;
/// DAC sample period at 100 kHz, µs.
const SAMPLE_US: f64 = 10.0;
/// One half buffer (128 samples at 100 kHz), µs.
const REFILL_WINDOW_US: f64 = 1280.0;
/// The whole run may take this long (wall clock) before it is killed.
const RUN_TIMEOUT: Duration = Duration::from_secs(120);

/// Whether a budget is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Enforcement {
    /// Exceeding it fails the run (and `cargo xtask test`).
    Enforced,
    /// Measured and reported, not yet met; the reason names the work.
    NotYetMet(&'static str),
}

/// One row of the table: what a benchmark id measures, per what unit,
/// and its budget (µs per unit) if it has one.
#[derive(Debug, Clone, Copy)]
pub struct Row {
    pub id: &'static str,
    pub what: &'static str,
    pub unit: &'static str,
    pub budget: Option<(f64, &'static str, Enforcement)>,
}

/// Time-optimal jump planning in single precision (galvo-planner
/// `fast_optimal`): met, enforced.
const PLANNING: Enforcement = Enforcement::Enforced;
/// The refill that starts a jump still plans it in the refill and then
/// steps its samples at the loop's per-sample cost.
const JUMP_REFILL: Enforcement = Enforcement::NotYetMet(
    "issue 11 item 3: planning out of the refill (prep stage) and the per-sample loop cost",
);
/// What is left per sample is the loop body around the f32 math: its
/// state machine, phase checks and sample bookkeeping (scan.rs), and the
/// Kahan-compensated integrator on jumps.
const LOOP: Enforcement =
    Enforcement::NotYetMet("issue 11: the loop's per-sample state machine (scan.rs)");
/// A stroke's first half also loads it into the f64 look-ahead planner.
const STROKE_SETUP: Enforcement =
    Enforcement::NotYetMet("issue 11 item 3: stroke setup (f64 path planning) in the refill");

/// Budget of a refill: half the refill window, µs per half.
const fn half_refill_budget(enforcement: Enforcement) -> Option<(f64, &'static str, Enforcement)> {
    Some((
        0.5 * REFILL_WINDOW_US,
        "50 % of the 1.28 ms refill",
        enforcement,
    ))
}

/// Every benchmark and its budget (issue 11, "Done when": 100 kHz, CPI 1.3
/// at 168 MHz). Budgets are µs per unit. `Enforced` ones fail the run
/// (and `cargo xtask test`); the others are reported with what is still
/// missing, and move to `Enforced` when that work lands.
pub const ROWS: &[Row] = &[
    Row {
        id: "loop.holding.steady",
        what: "loop, holding: hold sample, both DAC halves checked, nothing written",
        unit: "sample",
        budget: Some((
            0.05 * SAMPLE_US,
            "5 % of the 10 µs sample",
            Enforcement::Enforced,
        )),
    },
    Row {
        id: "loop.line.steady",
        what: "loop, marking a line (path + galvo IK + DAC)",
        unit: "sample",
        budget: Some((0.20 * SAMPLE_US, "20 % of the 10 µs sample", LOOP)),
    },
    Row {
        id: "loop.arc_r40.steady",
        what: "loop, marking a circle r = 40 mm",
        unit: "sample",
        budget: Some((0.20 * SAMPLE_US, "20 % of the 10 µs sample", LOOP)),
    },
    Row {
        id: "loop.jump.steady",
        what: "loop, jumping (integrator + DAC)",
        unit: "sample",
        budget: Some((0.10 * SAMPLE_US, "10 % of the 10 µs sample", LOOP)),
    },
    Row {
        id: "loop.holding.refill",
        what: "refill, holding: hold sample copied into the half (worst half)",
        unit: "half",
        budget: half_refill_budget(Enforcement::Enforced),
    },
    Row {
        id: "loop.line.refill",
        what: "refill, line job incl. stroke load (worst half)",
        unit: "half",
        budget: half_refill_budget(STROKE_SETUP),
    },
    Row {
        id: "loop.arc_r40.refill",
        what: "refill, circle job incl. stroke load (worst half)",
        unit: "half",
        budget: half_refill_budget(STROKE_SETUP),
    },
    Row {
        id: "loop.jump.refill",
        what: "refill that plans a 160 mm two-axis jump",
        unit: "half",
        budget: half_refill_budget(JUMP_REFILL),
    },
    Row {
        id: "loop.hold_sample",
        what: "GalvoLoop::hold_sample (idle: the rest position's codes)",
        unit: "call",
        budget: None,
    },
    Row {
        id: "loop.new",
        what: "GalvoLoop::new",
        unit: "call",
        budget: None,
    },
    Row {
        id: "integrator.xy.step",
        what: "integrator, both axes moving",
        unit: "sample",
        budget: None,
    },
    Row {
        id: "path.sample.line",
        what: "path sampler, line",
        unit: "sample",
        budget: None,
    },
    Row {
        id: "path.sample.arc",
        what: "path sampler, arc r = 40 mm",
        unit: "sample",
        budget: None,
    },
    Row {
        id: "galvo.board_to_codes.f32",
        what: "galvo IK + DAC, f32",
        unit: "point",
        budget: None,
    },
    Row {
        id: "galvo.sample_map.board_to_codes",
        what: "per-sample map: galvo IK + DAC, f32",
        unit: "point",
        budget: None,
    },
    Row {
        id: "galvo.sample_map.angles_to_codes",
        what: "per-sample map: DAC, both axes, f32",
        unit: "point",
        budget: None,
    },
    Row {
        id: "galvo.ik.f32",
        what: "galvo IK, f32",
        unit: "point",
        budget: None,
    },
    Row {
        id: "galvo.angles_to_codes.f32",
        what: "DAC mapping, both axes, f32",
        unit: "point",
        budget: None,
    },
    Row {
        id: "dac.angle_to_code.f32",
        what: "DAC mapping, one axis, f32",
        unit: "point",
        budget: None,
    },
    Row {
        id: "galvo.board_to_codes.f64",
        what: "galvo IK + DAC, f64 reference",
        unit: "point",
        budget: None,
    },
    Row {
        id: "path.add.line",
        what: "look-ahead planner: add a line behind 8 blocks",
        unit: "segment",
        budget: None,
    },
    Row {
        id: "path.add.arc",
        what: "look-ahead planner: add an arc behind 8 blocks",
        unit: "segment",
        budget: None,
    },
    Row {
        id: "gimbal.ik_wire",
        what: "gimbal IK to servo wire values",
        unit: "point",
        budget: None,
    },
    Row {
        id: "error_model.compensate",
        what: "error-model compensation",
        unit: "point",
        budget: None,
    },
    Row {
        id: "plan.xy.optimal.1lsb",
        what: "two-axis time-optimal jump plan, 1 LSB",
        unit: "jump",
        budget: Some((100.0, "100 µs per two-axis jump", PLANNING)),
    },
    Row {
        id: "plan.xy.optimal.160mm",
        what: "two-axis time-optimal jump plan, (−80,−80)→(80,80) mm",
        unit: "jump",
        budget: Some((100.0, "100 µs per two-axis jump", PLANNING)),
    },
];

/// The description of a planning id `plan.<method>.<amplitude>`.
fn plan_row(id: &str) -> Option<(String, &'static str)> {
    let rest = id.strip_prefix("plan.")?;
    let (method, amp) = rest.split_once('.')?;
    Some((format!("one-axis {method} plan, {amp}"), "jump"))
}

/// One measured benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct Measured {
    pub id: String,
    pub what: String,
    pub unit: String,
    /// Guest instructions per unit.
    pub instructions: f64,
    /// Estimated µs per unit on the M4 (CPI × instructions / clock).
    pub est_us: f64,
    pub budget_us: Option<f64>,
    pub budget: Option<String>,
    /// Fraction of the budget used.
    pub share: Option<f64>,
    /// "enforced", or "reported, not yet met (…)".
    pub status: Option<String>,
    pub over_budget: bool,
}

/// The run's parsed output.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub method: &'static str,
    pub clock_mhz: f64,
    pub cpi: f64,
    pub instructions_per_tick: f64,
    pub rows: Vec<Measured>,
}

/// Estimated µs on the M4 for `instructions`.
pub fn est_us(instructions: f64) -> f64 {
    instructions * CPI / CLOCK_MHZ
}

/// Parses the bench's semihosting output into the table.
pub fn parse(output: &str) -> Result<Report> {
    let mut ipt = None;
    let mut overhead_ticks = 0.0;
    let mut rows = Vec::new();
    let mut errors = Vec::new();
    let mut done = false;
    let mut self_checked = false;
    for line in output.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        match f.as_slice() {
            ["calibration", instr, ticks] => {
                let instr: f64 = instr.parse().context("calibration instructions")?;
                let ticks: f64 = ticks.parse().context("calibration ticks")?;
                if ticks <= 0.0 {
                    bail!("calibration window read no timer ticks");
                }
                let k = instr / ticks;
                if (k / NOMINAL_INSTRUCTIONS_PER_TICK - 1.0).abs() > 0.005 {
                    bail!(
                        "calibration: {k:.3} instructions per timer tick, expected \
                         {NOMINAL_INSTRUCTIONS_PER_TICK} (is QEMU running with -icount shift=0?)"
                    );
                }
                ipt = Some(k);
            }
            ["empty", ticks, n] => {
                let ticks: f64 = ticks.parse().context("empty ticks")?;
                let n: f64 = n.parse().context("empty count")?;
                overhead_ticks = ticks / n.max(1.0);
            }
            ["bench", id, ticks, units] => {
                let k = ipt.context("bench line before calibration")?;
                let ticks: f64 = ticks.parse().with_context(|| format!("ticks of {id}"))?;
                let units: f64 = units.parse().with_context(|| format!("units of {id}"))?;
                let instructions = ((ticks - overhead_ticks).max(0.0) * k) / units.max(1.0);
                rows.push(measured(id, instructions));
            }
            ["error", id, rest @ ..] => errors.push(format!("{id}: {}", rest.join(" "))),
            ["check", .., "ok", _] => self_checked = true,
            ["done", _] => done = true,
            _ => {}
        }
    }
    if !errors.is_empty() {
        bail!("bench-m4 reported errors: {}", errors.join("; "));
    }
    if !done {
        bail!("bench-m4 did not finish (no `done` line); output:\n{output}");
    }
    if !self_checked {
        bail!("bench-m4 did not report its on-target self-check (VSQRT, DAC conversion)");
    }
    for row in ROWS.iter().filter(|r| r.budget.is_some()) {
        if !rows.iter().any(|m| m.id == row.id) {
            bail!("bench-m4 did not report `{}`", row.id);
        }
    }
    Ok(Report {
        method: "QEMU mps2-an386 (Cortex-M4F), -icount shift=0: 1 ns per instruction, \
                 25 MHz APB timer 0 = 40 instructions per tick, calibrated on an asm loop",
        clock_mhz: CLOCK_MHZ,
        cpi: CPI,
        instructions_per_tick: ipt.unwrap_or(NOMINAL_INSTRUCTIONS_PER_TICK),
        rows,
    })
}

fn measured(id: &str, instructions: f64) -> Measured {
    let row = ROWS.iter().find(|r| r.id == id);
    let (what, unit) = match (row, plan_row(id)) {
        (Some(r), _) => (r.what.to_owned(), r.unit),
        (None, Some((what, unit))) => (what, unit),
        (None, None) => (id.to_owned(), "call"),
    };
    let us = est_us(instructions);
    let budget = row.and_then(|r| r.budget);
    let share = budget.map(|(b, _, _)| us / b);
    Measured {
        id: id.to_owned(),
        what,
        unit: unit.to_owned(),
        instructions,
        est_us: us,
        budget_us: budget.map(|(b, _, _)| b),
        budget: budget.map(|(_, text, _)| text.to_owned()),
        share,
        status: budget.map(|(_, _, e)| match e {
            Enforcement::Enforced => "enforced".to_owned(),
            Enforcement::NotYetMet(why) => format!("reported, not yet met ({why})"),
        }),
        over_budget: budget.is_some_and(|(b, _, e)| e == Enforcement::Enforced && us > b),
    }
}

/// Prints the table.
pub fn print(report: &Report) {
    println!(
        "M4 instructions (QEMU mps2-an386, -icount; {:.2} instructions/tick); \
         µs estimated at {} MHz, CPI {}",
        report.instructions_per_tick, report.clock_mhz, report.cpi
    );
    println!(
        "{:<34} {:<66} {:>12} {:>10} {:>8}  budget",
        "id", "what", "instr/unit", "est. µs", "share"
    );
    for m in &report.rows {
        let share = m
            .share
            .map_or(String::new(), |s| format!("{:.0} %", 100.0 * s));
        let budget = match (&m.budget, &m.status) {
            (Some(b), Some(s)) => {
                format!("{b}: {s}{}", if m.over_budget { " EXCEEDED" } else { "" })
            }
            _ => String::new(),
        };
        println!(
            "{:<34} {:<66} {:>12.0} {:>10.2} {:>8}  {}",
            m.id,
            format!("{} (per {})", m.what, m.unit),
            m.instructions,
            m.est_us,
            share,
            budget
        );
    }
}

/// Fails when an enforced budget is exceeded.
pub fn check(report: &Report) -> Result<()> {
    let over: Vec<String> = report
        .rows
        .iter()
        .filter(|m| m.over_budget)
        .map(|m| {
            format!(
                "{} ({}): {:.2} µs per {} > {:.2} µs",
                m.id,
                m.what,
                m.est_us,
                m.unit,
                m.budget_us.unwrap_or(0.0)
            )
        })
        .collect();
    if !over.is_empty() {
        bail!("M4 budgets exceeded:\n  {}", over.join("\n  "));
    }
    Ok(())
}

/// Installs Debian's `qemu-system-arm` when it is missing.
fn ensure_qemu() -> Result<()> {
    if Command::new("qemu-system-arm")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
    {
        return Ok(());
    }
    println!(
        "qemu-system-arm not found: installing it (apt-get update && apt-get install -y qemu-system-arm)"
    );
    run("apt-get", &["update"]).context("apt-get update (needs root)")?;
    run("apt-get", &["install", "-y", "qemu-system-arm"])
        .context("could not install qemu-system-arm; install it and run again")
}

/// Runs the bench ELF on QEMU and returns its output; fails on a non-zero
/// exit or when it runs longer than [`RUN_TIMEOUT`].
fn run_qemu(elf: &PathBuf) -> Result<String> {
    let mut child = Command::new("qemu-system-arm")
        .args([
            "-machine",
            "mps2-an386",
            "-cpu",
            "cortex-m4",
            "-icount",
            "shift=0",
            "-nographic",
            "-semihosting-config",
            "enable=on,target=native",
            "-kernel",
        ])
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("could not start qemu-system-arm")?;
    // Semihosting prints on QEMU's stderr; read both pipes on threads so a
    // full pipe never stalls the guest.
    let reader = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_string(&mut text);
            }
            text
        })
    };
    let stdout = reader(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let stderr = reader(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > RUN_TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            bail!("bench-m4 ran longer than {RUN_TIMEOUT:?} on QEMU: killed");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut out = stdout.join().unwrap_or_default();
    out.push_str(&stderr.join().unwrap_or_default());
    if !status.success() {
        bail!("bench-m4 failed on QEMU ({status}):\n{out}");
    }
    Ok(out)
}

/// The bench's manifest, relative to the workspace root. It is a workspace
/// of its own (the root one excludes it): cargo runs its rustc, and so the
/// linker, in `firmware/bench-m4/`, where cortex-m-rt's `INCLUDE memory.x`
/// finds the MPS2 board's map before the root's STM32F407 one.
pub const MANIFEST: &str = "firmware/bench-m4/Cargo.toml";

/// Runs `cargo <args> --manifest-path firmware/bench-m4/Cargo.toml` in the
/// workspace root (so the root's `.cargo/config.toml` applies: target
/// rustflags, flip-link) with the root's target directory.
pub fn cargo(args: &[&str]) -> Result<()> {
    let (command, rest) = args.split_first().context("cargo without a command")?;
    let target = target_dir();
    println!(
        "$ CARGO_TARGET_DIR={} cargo {command} --manifest-path {MANIFEST} {}",
        target.display(),
        rest.join(" ")
    );
    let status = Command::new("cargo")
        .arg(command)
        .args(["--manifest-path", MANIFEST])
        .args(rest)
        .env("CARGO_TARGET_DIR", &target)
        .current_dir(workspace_root())
        .status()
        .context("could not start `cargo`")?;
    if !status.success() {
        bail!(
            "`cargo {}` for {MANIFEST} failed ({status})",
            args.join(" ")
        );
    }
    Ok(())
}

/// `cargo xtask bench-m4`.
pub fn bench_m4() -> Result<()> {
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
    check(&report)
}

#[cfg(test)]
mod tests {
    use super::*;

    const OUT: &str = "bench-m4 1\ncalibration 2000000 50000\nempty 0 64\n\
        check sqrt+dac ok 6960\n\
        bench loop.holding.steady 40 128\nbench loop.line.steady 100 128\n\
        bench loop.arc_r40.steady 100 128\nbench loop.jump.steady 10 40\n\
        bench loop.holding.refill 40 1\nbench loop.line.refill 100 1\n\
        bench loop.arc_r40.refill 100 1\nbench loop.jump.refill 400000 1\n\
        bench plan.xy.optimal.1lsb 250 1\nbench plan.xy.optimal.160mm 300 1\n\
        bench plan.seed.1deg 100 1\ndone 0\n";

    #[test]
    fn turns_ticks_into_instructions_and_checks_budgets() {
        let r = parse(OUT).unwrap();
        assert_eq!(r.instructions_per_tick, 40.0);
        let holding = r
            .rows
            .iter()
            .find(|m| m.id == "loop.holding.steady")
            .unwrap();
        // 40 ticks · 40 / 128 = 12.5 instructions per sample.
        assert_eq!(holding.instructions, 12.5);
        assert!((holding.est_us - 12.5 * 1.3 / 168.0).abs() < 1e-12);
        assert!(!holding.over_budget);
        // Planning is within its enforced budget: 300 ticks = 12 000
        // instructions = 92.9 µs of 100 µs.
        let plan = r
            .rows
            .iter()
            .find(|m| m.id == "plan.xy.optimal.160mm")
            .unwrap();
        assert!(plan.share.unwrap() < 1.0 && !plan.over_budget);
        assert_eq!(plan.status.as_deref(), Some("enforced"));
        let seed = r.rows.iter().find(|m| m.id == "plan.seed.1deg").unwrap();
        assert_eq!(seed.what, "one-axis seed plan, 1deg");
        assert!(check(&r).is_ok());
    }

    #[test]
    fn an_enforced_budget_over_fails() {
        // 3000 ticks for a holding half: 120 000 instructions, 929 µs of
        // the 640 µs allowed.
        let out = OUT.replace(
            "bench loop.holding.refill 40 1",
            "bench loop.holding.refill 3000 1",
        );
        let r = parse(&out).unwrap();
        let err = check(&r).unwrap_err().to_string();
        assert!(err.contains("loop.holding.refill"), "{err}");
        // A two-axis jump plan over 100 µs (14 000 instructions) fails.
        let out = OUT.replace(
            "bench plan.xy.optimal.160mm 300 1",
            "bench plan.xy.optimal.160mm 350 1",
        );
        let err = check(&parse(&out).unwrap()).unwrap_err().to_string();
        assert!(err.contains("plan.xy.optimal.160mm"), "{err}");
        // Holding per sample is enforced too: 1000 ticks for 128 samples,
        // 312.5 instructions (2.4 µs) each, over its 0.5 µs.
        let holding = OUT.replace(
            "bench loop.holding.steady 40 128",
            "bench loop.holding.steady 1000 128",
        );
        let err = check(&parse(&holding).unwrap()).unwrap_err().to_string();
        assert!(err.contains("loop.holding.steady"), "{err}");
        // A budget not yet met is reported, not failed: 1000 ticks for 40
        // jump samples, 1000 instructions (7.7 µs) each, over its 1 µs.
        let jumping = OUT.replace(
            "bench loop.jump.steady 10 40",
            "bench loop.jump.steady 1000 40",
        );
        let r = parse(&jumping).unwrap();
        let m = r.rows.iter().find(|m| m.id == "loop.jump.steady").unwrap();
        assert!(m.share.unwrap() > 1.0 && !m.over_budget);
        assert!(
            m.status
                .as_deref()
                .unwrap()
                .starts_with("reported, not yet met")
        );
        assert!(check(&r).is_ok());
    }

    fn manifest(path: &str) -> toml::Table {
        let path = workspace_root().join(path);
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        text.parse()
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    /// `[profile.release]` with its per-package overrides.
    fn release_profile(manifest: &toml::Table) -> Option<&toml::Value> {
        manifest.get("profile")?.get("release")
    }

    /// The bench measures the crates as the firmware builds them: its
    /// workspace's release profile (profiles come from the workspace root
    /// only) must equal the root's, overrides included.
    #[test]
    fn bench_release_profile_is_the_firmware_one() {
        let root = manifest("Cargo.toml");
        let bench = manifest(MANIFEST);
        let root_release = release_profile(&root).expect("root [profile.release]");
        // Not vacuous: the root builds for size, the math crates for speed.
        assert_eq!(
            root_release.get("opt-level").and_then(toml::Value::as_str),
            Some("z")
        );
        assert!(
            root_release
                .get("package")
                .and_then(|p| p.get("galvo-planner"))
                .is_some()
        );
        assert_eq!(
            release_profile(&bench),
            Some(root_release),
            "{MANIFEST}'s [profile.release*] differs from the root Cargo.toml's: \
             copy the root's release profile there"
        );
        // A workspace of its own, excluded by the root: otherwise the
        // linker runs in the root and links the STM32F407 memory map.
        assert!(bench.get("workspace").is_some_and(toml::Value::is_table));
        let excluded = root
            .get("workspace")
            .and_then(|w| w.get("exclude"))
            .and_then(toml::Value::as_array)
            .is_some_and(|e| e.iter().any(|p| p.as_str() == Some("firmware/bench-m4")));
        assert!(
            excluded,
            "the root workspace must exclude firmware/bench-m4"
        );
    }

    /// The bench's own lock file pins the versions the firmware is built
    /// with: every package in it has the same version in the root lock.
    #[test]
    fn bench_lock_pins_the_root_versions() {
        let versions = |lock: &toml::Table| -> Vec<(String, String)> {
            lock.get("package")
                .and_then(toml::Value::as_array)
                .expect("[[package]] entries")
                .iter()
                .filter_map(|p| {
                    Some((
                        p.get("name")?.as_str()?.to_owned(),
                        p.get("version")?.as_str()?.to_owned(),
                    ))
                })
                .collect()
        };
        let root = versions(&manifest("Cargo.lock"));
        let bench = versions(&manifest("firmware/bench-m4/Cargo.lock"));
        assert!(bench.iter().any(|(name, _)| name == "cortex-m-rt"));
        let drifted: Vec<String> = bench
            .iter()
            .filter(|(name, version)| {
                name != "bench-m4" && !root.iter().any(|(n, v)| n == name && v == version)
            })
            .map(|(name, version)| format!("{name} {version}"))
            .collect();
        assert!(
            drifted.is_empty(),
            "firmware/bench-m4/Cargo.lock has versions the root Cargo.lock does not: {drifted:?} \
             (copy the root Cargo.lock there and build the bench once)"
        );
    }

    #[test]
    fn refuses_bad_runs() {
        // Without -icount the timer does not tick 40 instructions.
        let wrong = OUT.replace("calibration 2000000 50000", "calibration 2000000 20000");
        assert!(parse(&wrong).unwrap_err().to_string().contains("icount"));
        assert!(parse(&OUT.replace("done 0\n", "")).is_err());
        let missing = OUT.replace("bench loop.jump.steady 10 40\n", "");
        assert!(
            parse(&missing)
                .unwrap_err()
                .to_string()
                .contains("loop.jump.steady")
        );
        let error = format!("{OUT}error loop.jump \"setup\"\n");
        assert!(parse(&error).is_err());
        let unchecked = OUT.replace("check sqrt+dac ok 6960\n", "");
        assert!(
            parse(&unchecked)
                .unwrap_err()
                .to_string()
                .contains("self-check")
        );
    }
}
