//! The G-code path's share of the firmware image, for `cargo xtask size`:
//! the symbols of the grbl protocol layer (`laser_app::grbl`) and of the
//! sequencer's G-code session (`sequencer::gcode`) and the drivers' G-code
//! stages (the gimbal's stream, the galvo's strokes, the stepper's
//! hand-over: [`GCODE_SYMBOLS`]), read
//! with `llvm-nm`. Code the optimiser inlined into other functions (the
//! console and sequencer tasks) is not attributed, so the flash figure is
//! a lower bound; the RAM figure is the state the G-code path adds.

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

/// Symbol name parts that belong to the G-code path.
/// (The gimbal's point runs, `drivers::gimbal::points`, are the
/// product's patterns, not G-code.)
const GCODE_SYMBOLS: [&str; 11] = [
    "laser_app::grbl::",
    "laser_app::sequencer::gcode",
    "laser_app::sequencer::drivers::gimbal::stream",
    "laser_app::sequencer::drivers::gimbal::plan",
    "laser_app::sequencer::drivers::gimbal::step",
    "laser_app::sequencer::drivers::gimbal::cache",
    "laser_app::sequencer::drivers::gimbal::deg_per_mm",
    "laser_app::sequencer::drivers::galvo::gcode",
    "laser_app::sequencer::drivers::galvo::ahead",
    "laser_app::sequencer::drivers::galvo::hold",
    "laser_app::sequencer::drivers::stepper::gcode",
];

/// Flash bytes (code and read-only data) and symbol count of the G-code
/// path in `nm` (output of `llvm-nm --print-size --demangle`).
pub fn flash_of(nm: &str) -> (u64, usize) {
    let mut bytes = 0;
    let mut symbols = 0;
    for line in nm.lines() {
        let mut fields = line.split_whitespace();
        let (Some(_addr), Some(size), Some(kind)) = (fields.next(), fields.next(), fields.next())
        else {
            continue;
        };
        let name: String = fields.collect::<Vec<_>>().join(" ");
        let in_flash = matches!(kind, "t" | "T" | "r" | "R");
        if in_flash
            && GCODE_SYMBOLS.iter().any(|part| name.contains(part))
            && let Ok(size) = u64::from_str_radix(size, 16)
        {
            bytes += size;
            symbols += 1;
        }
    }
    (bytes, symbols)
}

/// Prints the G-code path's flash and RAM cost in `elf`.
pub fn report(elf: &Path, llvm_size: &Path) -> Result<()> {
    let nm = llvm_size.with_file_name("llvm-nm");
    let out = Command::new(&nm)
        .args(["--print-size", "--demangle"])
        .arg(elf)
        .output()
        .with_context(|| format!("could not run {}", nm.display()))?;
    if !out.status.success() {
        bail!("llvm-nm failed: {}", String::from_utf8_lossy(&out.stderr));
    }
    let (bytes, symbols) = flash_of(&String::from_utf8_lossy(&out.stdout));
    let ram = laser_app::sequencer::GCODE_RAM_BYTES;
    println!(
        "  G-code path: flash >= {bytes} B in {symbols} functions/tables (grbl layer, sequencer::gcode, the drivers' G-code stages; inlined code not counted), RAM {ram} B (session, 16-block queue, realtime queue, RX buffer)"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_gcode_symbols_in_flash_are_counted() {
        let nm = "08000100 00000040 T laser_app::grbl::parser::<impl laser_app::grbl::state::ParserState>::execute\n\
                  08000200 00000010 t laser_app::sequencer::gcode::queue::point_at\n\
                  08000210 00000008 t laser_app::sequencer::drivers::galvo::hold::<impl laser_app::sequencer::machine::Core>::gcode_galvo_hold\n\
                  08000218 00000004 t laser_app::sequencer::drivers::galvo::points::<impl laser_app::sequencer::machine::Core>::stop_galvo\n\
                  08000220 00000030 t laser_app::sequencer::drivers::gimbal::stream::Stream::tick\n\
                  08000250 00000018 t laser_app::sequencer::drivers::gimbal::points::aim\n\
                  08000300 00000020 R laser_app::grbl::settings_map::SETTINGS\n\
                  20000000 00000100 B laser_app::grbl::something_in_ram\n\
                  08000400 00000080 T laser_app::usb::run_console\n\
                  08000500 T no_size_symbol\n";
        assert_eq!(flash_of(nm), (0x40 + 0x10 + 0x8 + 0x30 + 0x20, 5));
    }
}
