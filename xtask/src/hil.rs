//! `cargo xtask hil --port DEVICE [--flash]`: the hardware acceptance run.
//! The shared scenarios (`tests/scenarios`) that need no injected fault run
//! against a board over its serial console and are judged by the same
//! assertions as on the simulator and the QEMU board
//! (`scenario::check`). The board reports its laser changes and
//! laser-deciding events itself, stamped with its own clock (`trace on`),
//! so a real board needs nothing but its USB port. Settings a scenario
//! changes are put back afterwards (and saved again if it saved).
//!
//! `cargo xtask test` proves the runner on the simulator's and the QEMU
//! board's PTY consoles.

mod run;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

use crate::scenario::{self, Scenario};
use crate::serial::Console;
use crate::toolchain::CHIP;

pub use run::{Reset, run_scenario};

/// Options of `cargo xtask hil`.
#[derive(clap::Args, Debug)]
pub struct HilArgs {
    /// The board's console (e.g. /dev/ttyACM0 or /dev/laser-pointer).
    #[arg(long)]
    port: PathBuf,
    /// Build this checkout's firmware and flash it with probe-rs first
    /// (also lets `save_reset` reset the board through the probe).
    #[arg(long)]
    flash: bool,
    /// Reset the board through probe-rs where a scenario resets it
    /// (implied by --flash).
    #[arg(long)]
    probe_reset: bool,
    /// Write the report as JSON here (default target/hil-report.json).
    #[arg(long)]
    json: Option<PathBuf>,
}

/// How a scenario came out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Verdict {
    /// All its assertions held.
    Pass,
    /// Why it failed.
    Fail(String),
    /// Why it could not run on this board.
    Skipped(String),
}

/// One row of the report.
#[derive(Debug, Clone)]
pub struct Row {
    /// The scenario's name.
    pub name: String,
    /// Its verdict.
    pub verdict: Verdict,
    /// Wall time it took, s.
    pub seconds: f64,
}

/// Why `scenario` cannot run over a bare console, if it cannot.
fn unrunnable(scenario: &Scenario, can_reset: bool) -> Option<String> {
    if !scenario.faults.is_empty() {
        return Some("needs fault injection (simulator and QEMU only)".into());
    }
    if scenario.script.lines().any(|l| l.trim() == "@button") {
        return Some("needs the stop button pressed (simulator and QEMU only)".into());
    }
    if !can_reset && scenario.script.lines().any(|l| l.trim() == "@reset") {
        return Some("needs a board reset: run on a board with --flash or --probe-reset".into());
    }
    None
}

/// Runs every shared scenario against the console at `port`.
pub fn run_all(port: &Path, reset: Reset<'_>) -> Result<Vec<Row>> {
    let mut console = Console::open(port)?;
    let mut rows = Vec::new();
    for scenario in scenario::all()? {
        let started = Instant::now();
        let verdict = match unrunnable(&scenario, reset.is_some()) {
            Some(why) => Verdict::Skipped(why),
            None => match run_scenario(&mut console, port, &scenario, reset) {
                Ok(run::Ran::Outcome(outcome)) => match scenario::check(&scenario.name, &outcome) {
                    Ok(()) => Verdict::Pass,
                    Err(e) => Verdict::Fail(format!("{e:#}")),
                },
                Ok(run::Ran::NoGalvo) => Verdict::Skipped("this board has no galvo output".into()),
                Ok(run::Ran::SwitchesInputs) => Verdict::Skipped(
                    "the interlock and key cannot be switched over the console".into(),
                ),
                Err(e) => Verdict::Fail(format!("{e:#}")),
            },
        };
        rows.push(Row {
            name: scenario.name.clone(),
            verdict,
            seconds: started.elapsed().as_secs_f64(),
        });
    }
    Ok(rows)
}

/// The pass/fail table.
pub fn table(rows: &[Row]) -> String {
    let mut out = String::from("scenario          result   time   note\n");
    for row in rows {
        let (result, note) = match &row.verdict {
            Verdict::Pass => ("pass", ""),
            Verdict::Fail(why) => ("FAIL", why.as_str()),
            Verdict::Skipped(why) => ("skipped", why.as_str()),
        };
        out.push_str(&format!(
            "{:<17} {:<8} {:>5.1} s {note}\n",
            row.name, result, row.seconds
        ));
    }
    out
}

/// The report as JSON.
pub fn json(port: &Path, rows: &[Row]) -> serde_json::Value {
    let scenarios: Vec<serde_json::Value> = rows
        .iter()
        .map(|row| {
            let (result, reason) = match &row.verdict {
                Verdict::Pass => ("pass", None),
                Verdict::Fail(why) => ("fail", Some(why.clone())),
                Verdict::Skipped(why) => ("skipped", Some(why.clone())),
            };
            serde_json::json!({
                "name": row.name,
                "result": result,
                "reason": reason,
                "seconds": row.seconds,
            })
        })
        .collect();
    serde_json::json!({
        "port": port.display().to_string(),
        "passed": rows.iter().filter(|r| r.verdict == Verdict::Pass).count(),
        "failed": rows.iter().filter(|r| matches!(r.verdict, Verdict::Fail(_))).count(),
        "skipped": rows.iter().filter(|r| matches!(r.verdict, Verdict::Skipped(_))).count(),
        "scenarios": scenarios,
    })
}

/// Fails naming every failed scenario.
pub fn require_pass(rows: &[Row], board: &str) -> Result<()> {
    let failed: Vec<String> = rows
        .iter()
        .filter_map(|r| match &r.verdict {
            Verdict::Fail(why) => Some(format!("{}: {why}", r.name)),
            _ => None,
        })
        .collect();
    if !failed.is_empty() {
        bail!("hil on {board}:\n{}", failed.join("\n"));
    }
    if !rows.iter().any(|r| r.verdict == Verdict::Pass) {
        bail!("hil on {board}: no scenario ran");
    }
    Ok(())
}

/// The runner proved on the QEMU board from `elf` over its PTY console.
pub fn check_on_qemu(elf: &Path) -> Result<Vec<Row>> {
    let (rows, _run) =
        crate::qemu::with_board_on_pty(elf, Duration::from_secs(300), |path| run_all(path, None))?;
    let rows = rows?;
    require_pass(&rows, "the QEMU board's PTY")?;
    Ok(rows)
}

/// Resets the board through probe-rs and waits for its console to come
/// back.
fn probe_reset(port: &Path) -> Result<()> {
    crate::toolchain::run("probe-rs", &["reset", "--chip", CHIP])?;
    wait_for_port(port, Duration::from_secs(15))
}

fn wait_for_port(port: &Path, limit: Duration) -> Result<()> {
    let started = Instant::now();
    // The USB device goes away on reset and enumerates again.
    std::thread::sleep(Duration::from_millis(500));
    while Console::open(port).is_err() {
        if started.elapsed() > limit {
            bail!(
                "{} did not come back within {} s",
                port.display(),
                limit.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    Ok(())
}

/// Runs `cargo xtask hil`.
pub fn run(args: HilArgs) -> Result<ExitCode> {
    if args.flash {
        let elf = crate::toolchain::build_firmware()?;
        let elf = elf.to_string_lossy().into_owned();
        crate::toolchain::run("probe-rs", &["download", "--chip", CHIP, &elf])
            .context("flashing with probe-rs (is the ST-LINK plugged in? `cargo xtask doctor`)")?;
        probe_reset(&args.port)?;
    }
    let port = args.port.clone();
    let reset_fn = move || probe_reset(&port);
    let reset: Reset<'_> = (args.flash || args.probe_reset).then_some(&reset_fn as _);
    let rows = run_all(&args.port, reset)?;
    print!("{}", table(&rows));
    let report = json(&args.port, &rows);
    let path = args
        .json
        .unwrap_or_else(|| crate::toolchain::target_dir().join("hil-report.json"));
    std::fs::write(&path, serde_json::to_string_pretty(&report)?)
        .with_context(|| format!("cannot write {}", path.display()))?;
    println!("report: {}", path.display());
    Ok(
        if require_pass(&rows, &args.port.display().to_string()).is_ok() {
            ExitCode::SUCCESS
        } else {
            ExitCode::FAILURE
        },
    )
}

#[cfg(test)]
mod tests;
