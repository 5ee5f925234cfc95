//! Scenarios that run on both boards from one description
//! (`tests/scenarios/*.txt`, see its README): the host simulator in virtual
//! time and the emulated Cortex-M4F on QEMU in real time, reduced to one
//! board-neutral [`Outcome`] and checked by the same assertions. Times are
//! the board's own clock (virtual µs in the simulator, embassy-time µs on
//! the emulated board), so the safety bounds are the same on both.

mod checks;
mod outcome;

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result};
use laser_sim::recorder::SequencerEvent;
use laser_sim::servo_port::BusFaults;
use laser_sim::world::{SimOptions, run};

use crate::qemu::{
    BoardEvent, BoardRun, BoardStep, Drive, MachineOptions, parse_board_script, run_board,
    split_at_resets,
};
use crate::toolchain::workspace_root;

pub use checks::check;
pub use outcome::Outcome;

/// The scenarios' directory, relative to the workspace root.
pub const DIR: &str = "tests/scenarios";
/// The longest a scenario may run on QEMU (real time).
const QEMU_TIME_LIMIT: Duration = Duration::from_secs(60);

/// One scenario: its name (file stem), script and faults.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// File stem (`grid`, `switch`, …): selects its assertions.
    pub name: String,
    /// The script, `@reset` lines included.
    pub script: String,
    /// The `#! fault` specs.
    pub faults: Vec<String>,
    /// `#! galvo-dac`: the board has a galvo DAC stream.
    pub galvo_dac: bool,
    /// The script sets the laser controls (`@interlock`, `@key`): the
    /// board has them.
    pub laser_controls: bool,
}

impl Scenario {
    /// Reads `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let script = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let faults = script
            .lines()
            .filter_map(|l| l.trim().strip_prefix("#! fault "))
            .map(|s| s.trim().to_owned())
            .collect();
        let galvo_dac = script.lines().any(|l| l.trim() == "#! galvo-dac");
        let laser_controls = parse_board_script(&script)?
            .iter()
            .any(|s| matches!(s, BoardStep::Script(step) if step.uses_laser_controls()));
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .context("scenario file without a name")?
            .to_owned();
        Ok(Self {
            name,
            script,
            faults,
            galvo_dac,
            laser_controls,
        })
    }

    fn faults(&self) -> Result<(BusFaults, f64)> {
        crate::sim::parse_faults(&self.faults)
    }
}

/// Every scenario in [`DIR`], by name.
pub fn all() -> Result<Vec<Scenario>> {
    let dir = workspace_root().join(DIR);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "txt"))
        .collect();
    paths.sort();
    paths.iter().map(|p| Scenario::load(p)).collect()
}

fn board_event(event: &SequencerEvent) -> BoardEvent {
    match event {
        SequencerEvent::Stopped { why } => BoardEvent::Stopped(why.clone()),
        SequencerEvent::RunStarted => BoardEvent::RunStarted,
        SequencerEvent::GimbalMoveSent => BoardEvent::GimbalMoveSent,
        SequencerEvent::GimbalArrived => BoardEvent::GimbalArrived,
    }
}

/// Runs `scenario` on the simulator: one run per part between `@reset`s,
/// each booting from the settings flash the previous one left, until idle;
/// with a galvo DAC only when the scenario asks for one.
pub fn on_simulator(scenario: &Scenario) -> Result<Outcome> {
    let (faults, slow_factor) = scenario.faults()?;
    let mut outcome = Outcome {
        board: "simulator",
        script_done: true,
        ..Outcome::default()
    };
    let mut flash = None;
    for part in split_at_resets(&scenario.script) {
        let report = run(SimOptions {
            script: laser_sim::script::parse_script(&part)?,
            until_idle: true,
            faults: faults.clone(),
            slow_factor,
            max_time_ms: 120_000,
            settings_flash: flash.take(),
            galvo_dac: scenario.galvo_dac,
            ..SimOptions::default()
        });
        let offset = outcome.end_us;
        outcome.boots += 1;
        outcome
            .transcript
            .extend(report.transcript.lines.iter().map(|(_, l)| l.clone()));
        outcome.error_replies += report.transcript.error_replies;
        outcome
            .notices
            .extend(report.transcript.notices.iter().map(|(_, l)| l.clone()));
        let rec = &report.recording;
        outcome
            .laser_events
            .extend(rec.laser_events.iter().map(|&(t, on)| (offset + t, on)));
        outcome.events.extend(
            rec.events
                .iter()
                .map(|e| (offset + e.t_us, board_event(&e.event))),
        );
        outcome.script_done &= report.transcript.script_done;
        outcome.idle_at_end = report.idle_at_end;
        outcome.end_us = offset + report.end_time_us;
        flash = Some(report.settings_flash);
    }
    Ok(outcome)
}

impl From<BoardRun> for Outcome {
    fn from(run: BoardRun) -> Self {
        Self {
            board: "QEMU mps2-an386",
            transcript: run.terminal.lines.into_iter().map(|(_, l)| l).collect(),
            error_replies: run.terminal.error_replies,
            notices: run.terminal.notices.into_iter().map(|(_, l)| l).collect(),
            laser_events: run.log.laser_events,
            events: run.log.events,
            script_done: run.script_done,
            idle_at_end: run.idle_at_end,
            boots: run.log.boots,
            end_us: run.log.last_us,
        }
    }
}

/// Runs `scenario` on the emulated board built at `elf`.
pub fn on_qemu(elf: &Path, scenario: &Scenario) -> Result<Outcome> {
    let (faults, slow_factor) = scenario.faults()?;
    let options = MachineOptions {
        faults,
        slow_factor,
        echo: false,
        echo_log: false,
        console_tee: None,
        pelco: None,
    };
    let steps = parse_board_script(&scenario.script)?;
    let run = run_board(
        elf,
        &options,
        Drive::Steps(steps),
        true,
        QEMU_TIME_LIMIT,
        false,
    )?;
    Ok(Outcome::from(run))
}

#[cfg(test)]
mod tests;
