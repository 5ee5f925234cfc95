//! The defmt log channel checked end to end (`cargo xtask test`): a
//! `defmt-log` image's lines arrive decoded ([`super::defmt_log`]).

use std::path::Path;
use std::time::Duration;

use anyhow::{Result, bail};

use super::board_run::{Drive, run_board};
use super::machine::MachineOptions;
use super::script::parse_board_script;

/// The defmt channel checked end to end on a `defmt-log` image: the
/// board's boot record (`no saved settings, using defaults`) and a
/// pattern's start arrive decoded, stamped and with their level.
pub fn check_channel(elf: &Path) -> Result<()> {
    let steps = parse_board_script("pattern home once\nwait 300\nstop\n")?;
    let run = run_board(
        elf,
        &MachineOptions::default(),
        Drive::Steps(steps),
        true,
        Duration::from_secs(30),
        false,
    )?;
    let lines = &run.log.defmt_lines;
    let boot = lines
        .iter()
        .any(|l| l.contains("INFO") && l.ends_with("no saved settings, using defaults"));
    let start = lines
        .iter()
        .any(|l| l.contains("INFO") && l.contains("start home (once=true)"));
    if !boot || !start || lines.iter().any(|l| l.contains("malformed")) {
        bail!("defmt lines decoded from the board: {lines:?}");
    }
    Ok(())
}
